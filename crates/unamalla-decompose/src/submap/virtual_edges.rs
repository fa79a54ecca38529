//! Step 3: virtual edges from a constrained Delaunay triangulation of the boundary discretization
//! and loop surgery ([Ruiz-Gironés & Sarrate, Fig 8, Fig 10, (7)]; the angle score, the labels of
//! the junction vertices and the recheck of (1) on the merged loop are ours).

use std::f64::consts::FRAC_PI_2;

use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use unamalla_compat_ilp::{classify_vertices_to_sum, VertexClassOptions};
use unamalla_mesh::geometry::point_segment_distance;
use unamalla_mesh::{DVec2, Region};

use super::classify::{right_deviation, rule_label, turning_angle, LPoint};
use super::{EdgeTag, SubmapError, VirtualEdge};

/// The simply connected loop and the virtual edges that made it.
pub(crate) struct Merged {
    pub points: Vec<LPoint>,
    pub edges: Vec<VirtualEdge>,
    pub repaired: bool,
}

/// Where a point lies on a loop.
#[derive(Debug, Clone, Copy)]
enum Loc {
    /// At loop point `k`.
    Vertex(usize),
    /// Strictly inside the segment `k → k+1`.
    Edge(usize),
}

fn locate(lp: &[LPoint], p: DVec2, ring: usize, tol: f64) -> Option<Loc> {
    let n = lp.len();
    if let Some(k) = (0..n).find(|&k| lp[k].pos.distance(p) <= tol) {
        return Some(Loc::Vertex(k));
    }
    (0..n)
        .filter(|&k| lp[k].tag == EdgeTag::Boundary(ring))
        .map(|k| (k, point_segment_distance(p, lp[k].pos, lp[(k + 1) % n].pos)))
        .filter(|&(_, d)| d <= tol)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| Loc::Edge(k))
}

/// Incoming and outgoing tangents at a located point.
fn tangents(lp: &[LPoint], loc: Loc) -> (DVec2, DVec2) {
    let n = lp.len();
    match loc {
        Loc::Vertex(k) => (
            lp[k].pos - lp[(k + n - 1) % n].pos,
            lp[(k + 1) % n].pos - lp[k].pos,
        ),
        Loc::Edge(k) => {
            let d = lp[(k + 1) % n].pos - lp[k].pos;
            (d, d)
        }
    }
}

/// The four turning angles a virtual edge `ab` (from `la` on the loop `current` to `lb` on
/// `hole`) creates: at A entering the edge, at B entering the hole, at B leaving it, at A
/// leaving the edge.
fn junction_turnings(current: &[LPoint], la: Loc, hole: &[LPoint], lb: Loc, ab: DVec2) -> [f64; 4] {
    let (ta_in, ta_out) = tangents(current, la);
    let (tb_in, tb_out) = tangents(hole, lb);
    [
        turning_angle(ta_in, ab),
        turning_angle(ab, tb_out),
        turning_angle(tb_in, -ab),
        turning_angle(-ab, ta_out),
    ]
}

/// Inserts `p` (if it is not a loop point already) and returns its index.
fn insert(lp: &mut Vec<LPoint>, p: DVec2, loc: Loc, key: &mut usize) -> usize {
    match loc {
        Loc::Vertex(k) => k,
        Loc::Edge(k) => {
            let tag = lp[k].tag;
            lp.insert(
                k + 1,
                LPoint {
                    pos: p,
                    key: *key,
                    label: 0,
                    brk: false,
                    tag,
                    junction: false,
                },
            );
            *key += 1;
            k + 1
        }
    }
}

/// Candidate score: max deviation, sum of deviations (radians), length, then coordinates.
type Score = (f64, f64, f64, [f64; 4]);

fn better(a: &Score, b: &Score) -> bool {
    const TOL: f64 = 1e-9;
    if (a.0 - b.0).abs() > TOL {
        return a.0 < b.0;
    }
    if (a.1 - b.1).abs() > TOL {
        return a.1 < b.1;
    }
    if (a.2 - b.2).abs() > TOL * (1.0 + a.2.abs()) {
        return a.2 < b.2;
    }
    a.3 < b.3
}

/// Joins every hole to the outer loop by virtual edges (the paper's four phases, Fig 10) and
/// relabels the junction vertices (angle rule, then ILP (6) on the merged loop if (1) fails).
pub(crate) fn connect(
    region: &Region,
    mut rings: Vec<Vec<LPoint>>,
    h: f64,
    banned: &[(DVec2, DVec2)],
) -> Result<Merged, SubmapError> {
    let mut key = rings.iter().map(|r| r.len()).sum::<usize>();
    let mut current = rings.remove(0);
    if rings.is_empty() {
        return Ok(Merged {
            points: current,
            edges: Vec::new(),
            repaired: false,
        });
    }
    let (lo, hi) = region.bounding_box();
    let tol = 1e-9 * (hi - lo).length().max(f64::MIN_POSITIVE);

    // boundary discretization at the target size (the CDT's only vertices), plus the feet of the
    // perpendiculars from every hole vertex onto the edges of the other rings, so that exactly
    // axis-aligned virtual edges are available (the points still lie on the boundary, as the paper
    // requires; skipped for very large inputs)
    let ring_pts: Vec<&[DVec2]> = region.rings().map(|r| r.points()).collect();
    let hole_vertices: usize = ring_pts[1..].iter().map(|r| r.len()).sum();
    let all_edges: usize = ring_pts.iter().map(|r| r.len()).sum();
    let mut extra: Vec<Vec<Vec<f64>>> =
        ring_pts.iter().map(|r| vec![Vec::new(); r.len()]).collect();
    if hole_vertices * all_edges <= 4_000_000 {
        for (hr, hole) in ring_pts.iter().enumerate().skip(1) {
            for &v in hole.iter() {
                for (r, pts) in ring_pts.iter().enumerate() {
                    if r == hr {
                        continue;
                    }
                    for i in 0..pts.len() {
                        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                        let d = b - a;
                        let t = (v - a).dot(d) / d.length_squared();
                        if t > 1e-9 && t < 1.0 - 1e-9 {
                            extra[r][i].push(t);
                        }
                    }
                }
            }
        }
    }
    let mut disc: Vec<(usize, DVec2)> = Vec::new();
    let mut ring_start = Vec::new();
    for (r, pts) in ring_pts.iter().enumerate() {
        ring_start.push(disc.len());
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            let k = ((a.distance(b) / h).round() as usize).max(1);
            let mut ts: Vec<f64> = (0..k).map(|j| j as f64 / k as f64).collect();
            ts.extend_from_slice(&extra[r][i]);
            ts.sort_by(f64::total_cmp);
            ts.dedup_by(|x, y| (*x - *y).abs() * a.distance(b) <= tol);
            for t in ts {
                disc.push((r, a.lerp(b, t)));
            }
        }
    }
    ring_start.push(disc.len());
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(disc.len());
    let mut owner: Vec<Option<usize>> = Vec::new();
    for (i, &(_, p)) in disc.iter().enumerate() {
        let hd = cdt
            .insert(Point2::new(p.x, p.y))
            .map_err(|e| SubmapError::Triangulation {
                x: p.x,
                y: p.y,
                message: format!("{e:?}"),
            })?;
        if owner.len() <= hd.index() {
            owner.resize(hd.index() + 1, None);
        }
        if owner[hd.index()].is_none() {
            owner[hd.index()] = Some(i);
        }
        handles.push(hd);
    }
    for r in 0..ring_start.len() - 1 {
        let (s, e) = (ring_start[r], ring_start[r + 1]);
        for i in s..e {
            let j = if i + 1 == e { s } else { i + 1 };
            if handles[i] != handles[j] {
                cdt.add_constraint(handles[i], handles[j]);
            }
        }
    }
    let mut candidates: Vec<(usize, usize)> = Vec::new();
    for e in cdt.undirected_edges() {
        if cdt.is_constraint_edge(e.fix()) {
            continue;
        }
        let [u, v] = e.vertices();
        if let (Some(Some(i)), Some(Some(j))) =
            (owner.get(u.fix().index()), owner.get(v.fix().index()))
        {
            if disc[*i].0 != disc[*j].0 {
                candidates.push((*i, *j));
            }
        }
    }
    candidates.sort_unstable();

    let index = region.edge_index();
    let nrings = region.holes().len() + 1;
    let mut merged = vec![false; nrings];
    merged[0] = true;
    // hole loops by ring number (rings[k − 1] is ring k)
    let mut holes: Vec<Option<Vec<LPoint>>> = std::iter::once(None)
        .chain(rings.into_iter().map(Some))
        .collect();
    let mut junctions: Vec<DVec2> = Vec::new();
    let mut edges: Vec<VirtualEdge> = Vec::new();
    while merged.iter().any(|m| !m) {
        let mut best: Option<(Score, usize, DVec2, usize, DVec2, [f64; 4])> = None;
        for &(i, j) in &candidates {
            let ((ra, pa), (rb, pb)) = match (merged[disc[i].0], merged[disc[j].0]) {
                (true, false) => (disc[i], disc[j]),
                (false, true) => (disc[j], disc[i]),
                _ => continue,
            };
            if junctions
                .iter()
                .any(|q| q.distance(pa) <= tol || q.distance(pb) <= tol)
            {
                continue;
            }
            if banned
                .iter()
                .any(|(a, b)| a.distance(pa) <= tol && b.distance(pb) <= tol)
            {
                continue;
            }
            if !region.segment_inside_with(&index, pa, pb) {
                continue;
            }
            let Some(hole) = holes[rb].as_ref() else {
                continue;
            };
            let (Some(la), Some(lb)) = (locate(&current, pa, ra, tol), locate(hole, pb, rb, tol))
            else {
                continue;
            };
            let ab = pb - pa;
            let th = junction_turnings(&current, la, hole, lb, ab);
            let devs = th.map(right_deviation);
            let score: Score = (
                devs.iter().copied().fold(0.0, f64::max),
                devs.iter().sum(),
                ab.length(),
                [pa.x, pa.y, pb.x, pb.y],
            );
            if best.as_ref().is_none_or(|b| better(&score, &b.0)) {
                best = Some((score, ra, pa, rb, pb, th));
            }
        }
        let Some((score, ra, pa, rb, pb, th)) = best else {
            let hole = merged.iter().position(|m| !m).unwrap_or(1) - 1;
            return Err(SubmapError::NoVirtualEdge { hole });
        };
        let hole = holes[rb].take().unwrap_or_default();
        splice(
            &mut current,
            hole,
            (pa, ra),
            (pb, rb),
            edges.len(),
            &mut key,
            tol,
        )?;
        merged[rb] = true;
        junctions.push(pa);
        junctions.push(pb);
        edges.push(VirtualEdge {
            a: pa,
            b: pb,
            hole: rb - 1,
            junction_angles_deg: th.map(f64::to_degrees),
            max_deviation_deg: score.0.to_degrees(),
        });
    }

    let repaired = label_junctions(&mut current)?;
    Ok(Merged {
        points: current,
        edges,
        repaired,
    })
}

/// Loop surgery for one virtual edge `v` from `pa` (on the current loop, ring `ra`) to `pb` (on
/// `hole`, ring `rb`): `outer…A → (A→B) → hole from B around to B → (B→A) → A…outer`.
fn splice(
    current: &mut Vec<LPoint>,
    mut hole: Vec<LPoint>,
    (pa, ra): (DVec2, usize),
    (pb, rb): (DVec2, usize),
    v: usize,
    key: &mut usize,
    tol: f64,
) -> Result<(), SubmapError> {
    let (Some(la), Some(lb)) = (locate(current, pa, ra, tol), locate(&hole, pb, rb, tol)) else {
        return Err(SubmapError::NoVirtualEdge { hole: rb - 1 });
    };
    let ia = insert(current, pa, la, key);
    let ib = insert(&mut hole, pb, lb, key);
    let mut a1 = current[ia].clone();
    a1.tag = EdgeTag::Virtual(v);
    a1.brk = true;
    a1.junction = true;
    let mut a2 = current[ia].clone();
    a2.brk = true;
    a2.junction = true;
    hole.rotate_left(ib);
    let mut b1 = hole[0].clone();
    b1.brk = true;
    b1.junction = true;
    let mut b2 = b1.clone();
    b2.tag = EdgeTag::Virtual(v);
    let mut next = Vec::with_capacity(current.len() + hole.len() + 3);
    next.extend_from_slice(&current[..ia]);
    next.push(a1);
    next.push(b1);
    next.extend_from_slice(&hole[1..]);
    next.push(b2);
    next.push(a2);
    next.extend_from_slice(&current[ia + 1..]);
    *current = next;
    Ok(())
}

/// Junction labels by the angle rule, then (1) on the merged loop: if `Σ label ≠ 4`, ILP (6)
/// relabels the junctions with the ring labels pinned (weight 1000; our rule, the paper does not
/// say how the junctions are classified). Returns
/// whether the ILP ran.
fn label_junctions(current: &mut [LPoint]) -> Result<bool, SubmapError> {
    let n = current.len();
    let alpha_at = |lp: &[LPoint], k: usize| {
        turning_angle(
            lp[k].pos - lp[(k + n - 1) % n].pos,
            lp[(k + 1) % n].pos - lp[k].pos,
        ) / FRAC_PI_2
    };
    for k in 0..n {
        if current[k].junction {
            current[k].label = rule_label(alpha_at(current, k));
        }
    }
    let sum: i64 = current.iter().map(|p| p.label).sum();
    if sum == 4 {
        return Ok(false);
    }
    let abar: Vec<f64> = (0..n)
        .map(|k| {
            if current[k].junction {
                alpha_at(current, k)
            } else {
                current[k].label as f64
            }
        })
        .collect();
    let w: Vec<f64> = current
        .iter()
        .map(|p| if p.junction { 1.0 } else { 1000.0 })
        .collect();
    let opts = VertexClassOptions::default()
        .rho(Some(w.clone()))
        .omega(Some(w));
    let c = classify_vertices_to_sum(&abar, 4, &opts).map_err(SubmapError::MergedClassification)?;
    for (p, &l) in current.iter_mut().zip(&c.labels) {
        p.label = l as i64;
    }
    Ok(true)
}

/// The merged loop for virtual edges chosen beforehand (White's method, [`super::white`]):
/// `chosen[k] = (rb, pa, pb)` joins hole ring `rb` at `pb` to the outer ring at `pa`, in that
/// order; each segment must lie inside the region and no two may share an end.
pub(crate) fn connect_prescribed(
    region: &Region,
    mut rings: Vec<Vec<LPoint>>,
    chosen: &[(usize, DVec2, DVec2)],
) -> Result<Merged, SubmapError> {
    let mut key = rings.iter().map(|r| r.len()).sum::<usize>();
    let mut current = rings.remove(0);
    let (lo, hi) = region.bounding_box();
    let tol = 1e-9 * (hi - lo).length().max(f64::MIN_POSITIVE);
    let index = region.edge_index();
    let mut holes: Vec<Option<Vec<LPoint>>> = std::iter::once(None)
        .chain(rings.into_iter().map(Some))
        .collect();
    let mut edges: Vec<VirtualEdge> = Vec::new();
    let mut junctions: Vec<DVec2> = Vec::new();
    for &(rb, pa, pb) in chosen {
        let hole_id = rb.wrapping_sub(1);
        let Some(hole) = holes.get_mut(rb).and_then(Option::take) else {
            return Err(SubmapError::NoVirtualEdge { hole: hole_id });
        };
        if junctions
            .iter()
            .any(|q| q.distance(pa) <= tol || q.distance(pb) <= tol)
            || !region.segment_inside_with(&index, pa, pb)
        {
            return Err(SubmapError::NoVirtualEdge { hole: hole_id });
        }
        let (Some(la), Some(lb)) = (locate(&current, pa, 0, tol), locate(&hole, pb, rb, tol))
        else {
            return Err(SubmapError::NoVirtualEdge { hole: hole_id });
        };
        let th = junction_turnings(&current, la, &hole, lb, pb - pa);
        splice(
            &mut current,
            hole,
            (pa, 0),
            (pb, rb),
            edges.len(),
            &mut key,
            tol,
        )?;
        junctions.push(pa);
        junctions.push(pb);
        edges.push(VirtualEdge {
            a: pa,
            b: pb,
            hole: hole_id,
            junction_angles_deg: th.map(f64::to_degrees),
            max_deviation_deg: th
                .map(right_deviation)
                .iter()
                .copied()
                .fold(0.0, f64::max)
                .to_degrees(),
        });
    }
    if let Some(rb) = holes.iter().position(Option::is_some) {
        return Err(SubmapError::NoVirtualEdge { hole: rb - 1 });
    }
    let repaired = label_junctions(&mut current)?;
    Ok(Merged {
        points: current,
        edges,
        repaired,
    })
}
