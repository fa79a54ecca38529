//! Known-answer tests of the decomposition (the "must show" list). Expected values are
//! derived here from the geometry, independently of the library's formulas.

use unamalla_decompose::{decompose, DecomposeOptions, Decomposition, EdgeKind, Tolerances};
use unamalla_mesh::{DVec2, Region};

/// The thesis's layout (Algorithm 1 alone): these known answers are the thesis's
/// (the chord layout, the default, may cut a triangle or a strip across first).
/// The thesis's rules: the concavity layout, critical triangle vertices blunted.
fn thesis() -> DecomposeOptions {
    DecomposeOptions::default()
        .layout(unamalla_decompose::Layout::Concavity)
        .blunt_critical_tips(true)
}

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// Independent checks of a tiling: validation, areas, cut sharing, graph cycles, and no
/// overlap / no gap at sample points (each interior sample lies in exactly one block).
fn check_tiling(region: &Region, d: &Decomposition) {
    d.validate(region).expect("valid decomposition");
    let sum: f64 = d.blocks.iter().map(|b| b.area()).sum();
    assert!(
        (sum - region.area()).abs() <= 1e-9 * region.area(),
        "areas {sum} vs {}",
        region.area()
    );
    for c in &d.cuts {
        let uses: Vec<usize> = d
            .blocks
            .iter()
            .filter(|b| {
                b.edges
                    .iter()
                    .any(|e| matches!(e, EdgeKind::Cut { cut, .. } if *cut == c.id))
            })
            .map(|b| b.id)
            .collect();
        assert_eq!(uses.len(), 2, "cut {} used by {uses:?}", c.id);
        // the endpoints are vertices of both blocks
        for &b in &uses {
            assert!(d.blocks[b].ring.contains(&c.a) && d.blocks[b].ring.contains(&c.b));
        }
    }
    assert_eq!(d.graph_cycles(), region.holes().len());
    let (lo, hi) = region.bounding_box();
    let k = 37;
    for i in 0..k {
        for j in 0..k {
            let p = lo
                + (hi - lo) * DVec2::new((i as f64 + 0.5) / k as f64, (j as f64 + 0.5) / k as f64);
            let inside = region.contains_point(p);
            let count = d
                .blocks
                .iter()
                .filter(|b| {
                    unamalla_mesh::geometry::locate_in_ring(&b.ring, p)
                        == unamalla_mesh::Location::Inside
                })
                .count();
            if inside {
                let on_edge = d.blocks.iter().any(|b| {
                    unamalla_mesh::geometry::locate_in_ring(&b.ring, p)
                        == unamalla_mesh::Location::OnBoundary
                });
                assert!(
                    count == 1 || (on_edge && count == 0),
                    "{p}: in {count} blocks"
                );
            } else {
                assert_eq!(count, 0, "{p} outside the region but in a block");
            }
        }
    }
    // corners: four, non-reflex, in ring order
    for b in &d.blocks {
        for a in b.corner_angles() {
            assert!(
                a <= std::f64::consts::PI + 1e-6,
                "block {} corner {a}",
                b.id
            );
        }
    }
}

#[test]
fn convex_quadrilateral_stays_one_block() {
    let r = Region::new(vec![v(0., 0.), v(4., 0.5), v(3.5, 3.), v(0.2, 2.5)], vec![]).unwrap();
    let d = decompose(&r, &thesis()).unwrap();
    assert_eq!(d.blocks.len(), 1);
    assert!(d.cuts.is_empty());
    let mut c = d.blocks[0].corners;
    c.sort_unstable();
    assert_eq!(c, [0, 1, 2, 3]);
    assert!(!d.blocks[0].triangle);
    check_tiling(&r, &d);
}

#[test]
fn square_with_square_hole_gets_at_least_four_blocks() {
    let r = Region::new(
        vec![v(0., 0.), v(10., 0.), v(10., 10.), v(0., 10.)],
        vec![vec![v(4., 4.), v(6., 4.), v(6., 6.), v(4., 6.)]],
    )
    .unwrap();
    let d = decompose(&r, &thesis()).unwrap();
    assert!(d.blocks.len() >= 4, "{} blocks", d.blocks.len());
    check_tiling(&r, &d);
    // the hole boundary is split among the blocks: every hole edge is on some block
    let hole_edges: usize = d
        .blocks
        .iter()
        .map(|b| {
            b.edges
                .iter()
                .filter(|e| **e == EdgeKind::Boundary { ring: 1 })
                .count()
        })
        .sum();
    assert!(hole_edges >= 4);
    let tol = Tolerances::default();
    for b in &d.blocks {
        assert!(
            d.block_admissible(b.id, &tol),
            "block {} not admissible",
            b.id
        );
    }
}

/// A triangle with interior angles (in degrees) `a` at the origin, `b` at (1, 0).
fn triangle(a: f64, b: f64) -> Vec<DVec2> {
    let (ar, br) = (a.to_radians(), b.to_radians());
    let c = std::f64::consts::PI - ar - br;
    // law of sines: side opposite to the third vertex is 1; |P0 P2| = sin(b)/sin(c)
    let l = br.sin() / c.sin();
    vec![v(0., 0.), v(1., 0.), v(l * ar.cos(), l * ar.sin())]
}

/// Expected triangle-block corners: for each critical vertex the two points at distance
/// d = 0.25 · (shorter incident edge) on its edges; the non-critical vertices if only one is
/// critical.
fn expected_triangle_corners(t: &[DVec2], critical: &[usize]) -> Vec<DVec2> {
    let mut out = Vec::new();
    for i in 0..3 {
        let p = t[i];
        let prev = t[(i + 2) % 3];
        let next = t[(i + 1) % 3];
        if critical.contains(&i) {
            let d = 0.25 * p.distance(prev).min(p.distance(next));
            out.push(p + (prev - p).normalize() * d);
            out.push(p + (next - p).normalize() * d);
        } else if critical.len() == 1 {
            out.push(p);
        }
    }
    out
}

fn assert_triangle_block(angles: (f64, f64), critical: &[usize]) {
    let t = triangle(angles.0, angles.1);
    let r = Region::new(t.clone(), vec![]).unwrap();
    let d = decompose(&r, &thesis()).unwrap();
    assert_eq!(d.blocks.len(), 1, "a triangle is a leaf");
    let b = &d.blocks[0];
    assert!(b.triangle);
    assert_eq!(b.ring.len(), 3 + 2 * critical.len());
    let got: Vec<DVec2> = b.corners.iter().map(|&k| b.ring[k]).collect();
    for e in expected_triangle_corners(&t, critical) {
        assert!(
            got.iter().any(|g| g.distance(e) < 1e-12),
            "expected corner {e} in {got:?}"
        );
    }
    check_tiling(&r, &d);
}

#[test]
fn thesis_triangle_102_50_28() {
    // 102° at the origin, 50° at (1,0), 28° at the third vertex (index 2)
    assert_triangle_block((102.0, 50.0), &[2]);
}

#[test]
fn thesis_triangle_24_78_78() {
    assert_triangle_block((24.0, 78.0), &[0]);
}

#[test]
fn thesis_triangle_15_20_145() {
    assert_triangle_block((15.0, 20.0), &[0, 1]);
}

/// The default triangle-block rule: every vertex is a corner, critical or not, and the fourth
/// corner is the midpoint of the longest side (the side opposite the largest angle), a point
/// inserted on it: a ring of 4 points.
fn assert_sharp_tips_are_corners(angles: (f64, f64), longest: (usize, usize)) {
    let t = triangle(angles.0, angles.1);
    let r = Region::new(t.clone(), vec![]).unwrap();
    let opts = DecomposeOptions::default().layout(unamalla_decompose::Layout::Concavity);
    let d = decompose(&r, &opts).unwrap();
    assert_eq!(d.blocks.len(), 1, "a triangle is a leaf");
    let b = &d.blocks[0];
    assert!(b.triangle);
    assert_eq!(b.ring.len(), 4);
    let got: Vec<DVec2> = b.corners.iter().map(|&k| b.ring[k]).collect();
    let mid = 0.5 * (t[longest.0] + t[longest.1]);
    for e in [t[0], t[1], t[2], mid] {
        assert!(
            got.iter().any(|g| g.distance(e) < 1e-12),
            "expected corner {e} in {got:?}"
        );
    }
    check_tiling(&r, &d);
}

#[test]
fn a_sharp_tip_is_a_corner_by_default() {
    // 28° at vertex 2 is critical; the largest angle, 102°, is at the origin: the longest
    // side joins vertices 1 and 2
    assert_sharp_tips_are_corners((102.0, 50.0), (1, 2));
    // 15° and 20° (both critical) at vertices 0 and 1, 145° at vertex 2: the longest side
    // joins vertices 0 and 1
    assert_sharp_tips_are_corners((15.0, 20.0), (0, 1));
}

fn rhombus_with_three_holes() -> Region {
    // long diagonal 10, short 3.2: acute angles 2·atan(1.6/5) ≈ 35.5° (critical)
    let outer = vec![v(-5., 0.), v(0., -1.6), v(5., 0.), v(0., 1.6)];
    let sq = |cx: f64| {
        let h = 0.25;
        vec![v(cx - h, -h), v(cx - h, h), v(cx + h, h), v(cx + h, -h)]
    };
    Region::new(outer, vec![sq(-2.0), sq(0.0), sq(2.0)]).unwrap()
}

#[test]
fn rhombus_with_three_holes_is_admissible() {
    let r = rhombus_with_three_holes();
    let d = decompose(&r, &thesis()).unwrap();
    check_tiling(&r, &d);
    let tol = Tolerances::default();
    for b in &d.blocks {
        assert!(
            d.block_admissible(b.id, &tol),
            "block {} not admissible: {:?}",
            b.id,
            b.ring
        );
    }
    // the two sharp corners end up in triangle blocks
    for tip in [v(-5., 0.), v(5., 0.)] {
        let owner: Vec<_> = d.blocks.iter().filter(|b| b.ring.contains(&tip)).collect();
        assert_eq!(owner.len(), 1);
        assert!(owner[0].triangle, "tip {tip} is in a non-triangle block");
    }
    assert!(d.blocks.len() >= 3 * 4 / 2 + 2, "{} blocks", d.blocks.len());
}

#[test]
fn result_does_not_depend_on_ring_numbering() {
    // a U-shaped region with one hole in the base; rotate the starting vertex of each ring
    let outer = vec![
        v(0., 0.),
        v(9., 0.),
        v(9., 7.),
        v(6., 7.),
        v(6., 3.),
        v(3., 3.),
        v(3., 7.),
        v(0., 7.),
    ];
    let hole = vec![v(4., 1.), v(4., 2.), v(5., 2.), v(5., 1.)];
    let cut_set = |d: &Decomposition| {
        let mut s: Vec<[f64; 4]> = d
            .cuts
            .iter()
            .map(|c| {
                let (a, b) = if (c.a.x, c.a.y) < (c.b.x, c.b.y) {
                    (c.a, c.b)
                } else {
                    (c.b, c.a)
                };
                [a.x, a.y, b.x, b.y]
            })
            .collect();
        s.sort_by(|x, y| x.partial_cmp(y).unwrap());
        s
    };
    let base = {
        let r = Region::new(outer.clone(), vec![hole.clone()]).unwrap();
        let d = decompose(&r, &thesis()).unwrap();
        check_tiling(&r, &d);
        (d.blocks.len(), cut_set(&d))
    };
    for shift in 1..outer.len() {
        let mut o = outer.clone();
        o.rotate_left(shift);
        let mut h = hole.clone();
        h.rotate_left(shift % 4);
        let r = Region::new(o, vec![h]).unwrap();
        let d = decompose(&r, &thesis()).unwrap();
        assert_eq!(d.blocks.len(), base.0, "shift {shift}");
        let cs = cut_set(&d);
        assert_eq!(cs.len(), base.1.len());
        for (x, y) in cs.iter().zip(&base.1) {
            for k in 0..4 {
                assert!(
                    (x[k] - y[k]).abs() < 1e-9,
                    "shift {shift}: {cs:?} vs {:?}",
                    base.1
                );
            }
        }
    }
}

#[test]
fn side_curves_cover_the_ring_and_separate_cuts() {
    let r = rhombus_with_three_holes();
    let d = decompose(&r, &thesis()).unwrap();
    for b in &d.blocks {
        let sides = b.side_curves();
        let edges: usize = sides.iter().flatten().map(|q| q.points.len() - 1).sum();
        assert_eq!(edges, b.ring.len());
        for (s, side) in sides.iter().enumerate() {
            assert_eq!(side[0].points[0], b.ring[b.corners[s]]);
            assert_eq!(
                side.last().unwrap().points.last().copied(),
                Some(b.ring[b.corners[(s + 1) % 4]])
            );
            for q in side {
                if let EdgeKind::Cut { cut, neighbour } = q.kind {
                    assert_eq!(q.points.len(), 2, "a cut is one edge");
                    let c = d.cuts[cut];
                    assert!(c.blocks.contains(&neighbour) && c.blocks.contains(&b.id));
                }
            }
        }
    }
}

/// Interior (left) angle at `p` of the counter-clockwise chain `a → p → c`, in degrees.
fn left_angle_deg(a: DVec2, p: DVec2, c: DVec2) -> f64 {
    let (u, w) = (c - p, a - p);
    let ang = (u.x * w.y - u.y * w.x).atan2(u.dot(w)).to_degrees();
    if ang < 0.0 {
        ang + 360.0
    } else {
        ang
    }
}

#[test]
fn a_needle_tip_makes_a_piece_not_approximately_convex() {
    // a 100 × 40 rectangle with a slit 0.2 wide and 30 deep cut into its top side: a thin spit
    // of the exterior whose tip (50, 10) has the region's angle 360° − 2·atan(0.1/30) ≈ 359.6°;
    // κ₁–κ₃ barely notice it
    let ring = vec![
        v(0., 0.),
        v(100., 0.),
        v(100., 40.),
        v(50.1, 40.),
        v(50., 10.),
        v(49.9, 40.),
        v(0., 40.),
    ];
    let tip = left_angle_deg(ring[3], ring[4], ring[5]);
    let expected = 360.0 - 2.0 * (0.1f64 / 30.0).atan().to_degrees();
    assert!((tip - expected).abs() < 1e-9, "{tip} vs {expected}");
    let tol = Tolerances::default();
    let c = unamalla_decompose::concavity(&ring);
    assert!((c.max_angle.to_degrees() - expected).abs() < 1e-9);
    // the area and distance criteria alone would accept it …
    let loose = Tolerances {
        theta_plus: std::f64::consts::TAU,
        ..tol
    };
    assert!(c.kappa2 < 0.01 && c.kappa2 <= tol.tau2_minus);
    // … the spike criterion (θ₊ = 350° < 359.6°) does not
    assert!(!c.approximately_convex(&tol));
    let without_spike = c.kappa1 <= loose.tau1_minus && c.kappa3 <= loose.tau3_minus;
    assert_eq!(c.approximately_convex(&loose), without_spike);
}

/// The largest interior angle over all blocks, in degrees.
fn largest_block_angle(d: &Decomposition) -> f64 {
    d.blocks
        .iter()
        .flat_map(|b| {
            let n = b.ring.len();
            (0..n).map(move |i| {
                left_angle_deg(b.ring[(i + n - 1) % n], b.ring[i], b.ring[(i + 1) % n])
            })
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_spike_tip_gets_a_cut_so_no_block_keeps_it() {
    let theta_plus = Tolerances::default().theta_plus.to_degrees();
    // a 100 × 100 square with a slit 0.2 wide and 6 deep from its top side: the slit's tip
    // (50, 94) has the region's angle 360° − 2·atan(0.1/6) ≈ 358.1°, while κ₁ ≈ 0.03,
    // κ₂ ≈ 10⁻⁴ and κ₃ ≈ 6/70.7 ≈ 0.085 all pass their tolerances
    let tip = v(50., 94.);
    let r = Region::new(
        vec![
            v(0., 0.),
            v(100., 0.),
            v(100., 100.),
            v(50.1, 100.),
            tip,
            v(49.9, 100.),
            v(0., 100.),
        ],
        vec![],
    )
    .unwrap();
    // without the spike criterion the square stays one block with the tip inside a side
    let mut opts = thesis();
    opts.tolerances.theta_plus = std::f64::consts::TAU;
    let d = decompose(&r, &opts).unwrap();
    assert_eq!(d.blocks.len(), 1);
    let expected = 360.0 - 2.0 * (0.1f64 / 6.0).atan().to_degrees();
    assert!((largest_block_angle(&d) - expected).abs() < 1e-9);
    // with it a cut starts at the tip and leaves two angles ≤ 180° there
    let d = decompose(&r, &thesis()).unwrap();
    check_tiling(&r, &d);
    assert!(
        largest_block_angle(&d) <= 180.0,
        "{}",
        largest_block_angle(&d)
    );
    assert!(largest_block_angle(&d) <= theta_plus);
    let at_tip = d.blocks.iter().filter(|b| b.ring.contains(&tip)).count();
    assert_eq!(at_tip, 2);
}

#[test]
fn a_sliver_island_keeps_no_spike_in_any_block() {
    // a sliver island of gulf-of-mexico in miniature: an island 60 long and 2 wide, tip
    // angle 2·atan(1/60) ≈ 1.9°, so the region's angle at the tip is ≈ 358.1° > θ₊ = 350°
    let r = Region::new(
        vec![v(0., 0.), v(100., 0.), v(100., 100.), v(0., 100.)],
        vec![vec![v(20., 50.), v(80., 51.), v(80., 49.)]],
    )
    .unwrap();
    let tip = v(20., 50.);
    let d = decompose(&r, &thesis()).unwrap();
    check_tiling(&r, &d);
    let theta_plus = Tolerances::default().theta_plus.to_degrees();
    assert!(largest_block_angle(&d) <= theta_plus);
    // the tip's 358° are shared by at least two blocks (a cut starts there)
    let at_tip = d.blocks.iter().filter(|b| b.ring.contains(&tip)).count();
    assert!(at_tip >= 2, "the tip is a vertex of {at_tip} block(s)");
}

/// An L of 2 × 2 units (a unit notch) at the origin and moved to (10⁹, 10⁹), where an ulp of
/// the coordinates is 1.2·10⁻⁷: the same layout (one cut from the reflex vertex, two blocks)
/// and a valid tiling — the cut test once shrank the cut by a relative 10⁻⁹, which does not move
/// its ends at that offset, and rejected it as touching the boundary.
#[test]
fn an_l_far_from_the_origin_is_cut_like_the_l_at_the_origin() {
    let l = |o: f64| {
        Region::new(
            vec![
                v(o, o),
                v(o + 2.0, o),
                v(o + 2.0, o + 1.0),
                v(o + 1.0, o + 1.0),
                v(o + 1.0, o + 2.0),
                v(o, o + 2.0),
            ],
            vec![],
        )
        .unwrap()
    };
    let r0 = l(0.0);
    let d0 = decompose(&r0, &thesis()).unwrap();
    assert_eq!((d0.blocks.len(), d0.cuts.len()), (2, 1));
    let r9 = l(1e9);
    let d9 = decompose(&r9, &thesis()).unwrap();
    assert_eq!((d9.blocks.len(), d9.cuts.len()), (2, 1));
    // the cut starts at the reflex vertex (o + 1, o + 1) and is the same cut as at the origin
    let (c0, c9) = (&d0.cuts[0], &d9.cuts[0]);
    assert_eq!(c9.a - DVec2::splat(1e9), c0.a);
    assert_eq!(c9.b - DVec2::splat(1e9), c0.b);
    check_tiling(&r9, &d9);
}
