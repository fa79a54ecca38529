//! The dual tree of one simply connected piece of the chord mesh: the areas on both sides of
//! each of its chords (subtree sums).

use super::mesh::ChordMesh;

/// The dual spanning tree of one simply connected piece of a [`ChordMesh`]: triangles in DFS
/// preorder, each one's parent and the dual edge to it, and subtree areas.
///
/// `parent` and `sub` are aligned with `order` (entry `i` belongs to triangle `order[i]`):
/// the same values, summed in the same order, as maps keyed by triangle would hold, without
/// the maps' per-entry work; the per-triangle marks of the traversal live in a
/// [`TreeScratch`] that is cleared after each tree.
pub(super) struct PieceTree {
    order: Vec<usize>,
    parent: Vec<Option<(usize, usize)>>,
    sub: Vec<f64>,
    pub(super) total: f64,
}

/// Per-triangle marks for building [`PieceTree`]s of one mesh: whether a triangle was seen,
/// its parent and its place in the order. All unset between trees.
pub(super) struct TreeScratch {
    seen: Vec<bool>,
    parent: Vec<Option<(usize, usize)>>,
    pos: Vec<usize>,
}

impl TreeScratch {
    /// Unset marks for the triangles of `m`.
    pub(super) fn new(m: &ChordMesh) -> Self {
        let nt = m.tris.len();
        Self {
            seen: vec![false; nt],
            parent: vec![None; nt],
            pos: vec![usize::MAX; nt],
        }
    }
}

impl PieceTree {
    /// The tree of the piece containing `seed`, crossing only the edges `open(t, k)` returns a
    /// neighbour for; `None` if the piece's dual graph has a cycle (a hole inside the piece).
    pub(super) fn new(
        m: &ChordMesh,
        seed: usize,
        open: &dyn Fn(usize, usize) -> Option<usize>,
        scratch: &mut TreeScratch,
    ) -> Option<Self> {
        let TreeScratch { seen, parent, pos } = scratch;
        seen[seed] = true;
        let mut dfs = vec![seed];
        let mut order = Vec::new();
        let mut dual_edges = 0usize;
        while let Some(x) = dfs.pop() {
            pos[x] = order.len();
            order.push(x);
            for k in 0..3 {
                if let Some(u) = open(x, k) {
                    dual_edges += 1;
                    if !seen[u] {
                        seen[u] = true;
                        parent[u] = Some((x, k));
                        dfs.push(u);
                    }
                }
            }
        }
        let tree_parent: Vec<Option<(usize, usize)>> = order.iter().map(|&x| parent[x]).collect();
        let tree_pos: Vec<usize> = tree_parent
            .iter()
            .map(|p| p.map_or(usize::MAX, |(p, _)| pos[p]))
            .collect();
        // clear the marks (a triangle seen is in the order: every one pushed is popped)
        for &x in &order {
            seen[x] = false;
            parent[x] = None;
            pos[x] = usize::MAX;
        }
        if dual_edges / 2 + 1 != order.len() {
            return None;
        }
        // children before parents: a triangle's entry holds the sum of its children's
        // subtrees (0.0 + s₁ + s₂ …, in this order) when it is reached
        let mut sub = vec![0.0; order.len()];
        for i in (0..order.len()).rev() {
            let s = m.tri_area(order[i]) + sub[i];
            sub[i] = s;
            if tree_pos[i] != usize::MAX {
                sub[tree_pos[i]] += s;
            }
        }
        let total = sub.first().copied().unwrap_or(0.0);
        Some(Self {
            order,
            parent: tree_parent,
            sub,
            total,
        })
    }

    /// Every chord of the piece with the areas on its two sides: `(a, b, A_child, x)` where
    /// `x` is the triangle on the child side.
    pub(super) fn chords<'a>(
        &'a self,
        m: &'a ChordMesh,
    ) -> impl Iterator<Item = (usize, usize, f64, usize)> + 'a {
        self.order.iter().enumerate().filter_map(move |(i, &x)| {
            let (p, k) = self.parent[i]?;
            let (a, b) = (m.tris[p][k], m.tris[p][(k + 1) % 3]);
            Some((a, b, self.sub[i], x))
        })
    }
}
