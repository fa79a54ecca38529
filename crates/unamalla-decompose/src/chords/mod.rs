//! The chord layout: block-layout cuts chosen from the shape's chordal axis (module docs in
//! the crate root, section "Chord layout").
//!
//! The boundary is sampled every `s` (plus the feet of the perpendiculars from ring vertices
//! onto edges closer than `s/2`, so that a neck narrower than the spacing is seen at its true
//! width: `neck_feet`), the samples are triangulated by a constrained Delaunay
//! triangulation (`spade`) with the rings as constraints, and the triangles inside the region
//! are kept (parity flood from the convex hull). Every interior edge of that triangulation is a
//! **chord**: a straight segment between two boundary points inside the region, and no two
//! chords cross. The chords are the edges of the dual graph (triangles as nodes), whose
//! spanning skeleton is the chordal axis of Prasad (1997). Cuts are taken from the chords:
//!
//! 1. **Hole bridges**: a minimum spanning tree of the rings (outer ring and holes), each
//!    ring pair weighted by its cheapest chord `ℓ·(1 + ḡ)` (ℓ the chord length, ḡ the mean angle
//!    penalty of the four new angles at its ends), then **closing chords** until every bridge
//!    lies on a cycle of bridges (greedy by cost; a bridge that lies on no cycle would have the
//!    same block on both sides). A chord that closes a cycle with a bridge of the same ring pair
//!    must split the hole's perimeter into arcs of at least [`MIN_HOLE_ARC`] of it.
//! 2. **Transverse cuts**: in each simply connected piece left by the bridges the dual graph is
//!    a tree, so every chord c of length w splits the piece into two parts of areas A₁, A₂
//!    (subtree sums). Its score is `min(A₁, A₂)/w²` — how many chord widths the smaller part
//!    extends beyond the chord — discounted by `(1 − ½ḡ)`. The best chord is cut when its score
//!    reaches the aspect threshold `T` ([`DEFAULT_ASPECT`]), and both parts are treated again.
//!    The score is large at a **neck** (small w, both sides big: an arm or a peninsula is
//!    separated at its neck) and at the middle of a long **channel** or elongated island (the
//!    recursion cuts it into a chain of blocks whose length is at most ≈ 2T widths), and small
//!    at small capes and inlets (a half disc at its base scores π/8 ≈ 0.39), which are left to
//!    the block they belong to.
//!
//! Chords ending within `max(s, w/2)` of an earlier cut end are skipped (no fans), as are
//! chords making an angle below [`MIN_END_ANGLE_DEG`] with the boundary.
//!
//! Files: `mesh` (the sampled boundary and its constrained Delaunay triangulation), `tree`
//! (the dual tree of a simply connected piece), `arms` (the neck score and the arm chords of
//! a block); the layout itself (`layout_cuts`) is here.

use std::collections::{BTreeMap, HashMap, HashSet, VecDeque};
use std::f64::consts::PI;

use unamalla_mesh::{DVec2, Region};

mod arms;
mod mesh;
#[cfg(test)]
mod tests;
mod tree;

pub(crate) use arms::arm_chord;
pub use arms::neck_score;

use self::mesh::{ChordError, ChordMesh};
use self::tree::{PieceTree, TreeScratch};

/// Default aspect threshold `T` of a transverse cut: the smaller side must extend at least
/// `T` chord widths (area ≥ T·w²).
pub const DEFAULT_ASPECT: f64 = 1.5;
/// Smallest angle between a layout chord and the boundary at its ends.
pub const MIN_END_ANGLE_DEG: f64 = 50.0;
/// A closing chord of a ring pair that already has a bridge must leave arcs of at least this
/// fraction of the hole's perimeter on either side of the two chords.
pub const MIN_HOLE_ARC: f64 = 0.25;

/// The layout cuts of a region, in the order they must be applied (bridges from the outer
/// ring outwards, closing chords, transverse cuts), as point pairs on the boundary.
pub(crate) fn layout_cuts(
    region: &Region,
    spacing: f64,
    aspect: f64,
    min_area: f64,
) -> Result<Vec<(DVec2, DVec2)>, ChordError> {
    let m = ChordMesh::new(region, spacing)?;
    let min_angle = MIN_END_ANGLE_DEG.to_radians();
    let mut cut_set: HashSet<(usize, usize)> = HashSet::new();
    let mut order: Vec<(usize, usize)> = Vec::new();
    let mut ends: Vec<usize> = Vec::new();

    // 1. hole bridges
    let nr = m.ring_start.len() - 1;
    if nr > 1 {
        let mut inter: Vec<(f64, usize, usize)> = Vec::new();
        let mut angle_of: BTreeMap<(usize, usize), f64> = BTreeMap::new();
        for (a, b) in m.chords() {
            if m.ring[a] == m.ring[b] {
                continue;
            }
            let (amin, g) = m.chord_angles(a, b);
            angle_of.insert((a, b), amin);
            let cost = m.pts[a].distance(m.pts[b]) * (1.0 + g);
            inter.push((cost, a, b));
        }
        let bridge_angle = min_angle.min(PI / 6.0);
        inter.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        // Kruskal
        let mut parent: Vec<usize> = (0..nr).collect();
        fn find(p: &mut [usize], x: usize) -> usize {
            let mut x = x;
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        let mut tree: Vec<(usize, usize)> = Vec::new();
        let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); nr]; // (ring, tree edge id)
        let mut used = vec![false; inter.len()];
        for (k, &(_, a, b)) in inter.iter().enumerate() {
            let (ra, rb) = (m.ring[a], m.ring[b]);
            let (x, y) = (find(&mut parent, ra), find(&mut parent, rb));
            if x == y || angle_of.get(&(a, b)).copied().unwrap_or(0.0) < bridge_angle {
                continue;
            }
            if ends.iter().any(|&e| e == a || e == b) {
                continue;
            }
            parent[x] = y;
            adj[ra].push((rb, tree.len()));
            adj[rb].push((ra, tree.len()));
            tree.push((a, b));
            ends.extend([a, b]);
            used[k] = true;
        }
        if tree.len() != nr - 1 {
            return Err(ChordError(format!(
                "the rings are not connected by admissible chords ({} of {} bridges)",
                tree.len(),
                nr - 1
            )));
        }
        // BFS order from the outer ring; parent edge of each ring
        let mut depth = vec![usize::MAX; nr];
        let mut up: Vec<Option<(usize, usize)>> = vec![None; nr]; // (parent ring, edge)
        depth[0] = 0;
        let mut q = VecDeque::from([0usize]);
        let mut bfs_edges = Vec::new();
        while let Some(r) = q.pop_front() {
            let mut next = adj[r].clone();
            next.sort_unstable();
            for (s, e) in next {
                if depth[s] == usize::MAX {
                    depth[s] = depth[r] + 1;
                    up[s] = Some((r, e));
                    bfs_edges.push(e);
                    q.push_back(s);
                }
            }
        }
        for &e in &bfs_edges {
            order.push(tree[e]);
        }
        // closing chords: cover every tree edge by a cycle
        let mut covered = vec![false; tree.len()];
        let path = |mut x: usize, mut y: usize| -> Vec<usize> {
            let mut p = Vec::new();
            while x != y {
                if depth[x] >= depth[y] {
                    let (px, e) = up[x].unwrap_or((x, usize::MAX));
                    p.push(e);
                    x = px;
                } else {
                    let (py, e) = up[y].unwrap_or((y, usize::MAX));
                    p.push(e);
                    y = py;
                }
                if p.len() > nr {
                    break;
                }
            }
            p
        };
        // strict pass, then a relaxed one: (smallest end angle, spacing to other ends as a
        // fraction of the chord length, smallest hole arc)
        for (angle, near_frac, arc_min) in [
            (bridge_angle, 0.5, MIN_HOLE_ARC),
            (0.5 * bridge_angle, 0.0, 0.4 * MIN_HOLE_ARC),
        ] {
            for (k, &(_, a, b)) in inter.iter().enumerate() {
                if covered.iter().all(|&c| c) {
                    break;
                }
                if used[k] || angle_of.get(&(a, b)).copied().unwrap_or(0.0) < angle {
                    continue;
                }
                let (ra, rb) = (m.ring[a], m.ring[b]);
                let p = path(ra, rb);
                if p.iter().all(|&e| e == usize::MAX || covered[e]) {
                    continue;
                }
                let w = m.pts[a].distance(m.pts[b]);
                let near = |x: usize| {
                    let d = m.spacing(x).max(near_frac * w);
                    ends.iter().any(|&e| m.pts[e].distance(m.pts[x]) <= d)
                };
                if near(a) || near(b) {
                    continue;
                }
                // a second chord of a bridged ring pair must split the hole's perimeter
                if p.len() == 1 {
                    let (ta, tb) = tree[p[0]];
                    let hole_r = if ra == 0 { rb } else { ra.max(rb) };
                    let h_new = if m.ring[a] == hole_r { a } else { b };
                    let h_old = if m.ring[ta] == hole_r { ta } else { tb };
                    let d = (m.arc[h_new] - m.arc[h_old]).abs();
                    let l = m.ring_len[hole_r];
                    if d.min(l - d) < arc_min * l {
                        continue;
                    }
                }
                for &e in &p {
                    if e != usize::MAX {
                        covered[e] = true;
                    }
                }
                used[k] = true;
                order.push((a, b));
                ends.extend([a, b]);
            }
        }
        // a bridge on no cycle would leave one block on both of its sides: drop it with the
        // rings hanging from it (Algorithm 2 removes those holes later)
        let detached: Vec<bool> = (0..nr)
            .map(|r| {
                let mut x = r;
                while let Some((px, e)) = up[x] {
                    if !covered[e] {
                        return true;
                    }
                    x = px;
                }
                false
            })
            .collect();
        order.retain(|&(a, b)| !detached[m.ring[a]] && !detached[m.ring[b]]);
        for &(a, b) in &order {
            cut_set.insert((a.min(b), a.max(b)));
        }
    }

    // 2. transverse cuts in the simply connected pieces
    let nt = m.tris.len();
    // the two sides (triangle, edge) of each chord, to close the dual edges across the cuts
    // (`blocked`, kept with `cut_set`: a pair of samples is one edge of the triangulation,
    // between two triangles)
    let mut sides: HashMap<(usize, usize), Vec<(usize, usize)>> = HashMap::new();
    for t in 0..nt {
        for k in 0..3 {
            if m.nbr[t][k].is_some() {
                let (a, b) = (m.tris[t][k], m.tris[t][(k + 1) % 3]);
                sides.entry((a.min(b), a.max(b))).or_default().push((t, k));
            }
        }
    }
    let mut blocked = vec![[false; 3]; nt];
    let block = |blocked: &mut Vec<[bool; 3]>, pair: &(usize, usize)| {
        for &(t, k) in sides.get(pair).map(Vec::as_slice).unwrap_or(&[]) {
            blocked[t][k] = true;
        }
    };
    for pair in &cut_set {
        block(&mut blocked, pair);
    }
    let open = |t: usize, k: usize, blocked: &Vec<[bool; 3]>| -> Option<usize> {
        let u = m.nbr[t][k]?;
        (!blocked[t][k]).then_some(u)
    };
    let mut comp = vec![usize::MAX; nt];
    let mut work: Vec<usize> = Vec::new(); // a seed triangle per piece
    for t in 0..nt {
        if comp[t] == usize::MAX {
            work.push(t);
            let mut st = vec![t];
            comp[t] = t;
            while let Some(x) = st.pop() {
                for k in 0..3 {
                    if let Some(u) = open(x, k, &blocked) {
                        if comp[u] == usize::MAX {
                            comp[u] = t;
                            st.push(u);
                        }
                    }
                }
            }
        }
    }
    let budget = 4 * nt + 16;
    let mut scratch = TreeScratch::new(&m);
    let mut steps = 0;
    while let Some(seed) = work.pop() {
        steps += 1;
        if steps > budget {
            break;
        }
        let open_here = |t: usize, k: usize| open(t, k, &blocked);
        let Some(tree) = PieceTree::new(&m, seed, &open_here, &mut scratch) else {
            continue; // not simply connected (should not happen): leave it to Algorithm 1
        };
        let total = tree.total;
        let mut best: Option<(f64, usize, usize, usize)> = None;
        for (a, b, a1, x) in tree.chords(&m) {
            let small = a1.min(total - a1);
            if small < min_area {
                continue;
            }
            let w = m.pts[a].distance(m.pts[b]);
            let raw = small / (w * w);
            if raw < aspect {
                continue;
            }
            let (amin, g) = m.chord_angles(a, b);
            if amin < min_angle {
                continue;
            }
            let score = raw * (1.0 - 0.5 * g.min(1.0));
            if score < aspect {
                continue;
            }
            let (da, db) = (m.spacing(a).max(0.5 * w), m.spacing(b).max(0.5 * w));
            if ends
                .iter()
                .any(|&e| m.pts[e].distance(m.pts[a]) <= da || m.pts[e].distance(m.pts[b]) <= db)
            {
                continue;
            }
            let better = match best {
                None => true,
                Some((s, ba, bb, _)) => score > s || (score == s && (a, b) < (ba, bb)),
            };
            if better {
                best = Some((score, a, b, x));
            }
        }
        if let Some((_, a, b, x)) = best {
            cut_set.insert((a.min(b), a.max(b)));
            block(&mut blocked, &(a.min(b), a.max(b)));
            order.push((a, b));
            ends.extend([a, b]);
            work.push(seed);
            work.push(x);
        }
    }
    Ok(order
        .into_iter()
        .map(|(a, b)| (m.pts[a], m.pts[b]))
        .collect())
}
