//! Mesh-level quality: α statistics and ε-convexity, the μ bands / histogram / high-quality
//! verdict, interior-node valence (interior singularities), and per-cell metric arrays for
//! output files.
//!
//! Per-cell evaluation runs on rayon for meshes of at least [`PARALLEL_THRESHOLD`] cells. The
//! cell corners are first gathered sequentially (so the mesh need not be `Sync`), each cell is
//! then evaluated independently and the results are collected **in cell order**; every sum and
//! minimum is taken sequentially afterwards, so results are bit-for-bit deterministic whatever
//! the thread count.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::hex::HexMetrics;
use super::quad::QuadMetrics;
use crate::traits::{HasHexCells, HasQuadCells};

/// Meshes with at least this many cells are evaluated in parallel (rayon).
pub const PARALLEL_THRESHOLD: usize = 2048;

/// μ threshold of a "good" cell ([Méndez 2023, §2.2]: blue band, τ = 0.8).
pub const MU_GOOD: f64 = 0.8;
/// Lower μ limit of the "fair" band ([Méndez 2023, §2.2]: orange band 0.4 ≤ μ < 0.8).
pub const MU_FAIR: f64 = 0.4;
/// Fraction of cells with μ ≥ [`MU_GOOD`] that makes a mesh "high quality"
/// ([Méndez 2023, §2.2]: p = 85 %).
pub const HIGH_QUALITY_FRACTION: f64 = 0.85;

fn par_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync + Send) -> Vec<R> {
    if items.len() >= PARALLEL_THRESHOLD {
        items.par_iter().map(f).collect()
    } else {
        items.iter().map(f).collect()
    }
}

/// [`QuadMetrics`] of every cell, in cell order (rayon for large meshes, deterministic).
pub fn quad_metrics_per_cell<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<QuadMetrics> {
    let cells: Vec<[DVec2; 4]> = (0..mesh.num_quads()).map(|c| mesh.quad_points(c)).collect();
    par_map(&cells, QuadMetrics::compute)
}

/// [`HexMetrics`] of every cell, in cell order (rayon for large meshes, deterministic).
pub fn hex_metrics_per_cell<M: HasHexCells + ?Sized>(mesh: &M) -> Vec<HexMetrics> {
    let cells: Vec<[DVec3; 8]> = (0..mesh.num_hexes()).map(|c| mesh.hex_points(c)).collect();
    par_map(&cells, HexMetrics::compute)
}

/// Statistics of the corner-triangle measure α over a quad mesh ([González Flores, §4.1,
/// Table A.1]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlphaStats {
    /// Number of triangles `N = 4 × cells`.
    pub num_triangles: usize,
    /// `Σ α` over all triangles; equals `4·area(Ω)` for any grid with the given boundary,
    /// folded or not (the thesis's (3.53), (3.61), stated for positively oriented triangles, holds
    /// with signed α for any grid).
    pub sum: f64,
    /// `ᾱ = 4·area(Ω)/N`, computed as `Σα / N` (equal by the identity above); 0 for an empty
    /// mesh.
    pub mean: f64,
    /// `α₋ = min α` ("Alfamin"); 0 for an empty mesh.
    pub min: f64,
    /// Number of cells with some `α ≤ 0` ("Inocon").
    pub non_convex_cells: usize,
}

impl AlphaStats {
    /// `α₋ / ᾱ`, the scale-free convexity degree (0 when `|ᾱ| < f64::MIN_POSITIVE`).
    pub fn min_over_mean(&self) -> f64 {
        if self.mean.abs() < f64::MIN_POSITIVE {
            0.0
        } else {
            self.min / self.mean
        }
    }

    /// ε-convexity: `α₋ > ε·ᾱ`. The quality target of [González Flores, (4.36)] is
    /// `ε = 0.01`; `ε = 0` is plain convexity.
    pub fn is_eps_convex(&self, eps: f64) -> bool {
        self.num_triangles > 0 && self.min > eps * self.mean
    }

    pub(crate) fn from_metrics(m: &[QuadMetrics]) -> Self {
        Self::from_alphas(m.iter().map(|c| c.alphas))
    }

    /// The statistics of per-cell corner α given in cell order (summed in that order, so the
    /// result does not depend on how the α were computed).
    fn from_alphas(cells: impl ExactSizeIterator<Item = [f64; 4]>) -> Self {
        let n = 4 * cells.len();
        let mut sum = 0.0;
        let mut min = f64::INFINITY;
        let mut non_convex = 0;
        for alphas in cells {
            for a in alphas {
                sum += a;
                min = min.min(a);
            }
            if !super::quad::alphas_convex(&alphas) {
                non_convex += 1;
            }
        }
        Self {
            num_triangles: n,
            sum,
            mean: if n == 0 { 0.0 } else { sum / n as f64 },
            min: if n == 0 { 0.0 } else { min },
            non_convex_cells: non_convex,
        }
    }
}

/// α statistics of a quad mesh: ᾱ, α₋, `Σα`, the number of non-convex cells. Only the corner
/// α are computed (rayon for large meshes), then reduced in cell order: the same values, bit
/// for bit, as from [`quad_metrics_per_cell`].
pub fn alpha_stats<M: HasQuadCells + ?Sized>(mesh: &M) -> AlphaStats {
    let cells: Vec<[DVec2; 4]> = (0..mesh.num_quads()).map(|c| mesh.quad_points(c)).collect();
    AlphaStats::from_alphas(par_map(&cells, super::quad::corner_alphas).into_iter())
}

/// `true` iff the mesh is ε-convex: `α₋ > ε·ᾱ` (see [`AlphaStats::is_eps_convex`]).
pub fn is_eps_convex<M: HasQuadCells + ?Sized>(mesh: &M, eps: f64) -> bool {
    alpha_stats(mesh).is_eps_convex(eps)
}

/// Ids of the cells with some corner `α ≤ 0` (non-convex, degenerate or folded).
pub fn non_convex_cells<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<usize> {
    quad_metrics_per_cell(mesh)
        .iter()
        .enumerate()
        .filter(|(_, m)| !m.convex)
        .map(|(c, _)| c)
        .collect()
}

/// The μ quality bands of [Méndez 2023, §2.2], as **percentages** of the cells:
/// good (blue) `μ ≥ 0.8`, fair (orange) `0.4 ≤ μ < 0.8`, poor (red) `μ < 0.4` (including
/// non-convex cells, μ ≤ 0, and NaN). All 0 for an empty mesh.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MuBands {
    /// % of cells with μ ≥ 0.8.
    pub good: f64,
    /// % of cells with 0.4 ≤ μ < 0.8.
    pub fair: f64,
    /// % of cells with μ < 0.4.
    pub poor: f64,
}

impl MuBands {
    /// Bands of the given μ values.
    pub fn new(mu: &[f64]) -> Self {
        if mu.is_empty() {
            return Self {
                good: 0.0,
                fair: 0.0,
                poor: 0.0,
            };
        }
        let good = mu.iter().filter(|&&x| x >= MU_GOOD).count();
        let fair = mu
            .iter()
            .filter(|&&x| (MU_FAIR..MU_GOOD).contains(&x))
            .count();
        let poor = mu.len() - good - fair;
        let pct = |k: usize| 100.0 * k as f64 / mu.len() as f64;
        Self {
            good: pct(good),
            fair: pct(fair),
            poor: pct(poor),
        }
    }
}

/// Histogram of μ over `[0, 1]` (the "quality histogram" of [Méndez 2023, §2.2]) with a
/// configurable number `B` of equal bins: a cell with `μ > 0` goes to bin
/// `k = min(⌊μ·B⌋, B − 1)`, so bin `k` is `[k/B, (k+1)/B)` and the last bin is closed at 1. Cells with **μ ≤ 0** (non-convex, degenerate or folded) and NaN are **not**
/// in any bin: they are counted in [`non_positive`](Self::non_positive), so that
/// `Σ counts + non_positive = cells`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct MuHistogram {
    /// Count per bin; `counts.len()` is the number of bins.
    pub counts: Vec<usize>,
    /// Cells with μ ≤ 0 (or NaN).
    pub non_positive: usize,
}

impl MuHistogram {
    /// Histogram of the given μ values with `bins` bins (`bins = 0` is treated as 1).
    pub fn new(mu: &[f64], bins: usize) -> Self {
        let b = bins.max(1);
        let mut counts = vec![0; b];
        let mut non_positive = 0;
        for &x in mu {
            if x > 0.0 {
                let k = ((x * b as f64) as usize).min(b - 1);
                counts[k] += 1;
            } else {
                non_positive += 1;
            }
        }
        Self {
            counts,
            non_positive,
        }
    }

    /// The `B + 1` bin edges `0, 1/B, …, 1`.
    pub fn bin_edges(&self) -> Vec<f64> {
        let b = self.counts.len();
        (0..=b).map(|k| k as f64 / b as f64).collect()
    }
}

/// The high-quality verdict of [Méndez 2023, §2.2]: at least 85 % of the cells have
/// μ ≥ 0.8. An empty mesh is not high quality.
pub fn is_high_quality(mu: &[f64]) -> bool {
    !mu.is_empty()
        && mu.iter().filter(|&&x| x >= MU_GOOD).count() as f64
            >= HIGH_QUALITY_FRACTION * mu.len() as f64
}

/// The undirected edges of a quad mesh, `(min, max)` node ids, each with the number of cells
/// using it; sorted (deterministic, no hashing).
fn quad_edges<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<((usize, usize), u32)> {
    quad_edge_counts(
        (0..mesh.num_quads()).map(|c| mesh.quad(c)),
        mesh.num_quads(),
    )
}

/// [`quad_edges`] over any list of quads (`len` is a capacity hint): the one edge census of the
/// crate, also used by [`QuadMesh`](crate::QuadMesh) for its boundary flags.
pub(crate) fn quad_edge_counts(
    quads: impl Iterator<Item = [usize; 4]>,
    len: usize,
) -> Vec<((usize, usize), u32)> {
    let mut e: Vec<(usize, usize)> = Vec::with_capacity(4 * len);
    for q in quads {
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            if a != b {
                e.push((a.min(b), a.max(b)));
            }
        }
    }
    {
        use rayon::slice::ParallelSliceMut;
        e.par_sort_unstable();
    }
    let mut out: Vec<((usize, usize), u32)> = Vec::with_capacity(e.len() / 2 + 1);
    for x in e {
        match out.last_mut() {
            Some((y, n)) if *y == x => *n += 1,
            _ => out.push((x, 1)),
        }
    }
    out
}

/// Boundary flags from connectivity: a node is on the boundary iff it is an end of an edge
/// used by exactly one cell. Nodes of no cell are `false`.
pub fn quad_boundary_nodes<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<bool> {
    let mut b = vec![false; mesh.num_nodes()];
    for ((x, y), n) in quad_edges(mesh) {
        if n == 1 {
            b[x] = true;
            b[y] = true;
        }
    }
    b
}

/// The boundary edges of a quad mesh: `[a, b]` with `a < b` for every edge used by exactly
/// one cell, sorted (from the same edge census as [`quad_boundary_nodes`]).
pub fn quad_boundary_edges<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<[usize; 2]> {
    quad_edges(mesh)
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|((a, b), _)| [a, b])
        .collect()
}

/// Valence of every node: the number of distinct mesh edges incident to it (for an interior
/// node of a conformal quad mesh, also the number of cells around it). Nodes of no cell: 0.
pub fn quad_node_valences<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<usize> {
    let mut v = vec![0; mesh.num_nodes()];
    for ((x, y), _) in quad_edges(mesh) {
        v[x] += 1;
        v[y] += 1;
    }
    v
}

/// Interior-node valence census of a quad mesh.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InteriorValence {
    /// Number of interior nodes.
    pub interior_nodes: usize,
    /// The interior nodes whose valence is not 4, as `(node, valence)`, by increasing id.
    pub singular: Vec<(usize, usize)>,
}

impl InteriorValence {
    /// Number of interior singularities (interior nodes with valence ≠ 4).
    pub fn count(&self) -> usize {
        self.singular.len()
    }
}

/// Interior singularities of a quad mesh (the goal of [Méndez 2023, §1.1]: meshes "without
/// interior singularities"). **Interior** is computed from the connectivity, not from the
/// fixed flags: a node is interior iff it belongs to some cell and to no boundary edge (an edge
/// used by exactly one cell). A structured grid, or block grids merged conformally, has valence
/// 4 at every interior node, so its count is 0 ([Méndez 2023, §2.1.1]: valence 4 inside).
pub fn interior_singularities<M: HasQuadCells + ?Sized>(mesh: &M) -> InteriorValence {
    let edges = quad_edges(mesh);
    let n = mesh.num_nodes();
    let mut boundary = vec![false; n];
    let mut valence = vec![0usize; n];
    for &((x, y), k) in &edges {
        valence[x] += 1;
        valence[y] += 1;
        if k == 1 {
            boundary[x] = true;
            boundary[y] = true;
        }
    }
    let mut interior_nodes = 0;
    let mut singular = Vec::new();
    for v in 0..n {
        if valence[v] > 0 && !boundary[v] {
            interior_nodes += 1;
            if valence[v] != 4 {
                singular.push((v, valence[v]));
            }
        }
    }
    InteriorValence {
        interior_nodes,
        singular,
    }
}

/// Per-cell quad metric arrays for output files (e.g. VTK `CELL_DATA`), each `(name, values)`
/// with one value per cell in cell order. Names: `"mu"`, `"min_alpha"`, `"convex"` (1 or 0),
/// `"jacobian"`, `"scaled_jacobian"`, `"condition"`, `"shape"`, `"skew"`, `"taper"`,
/// `"aspect_ratio"`, `"edge_ratio"`, `"min_angle"`, `"max_angle"`, `"oddy"`.
/// Infinite metrics hold `f64::MAX` (Verdict's `DBL_MAX`).
pub fn quad_cell_metrics<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<(&'static str, Vec<f64>)> {
    quad_arrays(&quad_metrics_per_cell(mesh))
}

pub(crate) fn quad_arrays(m: &[QuadMetrics]) -> Vec<(&'static str, Vec<f64>)> {
    let col = |f: fn(&QuadMetrics) -> f64| m.iter().map(f).collect::<Vec<f64>>();
    vec![
        ("mu", col(|x| x.mu)),
        ("min_alpha", col(|x| x.min_alpha())),
        ("convex", col(|x| if x.convex { 1.0 } else { 0.0 })),
        ("jacobian", col(|x| x.jacobian)),
        ("scaled_jacobian", col(|x| x.scaled_jacobian)),
        ("condition", col(|x| x.condition)),
        ("shape", col(|x| x.shape)),
        ("skew", col(|x| x.skew)),
        ("taper", col(|x| x.taper)),
        ("aspect_ratio", col(|x| x.aspect_ratio)),
        ("edge_ratio", col(|x| x.edge_ratio)),
        ("min_angle", col(|x| x.min_angle)),
        ("max_angle", col(|x| x.max_angle)),
        ("oddy", col(|x| x.oddy)),
    ]
}

/// Per-cell hex metric arrays for output files: `"jacobian"`, `"scaled_jacobian"`,
/// `"condition"`, `"shape"`, `"skew"`, `"taper"`, `"oddy"`, `"min_tet_det"` (smallest of the
/// ten `V = 6 × tet volume`), `"convex_10tet"` (1 or 0), `"max_face_cos"`.
pub fn hex_cell_metrics<M: HasHexCells + ?Sized>(mesh: &M) -> Vec<(&'static str, Vec<f64>)> {
    hex_arrays(&hex_metrics_per_cell(mesh))
}

pub(crate) fn hex_arrays(m: &[HexMetrics]) -> Vec<(&'static str, Vec<f64>)> {
    let col = |f: fn(&HexMetrics) -> f64| m.iter().map(f).collect::<Vec<f64>>();
    vec![
        ("jacobian", col(|x| x.jacobian)),
        ("scaled_jacobian", col(|x| x.scaled_jacobian)),
        ("condition", col(|x| x.condition)),
        ("shape", col(|x| x.shape)),
        ("skew", col(|x| x.skew)),
        ("taper", col(|x| x.taper)),
        ("oddy", col(|x| x.oddy)),
        ("min_tet_det", col(|x| x.min_tet_det())),
        (
            "convex_10tet",
            col(|x| if x.convex_10tet() { 1.0 } else { 0.0 }),
        ),
        ("max_face_cos", col(|x| x.max_face_cos())),
    ]
}

/// Number of hexes failing the 10-tetrahedra test with threshold `ε·v̄`, where `v̄` is the mean
/// of all `10 × cells` tetrahedron values `V = 6 × volume` ([Cortés Aguirre 2012, (3.35)]: a
/// cell is non-convex if any `V ≤ ε·v̄`); `ε = 0` is the thesis's plain test (any `V ≤ 0`).
pub fn hex_non_convex_count<M: HasHexCells + ?Sized>(mesh: &M, eps: f64) -> usize {
    hex_non_convex_from(&hex_metrics_per_cell(mesh), eps)
}

pub(crate) fn hex_tet_mean(m: &[HexMetrics]) -> f64 {
    if m.is_empty() {
        return 0.0;
    }
    let s: f64 = m.iter().map(|x| x.tet_dets.iter().sum::<f64>()).sum();
    s / (10 * m.len()) as f64
}

pub(crate) fn hex_non_convex_from(m: &[HexMetrics], eps: f64) -> usize {
    let thr = if eps == 0.0 {
        0.0
    } else {
        eps * hex_tet_mean(m)
    };
    m.iter()
        .filter(|x| !x.tet_dets.iter().all(|&v| v > thr))
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{StructuredGrid2, StructuredGrid3};
    use crate::traits::HasNodes;
    use crate::unstructured::{HexMesh, QuadMesh};
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn shoelace(p: &[DVec2]) -> f64 {
        let n = p.len();
        0.5 * (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>()
    }

    /// The fixed boundary of the test grids: a wavy, non-convex outline.
    fn boundary_point(i: usize, j: usize) -> DVec2 {
        let (x, y) = (i as f64, j as f64);
        DVec2::new(x + 0.3 * (1.7 * y).sin(), y + 0.25 * (1.3 * x).cos())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Σα over all triangles = 4·area(Ω) whatever the interior nodes (folded or not),
        /// area from the shoelace formula of the boundary loop ([González Flores, (3.53)]).
        #[test]
        fn sum_alpha_is_four_times_area(
            m in 3usize..8, n in 3usize..8,
            seed in proptest::collection::vec((-3.0f64..12.0, -3.0f64..12.0), 64),
        ) {
            let mut k = 0;
            let g = StructuredGrid2::from_fn(m, n, |i, j| {
                if i == 0 || j == 0 || i + 1 == m || j + 1 == n {
                    boundary_point(i, j)
                } else {
                    k += 1;
                    let (x, y) = seed[k % seed.len()];
                    DVec2::new(x, y)
                }
            }).unwrap();
            let ring: Vec<DVec2> = g.boundary_loop().iter().map(|&v| g.nodes()[v]).collect();
            let area = shoelace(&ring);
            let s = alpha_stats(&g);
            prop_assert_eq!(s.num_triangles, 4 * (m - 1) * (n - 1));
            let scale = 1.0 + s.sum.abs() + 4.0 * area.abs();
            prop_assert!((s.sum - 4.0 * area).abs() <= 1e-10 * scale,
                "Σα = {}, 4·area = {}", s.sum, 4.0 * area);
            // ᾱ = 4·area/N
            prop_assert!((s.mean - 4.0 * area / s.num_triangles as f64).abs() <= 1e-10 * scale);
            // the α-only path gives the statistics of the full metrics, bit for bit, and
            // counts a cell non-convex exactly when its metrics say so
            let full = AlphaStats::from_metrics(&quad_metrics_per_cell(&g));
            prop_assert_eq!(s, full);
            let bad = quad_metrics_per_cell(&g).iter().filter(|q| !q.convex).count();
            prop_assert_eq!(s.non_convex_cells, bad);
        }
    }

    #[test]
    fn structured_grid_has_no_interior_singularity() {
        let g = StructuredGrid2::from_fn(6, 5, |i, j| {
            DVec2::new(
                i as f64 + 0.1 * j as f64,
                j as f64 * (1.0 + 0.05 * i as f64),
            )
        })
        .unwrap();
        let v = interior_singularities(&g);
        assert_eq!(v.interior_nodes, 4 * 3);
        assert_eq!(v.count(), 0);
        let val = quad_node_valences(&g);
        // corners 2, other boundary nodes 3, interior 4 ([Méndez 2023, §2.1.1])
        assert_eq!(val[g.index(0, 0)], 2);
        assert_eq!(val[g.index(2, 0)], 3);
        assert_eq!(val[g.index(2, 2)], 4);
        let b = quad_boundary_nodes(&g);
        for (v, &on_boundary) in b.iter().enumerate() {
            assert_eq!(on_boundary, crate::traits::FreeNodes::is_fixed(&g, v));
        }
        assert_eq!(b.len(), g.num_nodes());
        // boundary edges: the perimeter of an (m−1) × (n−1)-cell grid has 2(m−1) + 2(n−1)
        // edges, each joining two boundary nodes that are adjacent in i or j
        let e = quad_boundary_edges(&g);
        assert_eq!(e.len(), 2 * (g.m() - 1) + 2 * (g.n() - 1));
        for [a, c] in &e {
            assert!(a < c && b[*a] && b[*c]);
            assert!(c - a == 1 || c - a == g.m());
        }
        // same through an unstructured copy
        let q = QuadMesh::from_grid(&g);
        assert_eq!(interior_singularities(&q), v);
    }

    #[test]
    fn merged_block_meshes_have_no_interior_singularity() {
        let grid = |x0: f64, y0: f64| {
            StructuredGrid2::from_fn(3, 3, |i, j| DVec2::new(x0 + i as f64, y0 + j as f64)).unwrap()
        };
        // 2 × 2 blocks of 2 × 2 cells: the union is the 5 × 5-node grid of [0,4]², whose 9
        // interior nodes all have valence 4 — including (2,2), where four block corners meet.
        let bm = crate::block::BlockMesh2::merge(
            vec![grid(0., 0.), grid(2., 0.), grid(0., 2.), grid(2., 2.)],
            1e-9,
        )
        .unwrap();
        let v = interior_singularities(&bm);
        assert_eq!((v.interior_nodes, v.count()), (9, 0));
        // L-shape of three blocks: the re-entrant corner (2,2) is a boundary node; interior
        // nodes (1,1), (3,1), (1,3) inside the blocks and (2,1), (1,2) on the shared sides.
        let l =
            crate::block::BlockMesh2::merge(vec![grid(0., 0.), grid(2., 0.), grid(0., 2.)], 1e-9)
                .unwrap();
        let v = interior_singularities(&l);
        assert_eq!((v.interior_nodes, v.count()), (5, 0));
    }

    /// A triangle split into 3 quads (centre C, valence 3) glued along one side to a pentagon
    /// split into 5 quads (centre D, valence 5). Node ids:
    /// triangle T0 = 0 (0,0), T1 = 1 (2,0), T2 = 2 (1,√3), M01 = 3 (1,0), M12 = 4, M20 = 5,
    /// C = 6; pentagon V0 = T1, V1 = T0, W01 = M01, V2 = 7, V3 = 8, V4 = 9, W12 = 10, W23 = 11,
    /// W34 = 12, W40 = 13, D = 14.
    /// By hand: boundary edges are the 4 remaining triangle half-sides and the 8 remaining
    /// pentagon half-sides; the shared edges T0–M01, M01–T1 are used twice. Interior nodes:
    /// C (edges to M01, M12, M20: valence 3), D (edges to the 5 W's: valence 5) and M01
    /// (edges to T0, T1, C, D: valence 4). So 3 interior nodes, 2 singularities.
    fn tri_penta_mesh() -> QuadMesh {
        let s3 = 3f64.sqrt();
        let t0 = DVec2::new(0.0, 0.0);
        let t1 = DVec2::new(2.0, 0.0);
        let t2 = DVec2::new(1.0, s3);
        let mid = |a: DVec2, b: DVec2| (a + b) * 0.5;
        let v2 = DVec2::new(-0.3, -1.5);
        let v3 = DVec2::new(1.0, -2.5);
        let v4 = DVec2::new(2.3, -1.5);
        let d = (t1 + t0 + v2 + v3 + v4) / 5.0;
        let nodes = vec![
            t0,
            t1,
            t2,
            mid(t0, t1),
            mid(t1, t2),
            mid(t2, t0),
            (t0 + t1 + t2) / 3.0,
            v2,
            v3,
            v4,
            mid(t0, v2),
            mid(v2, v3),
            mid(v3, v4),
            mid(v4, t1),
            d,
        ];
        let cells = vec![
            // triangle: (corner, next midpoint, centre, previous midpoint)
            [0, 3, 6, 5],
            [1, 4, 6, 3],
            [2, 5, 6, 4],
            // pentagon V0..V4 = 1, 0, 7, 8, 9 with midpoints W01 = 3, W12 = 10, W23 = 11,
            // W34 = 12, W40 = 13
            [1, 3, 14, 13],
            [0, 10, 14, 3],
            [7, 11, 14, 10],
            [8, 12, 14, 11],
            [9, 13, 14, 12],
        ];
        QuadMesh::new(nodes, cells).unwrap()
    }

    #[test]
    fn hand_built_mesh_has_two_singularities() {
        let q = tri_penta_mesh();
        // the geometry is valid: every cell is convex
        assert_eq!(non_convex_cells(&q), Vec::<usize>::new());
        let v = interior_singularities(&q);
        assert_eq!(v.interior_nodes, 3);
        assert_eq!(v.singular, vec![(6, 3), (14, 5)]);
        assert_eq!(v.count(), 2);
        assert_eq!(quad_node_valences(&q)[3], 4);
        // connectivity-based boundary = the mesh's own boundary flags
        assert_eq!(quad_boundary_nodes(&q), q.boundary_flags());
    }

    /// Four disjoint cells with known μ: square (1), parallelogram 60° (sin 60° ≈ 0.866),
    /// parallelogram 40° (sin 40° ≈ 0.643) and a dart (μ < 0).
    fn four_cells() -> QuadMesh {
        let mut nodes = Vec::new();
        let mut cells = Vec::new();
        let mut add = |q: [DVec2; 4]| {
            let b = nodes.len();
            nodes.extend_from_slice(&q);
            cells.push([b, b + 1, b + 2, b + 3]);
        };
        let para = |deg: f64, x0: f64| {
            let e = DVec2::new(deg.to_radians().cos(), deg.to_radians().sin());
            let o = DVec2::new(x0, 0.0);
            [o, o + DVec2::X, o + DVec2::X + e, o + e]
        };
        add(para(90.0, 0.0));
        add(para(60.0, 3.0));
        add(para(40.0, 6.0));
        add([
            DVec2::new(10.0, 0.0),
            DVec2::new(12.0, 0.0),
            DVec2::new(12.0, 2.0),
            DVec2::new(11.5, 0.5),
        ]);
        QuadMesh::new(nodes, cells).unwrap()
    }

    #[test]
    fn mu_bands_histogram_and_verdict() {
        let q = four_cells();
        let mu: Vec<f64> = quad_metrics_per_cell(&q).iter().map(|m| m.mu).collect();
        let b = MuBands::new(&mu);
        assert_relative_eq!(b.good, 50.0);
        assert_relative_eq!(b.fair, 25.0);
        assert_relative_eq!(b.poor, 25.0);
        let h = MuHistogram::new(&mu, 10);
        // 1.0 → last bin (9), 0.866 → bin 8, 0.643 → bin 6, dart → non-positive
        assert_eq!(h.counts, vec![0, 0, 0, 0, 0, 0, 1, 0, 1, 1]);
        assert_eq!(h.non_positive, 1);
        assert_eq!(h.bin_edges().len(), 11);
        assert!(!is_high_quality(&mu));
        let s = alpha_stats(&q);
        assert_eq!(s.non_convex_cells, 1);
        assert_relative_eq!(s.min, -2.0); // the dart's reflex corner (quad.rs test)
        assert!(!s.is_eps_convex(0.0));
        // 7 good cells of 8 = 87.5 % ≥ 85 %: high quality; 6 of 8 = 75 %: not
        assert!(is_high_quality(&[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.8, -1.0]));
        assert!(!is_high_quality(&[
            1.0, 1.0, 1.0, 1.0, 1.0, 0.9, 0.79, -1.0
        ]));
        assert!(!is_high_quality(&[]));
    }

    #[test]
    fn eps_convexity_of_a_uniform_grid() {
        let g =
            StructuredGrid2::from_fn(5, 4, |i, j| DVec2::new(i as f64 * 2.0, j as f64)).unwrap();
        let s = alpha_stats(&g);
        // every α = 2·1 = 2 = ᾱ
        assert_relative_eq!(s.mean, 2.0);
        assert_relative_eq!(s.min, 2.0);
        assert_relative_eq!(s.min_over_mean(), 1.0);
        assert!(s.is_eps_convex(0.99));
        assert!(!s.is_eps_convex(1.0));
        assert!(is_eps_convex(&g, 0.01));
    }

    #[test]
    fn parallel_and_sequential_agree() {
        // 60 × 60 cells > PARALLEL_THRESHOLD
        let g = StructuredGrid2::from_fn(61, 61, |i, j| {
            let (x, y) = (i as f64 / 60.0, j as f64 / 60.0);
            DVec2::new(
                x + 0.1 * (6.0 * y).sin() * x * (1.0 - x),
                y + 0.05 * (5.0 * x).cos(),
            )
        })
        .unwrap();
        assert!(g.num_quads() >= PARALLEL_THRESHOLD);
        let par = quad_metrics_per_cell(&g);
        let seq: Vec<QuadMetrics> = (0..g.num_quads())
            .map(|c| QuadMetrics::compute(&g.quad_points(c)))
            .collect();
        assert_eq!(par, seq);
        let arrays = quad_cell_metrics(&g);
        assert_eq!(arrays.len(), 14);
        assert!(arrays.iter().all(|(_, v)| v.len() == g.num_quads()));
        assert_eq!(arrays[0].0, "mu");
        assert_eq!(arrays[0].1[7], seq[7].mu);
    }

    #[test]
    fn hex_mesh_level() {
        let g =
            StructuredGrid3::from_fn(3, 3, 3, |i, j, k| DVec3::new(i as f64, j as f64, k as f64))
                .unwrap();
        assert_eq!(hex_non_convex_count(&g, 0.0), 0);
        // all tets of a unit-cube grid: 8 × 1 + 2 × 2 per cell, mean 1.2; ε = 0.9 →
        // threshold 1.08 > 1 fails every cell
        assert_eq!(hex_non_convex_count(&g, 0.9), 8);
        let mut h = HexMesh::from_grid(&g);
        // dent the far corner of the last cell (node (2,2,2)) inward to (1.2,1.2,1.2)
        let last = h.num_nodes() - 1;
        h.nodes_mut()[last] = DVec3::splat(1.2);
        assert_eq!(hex_non_convex_count(&h, 0.0), 1);
        let arrays = hex_cell_metrics(&h);
        let convex = &arrays.iter().find(|(n, _)| *n == "convex_10tet").unwrap().1;
        assert_eq!(convex.iter().filter(|&&c| c == 0.0).count(), 1);
        assert_eq!(convex[7], 0.0);
    }
}
