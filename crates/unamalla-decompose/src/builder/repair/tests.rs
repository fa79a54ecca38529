use unamalla_mesh::geometry::open_segment_hits;
use unamalla_mesh::Region;

use super::table::CutTable;
use super::*;
use crate::piece::{End, Piece, Pos};
use crate::DecomposeOptions;

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn ring(pts: &[(f64, f64)], tags: &[Tag]) -> Ring {
    Ring {
        pts: pts.iter().map(|&(x, y)| v(x, y)).collect(),
        tags: tags.to_vec(),
    }
}

const B: Tag = Tag::Boundary(0);

/// L-shape (4×4 square minus the 2×2 top-right square) with a straight boundary vertex
/// S = (0, 2) on its left side.
fn l_region() -> Region {
    Region::new(
        vec![
            v(0., 0.),
            v(4., 0.),
            v(4., 2.),
            v(2., 2.),
            v(2., 4.),
            v(0., 4.),
            v(0., 2.),
        ],
        vec![],
    )
    .unwrap()
}

#[test]
fn triangle_without_usable_fourth_corner_gets_a_moved_cut() {
    // a bad cut (2,2)–(0,4) leaves the triangle (2,2),(2,4),(0,4) (45°/90°/45°: three
    // usable corners only). The union with its neighbour is the L-shape, not approximately
    // convex (κ₃ = 0.5 > 0.1, see the concavity tests), so the repair must re-split it: the
    // best splits into two good blocks are the cuts (2,2)–(0,2) and (2,2)–(2,0) (two
    // rectangles of areas 8 and 4, corner score 0 each: four 90° corners, balanced sides,
    // straight sides; the same cut length and end angles, so they tie on the score).
    let region = l_region();
    let opts = DecomposeOptions::default();
    let mut b = Builder::new(&region, &opts);
    b.cuts = vec![(v(2., 2.), v(0., 4.))];
    let tri = ring(&[(2., 2.), (2., 4.), (0., 4.)], &[B, B, Tag::Cut(0)]);
    let rest = ring(
        &[(0., 0.), (4., 0.), (4., 2.), (2., 2.), (0., 4.), (0., 2.)],
        &[B, B, B, Tag::Cut(0), B, B],
    );
    assert!(b.needs_repair(&tri));
    let out = b.repair_pass(vec![rest, tri]);
    assert_eq!(out.len(), 2);
    assert_eq!(b.cuts.len(), 1);
    let (p, q) = b.cuts[0];
    let ends = [p, q];
    assert!(
        ends.contains(&v(2., 2.)) && (ends.contains(&v(0., 2.)) || ends.contains(&v(2., 0.))),
        "{ends:?}"
    );
    for r in &out {
        assert!(b.good(r), "{:?}", r.pts);
        let a = crate::geom::signed_area(&r.pts);
        assert!(
            (a - 8.0).abs() < 1e-12 || (a - 4.0).abs() < 1e-12,
            "area {a}"
        );
    }
}

#[test]
fn u_shaped_block_needs_two_cuts() {
    // U = 3×3 square minus the 1×2 slot (1,1)–(2,3): κ₁ = (16 − 12)/16 = 0.25 > τ₁⁻, so it
    // needs a repair. Every single cut leaves a child with a reflex vertex and κ₁ ≥ 0.1
    // (an L or the U itself), so steps 1–2 find nothing (no neighbours to merge with);
    // step 3 must split it by two cuts into three rectangles (four usable 90° corners
    // each), with areas adding up to 9 − 2 = 7.
    let u = [
        (0., 0.),
        (3., 0.),
        (3., 3.),
        (2., 3.),
        (2., 1.),
        (1., 1.),
        (1., 3.),
        (0., 3.),
    ];
    let region = Region::new(u.iter().map(|&(x, y)| v(x, y)).collect(), vec![]).unwrap();
    let opts = DecomposeOptions::default();
    let mut b = Builder::new(&region, &opts);
    let block = ring(&u, &[B; 8]);
    assert!(b.needs_repair(&block));
    assert!(b.best_split(&block).is_none());
    let out = b.repair_pass(vec![block]);
    assert_eq!(out.len(), 3, "{out:?}");
    assert_eq!(b.cuts.len(), 2);
    let mut total = 0.0;
    for r in &out {
        assert!(b.good(r), "{:?}", r.pts);
        // a rectangle: every corner the best fit picks is a right angle
        let (c, _) = select_corners(&r.pts, &opts.corner_weights).expect("four corners");
        for &i in &c {
            let n = r.len();
            let (p, a, q) = (r.pts[(i + n - 1) % n], r.pts[i], r.pts[(i + 1) % n]);
            assert!((p - a).dot(q - a).abs() < 1e-12, "{:?} at {a:?}", r.pts);
        }
        total += crate::geom::signed_area(&r.pts);
    }
    assert!((total - 7.0).abs() < 1e-12, "area {total}");
    // each new cut has both ends on the region boundary and length 1 (the slot's depth
    // from a reflex vertex to the opposite side, or across an arm)
    for &(p, q) in &b.cuts {
        assert!((p.distance(q) - 1.0).abs() < 1e-12, "{p:?}–{q:?}");
    }
}

/// Where `CutTable::locate` matches a child's vertices and edges to the host's, the
/// table's angles are `Builder::end_angles` on the child, bit for bit, and a cut between
/// two such vertices is admissible in the child exactly when the table has it admissible
/// in the host and it meets none of the child's other edges.
#[test]
fn end_angle_table_matches_the_child_angles() {
    let mut state = 0x5eed_1234_abcd_0001u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let bits = |a: [f64; 2]| a.map(f64::to_bits);
    let (mut checked, mut admitted) = (0, 0);
    for _ in 0..200 {
        let n = 6 + (next() * 30.0) as usize;
        let pts: Vec<DVec2> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * (i as f64 + 0.5 * next()) / n as f64;
                let r = 0.5 + next();
                v(r * t.cos(), r * t.sin())
            })
            .collect();
        let host = ring(
            &pts.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>(),
            &vec![B; n],
        );
        let opts = DecomposeOptions::default();
        let region = l_region();
        let builder = Builder::new(&region, &opts);
        let table = CutTable::new(&host.pts, *builder.tier1_screen());
        // a child: the host from vertex i on, closed by a cut to a point inside an edge
        let i = (next() * n as f64) as usize % n;
        let len = 3 + (next() * (n - 4) as f64) as usize;
        let mut child: Vec<DVec2> = (0..len).map(|k| host.pts[(i + k) % n]).collect();
        let (a, b) = (host.pts[(i + len - 1) % n], host.pts[(i + len) % n]);
        let x = a + 0.5 * (b - a);
        child.push(x);
        // a child of an admissible cut lies in the host (admissibility is compared there)
        let host_piece = Piece {
            outer: host.clone(),
            holes: Vec::new(),
        };
        let cut_ends = [
            End {
                ring: 0,
                pos: Pos::OnEdge((i + len - 1) % n, x),
            },
            End {
                ring: 0,
                pos: Pos::Vertex(i),
            },
        ];
        let inside = host_piece.admissible_scan(cut_ends[0], cut_ends[1]);
        let child = Ring {
            tags: vec![B; child.len()],
            pts: child,
        };
        let at = table.locate(&child);
        let piece = Piece {
            outer: child.clone(),
            holes: Vec::new(),
        };
        let m = child.len();
        for k in (0..m).filter(|&k| at.vertex[k] != usize::MAX) {
            let e1 = End {
                ring: 0,
                pos: Pos::Vertex(k),
            };
            for l in (0..m).filter(|&l| l != k && at.vertex[l] != usize::MAX) {
                let q = child.pts[l];
                let (x, y) = Builder::end_angles(&piece, e1, q);
                // the screen rejects only angles below θ₋
                match table.vertex_angles(at.vertex[k], at.vertex[l]) {
                    Some(got) => assert_eq!(bits(got), bits([x, y])),
                    None => assert!(x.min(y) < opts.tolerances.theta_minus),
                }
                checked += 1;
                // admissibility from the host's and the child's other edges
                let idx = piece.index();
                let e2 = End {
                    ring: 0,
                    pos: Pos::Vertex(l),
                };
                let to = End {
                    ring: 0,
                    pos: Pos::Vertex(at.vertex[l]),
                };
                let p = child.pts[k];
                let hits = (0..m)
                    .filter(|&f| at.edge[f] == usize::MAX)
                    .any(|f| open_segment_hits(p, q, child.p(f), child.next(f)));
                if inside {
                    let via_host = table.admissible(at.vertex[k], to) && !hits;
                    assert_eq!(piece.admissible(&idx, e1, e2), via_host, "{k} {l}");
                    admitted += via_host as usize;
                }
            }
            for e in (0..m).filter(|&e| at.edge[e] != usize::MAX) {
                let (a, b) = (child.p(e), child.next(e));
                let x = a + crate::geom::project_t(child.pts[k], a, b) * (b - a);
                let (p0, p1) = Builder::end_angles(&piece, e1, x);
                let e2 = End {
                    ring: 0,
                    pos: Pos::OnEdge(e, x),
                };
                let (f0, f1) = Builder::end_angles(&piece, e2, child.pts[k]);
                let want = [p0, p1, f0, f1];
                match table.foot_angles(at.vertex[k], at.edge[e], x) {
                    Some(got) => assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits)),
                    None => assert!(want.iter().any(|&a| a < opts.tolerances.theta_minus)),
                }
            }
        }
    }
    assert!(checked > 1000, "{checked}");
    assert!(admitted > 100, "{admitted}");
}

#[test]
fn non_convex_block_bounded_by_cuts_is_split() {
    // the L-shape as a block whose every edge is a cut (like the pentagon of cuts around the
    // Gulf of Mexico's central basin): new cuts may end only at its vertices; the cut from
    // the reflex vertex (2,2) to the vertex (0,2) gives two rectangles (the foot (2,0) is
    // not offered: that edge is a cut, and a cut ending inside a cut is a T-junction).
    let region = l_region();
    let opts = DecomposeOptions::default();
    let mut b = Builder::new(&region, &opts);
    // pretend cut ids 0..7 exist (the outer neighbours are not part of this test)
    b.cuts = (0..7).map(|_| (v(0., 0.), v(1., 0.))).collect();
    let tags: Vec<Tag> = (0..7).map(Tag::Cut).collect();
    let l = ring(
        &[
            (0., 0.),
            (4., 0.),
            (4., 2.),
            (2., 2.),
            (2., 4.),
            (0., 4.),
            (0., 2.),
        ],
        &tags,
    );
    assert!(b.needs_repair(&l));
    let (_, a, c, ends) = b.best_split(&l).expect("a split");
    assert!(b.good(&a) && b.good(&c));
    let e = [ends.0, ends.1];
    assert!(
        e.contains(&v(2., 2.)) && (e.contains(&v(0., 2.)) || e.contains(&v(2., 0.))),
        "{e:?}"
    );
}

#[test]
fn cut_free_triangle_merges_back() {
    // rectangle with a straight vertex S = (2,0); a cut S–(4,2) leaves a 45°/90°/45°
    // triangle. The union is the rectangle (four 90° corners): merge, no cut left.
    let region = Region::new(
        vec![v(0., 0.), v(2., 0.), v(4., 0.), v(4., 2.), v(0., 2.)],
        vec![],
    )
    .unwrap();
    let opts = DecomposeOptions::default();
    let mut b = Builder::new(&region, &opts);
    b.cuts = vec![(v(2., 0.), v(4., 2.))];
    let tri = ring(&[(2., 0.), (4., 0.), (4., 2.)], &[B, B, Tag::Cut(0)]);
    let rest = ring(
        &[(0., 0.), (2., 0.), (4., 2.), (0., 2.)],
        &[B, Tag::Cut(0), B, B],
    );
    let out = b.repair_pass(vec![rest, tri]);
    assert_eq!(out.len(), 1);
    assert!(b.cuts.is_empty());
    assert!((crate::geom::signed_area(&out[0].pts) - 8.0).abs() < 1e-12);
}

#[test]
fn triangle_of_cuts_gets_no_corner_inside_a_cut() {
    // 10 × 10 square cut by the triangle of cuts P = (5,0), Q = (10,6), R = (0,6) (the
    // situation once seen on maryland: a piece bounded by cuts only). Its angles are
    // 2·atan(5/6) = 79.6° at P and atan(6/5) = 50.2° at Q and R (no critical angle), so the
    // triangle-block rule would put its fourth corner at the midpoint of its longest side —
    // inside a cut (a valence-3 node in the mesh). The joint pass must merge it away.
    let region = Region::new(vec![v(0., 0.), v(10., 0.), v(10., 10.), v(0., 10.)], vec![]).unwrap();
    let opts = DecomposeOptions::default();
    let mut b = Builder::new(&region, &opts);
    b.cuts = vec![
        (v(5., 0.), v(10., 6.)),
        (v(10., 6.), v(0., 6.)),
        (v(0., 6.), v(5., 0.)),
    ];
    let (c0, c1, c2) = (Tag::Cut(0), Tag::Cut(1), Tag::Cut(2));
    let t = ring(&[(5., 0.), (10., 6.), (0., 6.)], &[c0, c1, c2]);
    let theta = opts.tolerances.theta_minus;
    assert!(needs_cut_point(&t, theta, &opts));
    let mut slot = vec![
        Some(t),
        Some(ring(&[(5., 0.), (10., 0.), (10., 6.)], &[B, B, c0])),
        Some(ring(
            &[(10., 6.), (10., 10.), (0., 10.), (0., 6.)],
            &[B, B, B, c1],
        )),
        Some(ring(&[(0., 0.), (5., 0.), (0., 6.)], &[B, c2, B])),
    ];
    // the outer blocks are served on the boundary (triangles with two boundary edges,
    // the rectangle-like top block has four usable corners)
    for r in slot.iter().skip(1).flatten() {
        assert!(!needs_cut_point(r, theta, &opts), "{:?}", r.pts);
    }
    let mut owner: Vec<usize> = (0..4).collect();
    let mut alive = vec![true; 3];
    b.joint_pass(&mut slot, &mut owner, &mut alive);
    let out = b.renumber(slot, owner, alive);
    // one cut fewer at least, no block needs a point inside a cut, area 100 preserved
    assert!(out.len() <= 3, "{} blocks", out.len());
    assert_eq!(b.cuts.len(), out.len() - 1);
    let area: f64 = out.iter().map(|r| crate::geom::signed_area(&r.pts)).sum();
    assert!((area - 100.0).abs() < 1e-9, "area {area}");
    for r in &out {
        assert!(!needs_cut_point(r, theta, &opts), "{:?}", r.pts);
        assert!(r.tags.iter().any(|t| matches!(t, Tag::Boundary(_))));
    }
}
