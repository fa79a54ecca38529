//! Independent check of a finished mesh before success is reported (the guarantee holds or the
//! run fails; see `docs/reliability.md`).
//!
//! The product's promise is an all-convex mesh of the region. The stages compute quality
//! reports of their own, but a defect in a stage (a fold left by TFI of a wiggly block, a cell
//! bridging a narrow bay, a MultiPolygon part dropped) must not reach the user as a success.
//! [`verify_quads`] therefore re-derives the guarantee from nothing but the node coordinates,
//! the cell connectivity and the region's rings:
//!
//! 1. **Convexity.** A quad `P₀P₁P₂P₃` is strictly convex iff all four corner triangles
//!    `(P_{k−1}, P_k, P_{k+1})` are positively oriented,
//!    `α_k = det(P_{k+1} − P_k, P_{k−1} − P_k)·(−1) > 0` (Ivanenko 1999, eq. (1.4): the
//!    discrete Jacobian of each corner is positive; the same test as [González Flores, §4.1]). The
//!    sign is decided exactly with Shewchuk's adaptive `orient2d` (Shewchuk 1997), so a
//!    degenerate cell is never counted as convex by rounding.
//! 2. **Cells inside the region.** Every cell centroid `c = ¼ΣP_k` must lie in the closed
//!    region: winding number `w(c) ≠ 0` over all rings (outer counter-clockwise, holes
//!    clockwise, so `w = 0` inside a hole), or `c` on a ring. Exact `orient2d` per edge; the
//!    edges are bucketed by `y`-band so a query touches only the edges that can cross its
//!    horizontal ray (`O(n + q·n/B)` for `B` bands instead of `O(q·n)`).
//! 3. **Area.** `A_mesh = Σ_cells ½|Σ_k P_k × P_{k+1}|` (shoelace, signed) against the region's
//!    area `A_Ω`: `|A_mesh − A_Ω| ≤ τ·A_Ω` with `τ` = [`VerifyOptions::area_tolerance`]. The
//!    mesh boundary is a chord polygon of the region boundary (nodes on the rings), so the
//!    defect is of the order of the chord error; a dropped part or hole changes it by the
//!    part's share.
//! 4. **Holes.** The mesh's hole count from its Euler characteristic: for a planar mesh with
//!    `C` connected components, `V − E + F = C − H` (Euler–Poincaré; each component is a disk
//!    with holes), so `H = C − (V − E + F)` with `V` the nodes used by cells, `E` the distinct
//!    edges, `F` the cells. It must equal the region's hole count (and `C` must be 1).
//!
//! [`verify_hexes`] applies the thesis's convexity test of hexahedra: the ten tetrahedra of
//! [`unamalla_mesh::quality::hex::HEX_TETS`] ([Cortés Aguirre 2012, §3.2.1, (3.24)]) all of
//! positive volume `V = (S − P)·((Q − P) × (R − P)) > 0`.

use std::collections::HashMap;
use std::fmt;

use serde::Serialize;
use unamalla_mesh::geometry::orient2d;
use unamalla_mesh::quality::hex::HEX_TETS;
use unamalla_mesh::{DVec2, DVec3, HasHexCells, HasQuadCells, Region};

/// How many offending cells a [`Verification`] lists by index.
pub const LISTED_CELLS: usize = 5;

/// Tolerances of [`verify_quads`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[non_exhaustive]
pub struct VerifyOptions {
    /// Largest accepted relative area defect `|A_mesh − A_Ω| / A_Ω`.
    pub area_tolerance: f64,
}

impl Default for VerifyOptions {
    /// `area_tolerance = 0.02` (2 %): the bundled regions meshed at 20,000 cells differ from
    /// the meshed (simplified) region by well below 1 % (chord error), while a dropped part or
    /// a 4-cell mesh of a curved region (`--cells 0` used to give one: 32 %) is far above.
    fn default() -> Self {
        Self {
            area_tolerance: 0.02,
        }
    }
}

impl VerifyOptions {
    /// Sets [`area_tolerance`](Self::area_tolerance): largest accepted relative area defect
    /// `|A_mesh − A_Ω| / A_Ω`.
    #[must_use]
    pub fn area_tolerance(mut self, area_tolerance: f64) -> Self {
        self.area_tolerance = area_tolerance;
        self
    }
}

/// The outcome of [`verify_quads`] / [`verify_hexes`]; `report.json` carries it as
/// `verification`.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct Verification {
    /// Number of cells checked.
    pub cells: usize,
    /// Cells with a non-positive corner triangle (hexes: tetrahedron).
    pub non_convex_cells: usize,
    /// The first [`LISTED_CELLS`] of them.
    pub non_convex_examples: Vec<usize>,
    /// The corners of [`Self::non_convex_examples`] (quads; empty for hexes), so that a
    /// failure can be located against the region (`preflight::explain_guarantee`).
    pub non_convex_at: Vec<[[f64; 2]; 4]>,
    /// Smallest corner value `α_k` (quads: twice the corner triangle's area; hexes: `V`).
    pub min_corner: f64,
    /// Cells whose centroid is outside the region (`None`: no region given).
    pub centroids_outside: Option<usize>,
    /// The first [`LISTED_CELLS`] of them with their centroids.
    pub outside_examples: Vec<(usize, [f64; 2])>,
    /// Area of the mesh (quads only).
    pub mesh_area: Option<f64>,
    /// Area of the region.
    pub region_area: Option<f64>,
    /// `|A_mesh − A_Ω| / A_Ω`.
    pub relative_area_defect: Option<f64>,
    /// The tolerance it was compared with.
    pub area_tolerance: Option<f64>,
    /// Holes of the mesh (Euler characteristic) and connected components.
    pub mesh_holes: Option<i64>,
    /// Connected components of the mesh (cells sharing an edge or a node).
    pub mesh_components: Option<usize>,
    /// Holes of the region.
    pub region_holes: Option<usize>,
    /// Relative area change against the input region (before simplification), when checked.
    pub input_area_defect: Option<f64>,
    /// The tolerance it was compared with.
    pub input_area_tolerance: Option<f64>,
}

impl Verification {
    /// `true` iff every check passed.
    pub fn passed(&self) -> bool {
        self.failures().is_empty()
    }

    /// One sentence per failed check.
    pub fn failures(&self) -> Vec<String> {
        let mut f = Vec::new();
        if self.cells == 0 {
            f.push("the mesh has no cells".to_string());
        }
        if self.non_convex_cells > 0 {
            f.push(format!(
                "{} of {} cells are not convex (cells {:?}; smallest corner value {:.3e})",
                self.non_convex_cells, self.cells, self.non_convex_examples, self.min_corner
            ));
        }
        if let Some(n) = self.centroids_outside.filter(|&n| n > 0) {
            let ex: Vec<String> = self
                .outside_examples
                .iter()
                .map(|(c, p)| format!("cell {c} at ({:.6e}, {:.6e})", p[0], p[1]))
                .collect();
            f.push(format!(
                "{n} cell centroids lie outside the region ({})",
                ex.join(", ")
            ));
        }
        if let (Some(d), Some(t), Some(m), Some(r)) = (
            self.relative_area_defect,
            self.area_tolerance,
            self.mesh_area,
            self.region_area,
        ) {
            if d.is_nan() || d > t {
                f.push(format!(
                    "the mesh area {m:.6e} differs from the region area {r:.6e} by {:.3} % (tolerance {:.3} %)",
                    100.0 * d,
                    100.0 * t
                ));
            }
        }
        if let (Some(d), Some(t)) = (self.input_area_defect, self.input_area_tolerance) {
            if d.is_nan() || d > t {
                f.push(format!(
                    "the mesh area differs from the input region's by {:.3} % (tolerance {:.3} %); ask for more cells",
                    100.0 * d,
                    100.0 * t
                ));
            }
        }
        if let (Some(h), Some(c), Some(r)) =
            (self.mesh_holes, self.mesh_components, self.region_holes)
        {
            if c != 1 || h != r as i64 {
                f.push(format!(
                    "the mesh has {c} connected component(s) and {h} hole(s), the region 1 and {r}"
                ));
            }
        }
        f
    }
}

impl fmt::Display for Verification {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let fails = self.failures();
        if fails.is_empty() {
            write!(f, "all {} cells convex and inside the region", self.cells)
        } else {
            write!(f, "{}", fails.join("; "))
        }
    }
}

/// The output did not pass [`verify_quads`] / [`verify_hexes`]: the run must not report
/// success (CLI exit code 3, or a written output with `--allow-non-convex` and a warning).
#[derive(Debug, Clone, thiserror::Error)]
#[error("the mesh does not meet the guarantee (convex cells inside the region): {0}")]
pub struct GuaranteeNotMet(pub Box<Verification>);

impl Verification {
    /// `Ok(())` if passed, else the [`GuaranteeNotMet`] error.
    pub fn into_result(self) -> Result<(), GuaranteeNotMet> {
        if self.passed() {
            Ok(())
        } else {
            Err(GuaranteeNotMet(Box::new(self)))
        }
    }
}

/// The corner values `α_k = orient2d(P_{k−1}, P_k, P_{k+1})`, exact in sign, of a quad.
fn quad_corners(p: &[DVec2; 4]) -> [f64; 4] {
    std::array::from_fn(|k| orient2d(p[(k + 3) % 4], p[k], p[(k + 1) % 4]))
}

/// Checks `mesh` (see the module documentation). With `region`, also the centroids, the area
/// and the hole count against it.
pub fn verify_quads<M: HasQuadCells>(
    mesh: &M,
    region: Option<&Region>,
    opts: &VerifyOptions,
) -> Verification {
    let n = mesh.num_quads();
    let mut v = Verification {
        cells: n,
        min_corner: f64::INFINITY,
        ..Default::default()
    };
    for c in 0..n {
        let p = mesh.quad_points(c);
        let a = quad_corners(&p);
        let m = a.iter().copied().fold(f64::INFINITY, f64::min);
        let m = if a.iter().any(|x| x.is_nan()) {
            f64::NAN
        } else {
            m
        };
        if m.is_nan() || m < v.min_corner {
            v.min_corner = m;
        }
        // NaN counts as not convex
        if m.is_nan() || m <= 0.0 {
            v.non_convex_cells += 1;
            if v.non_convex_examples.len() < LISTED_CELLS {
                v.non_convex_examples.push(c);
                v.non_convex_at.push(p.map(|q| [q.x, q.y]));
            }
        }
    }
    let Some(region) = region else {
        return v;
    };
    let locator = RingLocator::new(region);
    let mut outside = 0;
    let mut area = 0.0;
    for c in 0..n {
        let p = mesh.quad_points(c);
        let centroid = (p[0] + p[1] + p[2] + p[3]) * 0.25;
        if !locator.in_closed_region(centroid) {
            outside += 1;
            if v.outside_examples.len() < LISTED_CELLS {
                v.outside_examples.push((c, [centroid.x, centroid.y]));
            }
        }
        // the fan from the first corner (`signed_area`, as the pipeline's report computes it):
        // the shoelace sum of the corner coordinates themselves cancels catastrophically far
        // from the origin (at 10⁹ its terms are 10¹⁸ for cells of unit area)
        area += unamalla_mesh::region::signed_area(&p);
    }
    let ra = region.area();
    v.centroids_outside = Some(outside);
    v.mesh_area = Some(area);
    v.region_area = Some(ra);
    v.relative_area_defect = Some((area - ra).abs() / ra);
    v.area_tolerance = Some(opts.area_tolerance);
    let (holes, components) = euler_holes(mesh);
    v.mesh_holes = Some(holes);
    v.mesh_components = Some(components);
    v.region_holes = Some(region.holes().len());
    v
}

/// `H = C − (V − E + F)` and `C` of the cell complex (module documentation, check 4).
fn euler_holes<M: HasQuadCells>(mesh: &M) -> (i64, usize) {
    let n = mesh.num_quads();
    let mut edges: HashMap<(usize, usize), ()> = HashMap::with_capacity(2 * n + 4);
    let mut parent: Vec<usize> = (0..mesh.num_nodes()).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut used = vec![false; mesh.num_nodes()];
    for c in 0..n {
        let q = mesh.quad(c);
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            used[a] = true;
            edges.insert((a.min(b), a.max(b)), ());
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra != rb {
                parent[ra] = rb;
            }
        }
    }
    let vcount = used.iter().filter(|&&u| u).count();
    let components = (0..parent.len())
        .filter(|&x| used[x] && find(&mut parent, x) == x)
        .count();
    let chi = vcount as i64 - edges.len() as i64 + n as i64;
    (components as i64 - chi, components)
}

/// Checks every hex of `mesh`: the ten tetrahedra of the thesis's convexity test positive.
pub fn verify_hexes<M: HasHexCells>(mesh: &M) -> Verification {
    let n = mesh.num_hexes();
    let mut v = Verification {
        cells: n,
        min_corner: f64::INFINITY,
        ..Default::default()
    };
    let det = |p: DVec3, q: DVec3, r: DVec3, s: DVec3| (s - p).dot((q - p).cross(r - p));
    for c in 0..n {
        let h = mesh.hex_points(c);
        let mut m = f64::INFINITY;
        for t in HEX_TETS {
            let d = det(h[t[0]], h[t[1]], h[t[2]], h[t[3]]);
            m = if d.is_nan() { f64::NAN } else { m.min(d) };
        }
        if m.is_nan() || m < v.min_corner {
            v.min_corner = m;
        }
        // NaN counts as not convex
        if m.is_nan() || m <= 0.0 {
            v.non_convex_cells += 1;
            if v.non_convex_examples.len() < LISTED_CELLS {
                v.non_convex_examples.push(c);
            }
        }
    }
    v
}

/// Point location in a region by the winding number over all rings, with the edges bucketed
/// in horizontal bands (module documentation, check 2).
pub struct RingLocator {
    edges: Vec<(DVec2, DVec2)>,
    y0: f64,
    band_height: f64,
    bands: Vec<Vec<u32>>,
}

impl RingLocator {
    /// The index of `region`'s edges.
    pub fn new(region: &Region) -> Self {
        let mut edges = Vec::with_capacity(region.num_vertices());
        for r in region.rings() {
            let p = r.points();
            for k in 0..p.len() {
                edges.push((p[k], p[(k + 1) % p.len()]));
            }
        }
        let (lo, hi) = region.bounding_box();
        let nb = (edges.len() / 4).clamp(1, 1 << 16);
        let band_height = ((hi.y - lo.y) / nb as f64).max(f64::MIN_POSITIVE);
        let mut bands = vec![Vec::new(); nb];
        let band = |y: f64| (((y - lo.y) / band_height) as usize).min(nb - 1);
        for (k, (a, b)) in edges.iter().enumerate() {
            for list in &mut bands[band(a.y.min(b.y))..=band(a.y.max(b.y))] {
                list.push(k as u32);
            }
        }
        Self {
            edges,
            y0: lo.y,
            band_height,
            bands,
        }
    }

    /// `true` iff `p` is inside the region or on one of its rings.
    pub fn in_closed_region(&self, p: DVec2) -> bool {
        if !p.is_finite() {
            return false;
        }
        let nb = self.bands.len();
        let fb = (p.y - self.y0) / self.band_height;
        if fb < 0.0 || fb >= nb as f64 + 1.0 {
            return false;
        }
        let list = &self.bands[(fb as usize).min(nb - 1)];
        let mut winding = 0i64;
        for &k in list {
            let (a, b) = self.edges[k as usize];
            let o = orient2d(a, b, p);
            if o == 0.0
                && p.x >= a.x.min(b.x)
                && p.x <= a.x.max(b.x)
                && p.y >= a.y.min(b.y)
                && p.y <= a.y.max(b.y)
            {
                return true;
            }
            if a.y <= p.y {
                if b.y > p.y && o > 0.0 {
                    winding += 1;
                }
            } else if b.y <= p.y && o < 0.0 {
                winding -= 1;
            }
        }
        winding != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::{HasNodes, QuadMesh};

    fn square_with_hole() -> Region {
        let outer = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 0.0),
            DVec2::new(3.0, 3.0),
            DVec2::new(0.0, 3.0),
        ];
        let hole = vec![
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 2.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(2.0, 1.0),
        ];
        Region::new(outer, vec![hole]).unwrap()
    }

    /// The 3×3 unit-cell grid on [0,3]² without its middle cell: exactly the region above.
    fn ring_mesh() -> QuadMesh {
        let nodes: Vec<DVec2> = (0..16)
            .map(|k| DVec2::new((k % 4) as f64, (k / 4) as f64))
            .collect();
        let mut cells = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                if (i, j) != (1, 1) {
                    let a = j * 4 + i;
                    cells.push([a, a + 1, a + 5, a + 4]);
                }
            }
        }
        QuadMesh::new(nodes, cells).unwrap()
    }

    /// The same region and mesh moved to (10⁹, 10⁹): every coordinate is exact there
    /// (integers below 2⁵³), so the area must still be exactly 8 (the shoelace sum of the
    /// coordinates themselves gave 0 at this offset: terms of 10¹⁸ cancelling).
    #[test]
    fn the_area_check_holds_far_from_the_origin() {
        let o = DVec2::splat(1e9);
        let r = square_with_hole();
        let r = Region::new(
            r.outer().points().iter().map(|&p| p + o).collect(),
            vec![r.holes()[0].points().iter().map(|&p| p + o).collect()],
        )
        .unwrap();
        let mut m = ring_mesh();
        m.nodes_mut().iter_mut().for_each(|p| *p += o);
        let v = verify_quads(&m, Some(&r), &VerifyOptions::default());
        assert!(v.passed(), "{v}");
        assert_eq!(v.mesh_area, Some(8.0));
    }

    #[test]
    fn an_exact_mesh_passes_with_derived_numbers() {
        let r = square_with_hole();
        let v = verify_quads(&ring_mesh(), Some(&r), &VerifyOptions::default());
        assert!(v.passed(), "{v}");
        assert_eq!(v.cells, 8);
        // unit squares: every corner value is det = 1
        assert_eq!(v.min_corner, 1.0);
        assert_eq!(v.mesh_area, Some(8.0));
        assert_eq!(v.region_area, Some(8.0));
        // V = 16, E = 24 (12 horizontal + 12 vertical), F = 8: χ = 0 = 1 − H, H = 1
        assert_eq!(v.mesh_holes, Some(1));
        assert_eq!(v.mesh_components, Some(1));
    }

    #[test]
    fn each_defect_is_found_and_named() {
        let r = square_with_hole();
        let opts = VerifyOptions::default();
        // fold node 5 (1,1) over to (1.5, 0.5)... inside cell 0: cell 0 becomes non-convex
        let mut m = ring_mesh();
        m.nodes_mut()[5] = DVec2::new(0.25, 0.25);
        let v = verify_quads(&m, Some(&r), &opts);
        // the cells around node 5: 0 (reflex corner at 5), 1 and 3 (hole corner moved):
        assert!(v.non_convex_cells >= 1, "{v}");
        assert!(v.non_convex_examples.contains(&0));
        assert!(v.failures()[0].contains("not convex"), "{v}");
        // the mesh also no longer matches the hole: the area grows by the moved corner's
        // triangle pair, |ΔA| = 2·½·|(0.75,0.75)×(1,0)| ... ≠ 0
        assert!(v.relative_area_defect.unwrap() > 0.0);

        // a mesh that covers the hole: 9 cells, 1 cell centroid (1.5, 1.5) inside the hole,
        // area 9 vs 8 (12.5 %), H = 0
        let nodes: Vec<DVec2> = (0..16)
            .map(|k| DVec2::new((k % 4) as f64, (k / 4) as f64))
            .collect();
        let cells: Vec<[usize; 4]> = (0..9)
            .map(|c| {
                let a = (c / 3) * 4 + c % 3;
                [a, a + 1, a + 5, a + 4]
            })
            .collect();
        let full = QuadMesh::new(nodes, cells).unwrap();
        let v = verify_quads(&full, Some(&r), &opts);
        assert_eq!(v.non_convex_cells, 0);
        assert_eq!(v.centroids_outside, Some(1));
        assert_eq!(v.outside_examples, vec![(4, [1.5, 1.5])]);
        assert_eq!(v.relative_area_defect, Some(0.125));
        assert_eq!(v.mesh_holes, Some(0));
        let text = v.to_string();
        assert!(text.contains("outside the region"), "{text}");
        assert!(text.contains("12.500 %"), "{text}");
        assert!(text.contains("0 hole(s), the region 1 and 1"), "{text}");
        assert!(v.clone().into_result().is_err());
    }

    #[test]
    fn clockwise_cells_are_not_convex() {
        let nodes = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.0),
        ];
        let m = QuadMesh::new(nodes, vec![[0, 1, 2, 3]]).unwrap();
        let v = verify_quads(&m, None, &VerifyOptions::default());
        assert_eq!(v.non_convex_cells, 1);
        assert_eq!(v.min_corner, -1.0);
        // a degenerate cell (three collinear corners) is not convex either: exact zero
        let nodes = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(0.5, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
        ];
        let m = QuadMesh::new(nodes, vec![[0, 1, 2, 3]]).unwrap();
        let v = verify_quads(&m, None, &VerifyOptions::default());
        assert_eq!(v.non_convex_cells, 1);
        assert_eq!(v.min_corner, 0.0);
    }

    #[test]
    fn the_banded_locator_agrees_with_the_plain_winding_number() {
        // a comb-like region with many edges: compare with the O(n) exact locate
        let mut outer = vec![DVec2::new(0.0, 0.0), DVec2::new(40.0, 0.0)];
        for k in (0..20).rev() {
            let x = 2.0 * k as f64;
            outer.push(DVec2::new(x + 2.0, 10.0 + (k % 3) as f64));
            outer.push(DVec2::new(x + 1.0, 2.0 + (k % 5) as f64 * 0.5));
        }
        let r = Region::new(outer, vec![]).unwrap();
        let loc = RingLocator::new(&r);
        let mut seed = 12345u64;
        for _ in 0..5000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = (seed >> 11) as f64 / (1u64 << 53) as f64 * 44.0 - 2.0;
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let y = (seed >> 11) as f64 / (1u64 << 53) as f64 * 16.0 - 2.0;
            let p = DVec2::new(x, y);
            let want = r.locate(p) != unamalla_mesh::Location::Outside;
            assert_eq!(loc.in_closed_region(p), want, "{p}");
        }
        // vertices are on the boundary
        for p in r.outer().points() {
            assert!(loc.in_closed_region(*p));
        }
        assert!(!loc.in_closed_region(DVec2::new(f64::NAN, 1.0)));
    }

    #[test]
    fn hexes_use_the_ten_tetrahedra() {
        use unamalla_mesh::StructuredGrid3;
        let g =
            StructuredGrid3::from_fn(2, 2, 2, |i, j, k| DVec3::new(i as f64, j as f64, k as f64))
                .unwrap();
        let v = verify_hexes(&g);
        assert!(v.passed(), "{v}");
        // unit cube: corner tets V = 1, interior V = 2
        assert_eq!(v.min_corner, 1.0);
        let mut bad = g.clone();
        // push the top face's node (1,1,1) below the bottom face: inverted
        let idx = bad.index(1, 1, 1);
        bad.nodes_mut()[idx] = DVec3::new(1.0, 1.0, -1.0);
        let v = verify_hexes(&bad);
        assert_eq!(v.non_convex_cells, 1);
        assert!(v.min_corner < 0.0);
    }
}
