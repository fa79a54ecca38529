//! Cell classification and admissibility ([Cortés Aguirre 2012, §3.3]; the references
//! are listed in `docs/references.md` of the repository).
//!
//! With boundary nodes fixed, a cell of a structured hex grid is
//! * a **corner** cell: 7 boundary nodes, 5 of its 10 tetrahedra have only fixed vertices;
//! * an **edge** cell: 6 boundary nodes, 2 fixed tetrahedra;
//! * a **face** cell: 4 boundary nodes, no fixed tetrahedron;
//! * an **interior** cell: no boundary node (for a grid, `1 ≤ i ≤ m−3` etc. 0-based; the
//!   thesis's `1 < i < m−1`, 1-based). Algorithm B's planarity penalty acts on these.
//!
//! There are 8 corner cells (the thesis says four). A grid with fewer than 4
//! nodes along some direction has cells with other counts (e.g. 8 fixed nodes when `m = 2`);
//! they are [`CellClass::Other`].
//!
//! **Admissibility** (Def. 11): every *fixed* tetrahedron (all four vertices fixed) of the
//! split [`HEX_TETS`] has `V > 0`; nothing the optimiser does can repair a fixed tetrahedron,
//! so an inadmissible region can never become convex.

use crate::quality::hex::{tet_det, HEX_TETS};
use crate::traits::{FreeNodes, HasHexCells};

/// The class of a cell (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum CellClass {
    /// 7 fixed nodes.
    Corner,
    /// 6 fixed nodes.
    Edge,
    /// 4 fixed nodes.
    Face,
    /// No fixed node.
    Interior,
    /// Any other number of fixed nodes (degenerate sizes, unstructured meshes).
    Other(u8),
}

impl CellClass {
    /// The class of a cell with `fixed` fixed nodes.
    pub fn from_fixed_count(fixed: usize) -> Self {
        match fixed {
            7 => CellClass::Corner,
            6 => CellClass::Edge,
            4 => CellClass::Face,
            0 => CellClass::Interior,
            k => CellClass::Other(k.min(8) as u8),
        }
    }
}

/// Number of cells of each class.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ClassCounts {
    /// Corner cells.
    pub corner: usize,
    /// Edge cells.
    pub edge: usize,
    /// Face cells.
    pub face: usize,
    /// Interior cells.
    pub interior: usize,
    /// Other cells.
    pub other: usize,
}

/// The class of every cell, in cell order.
pub fn classify_cells<M: HasHexCells + FreeNodes + ?Sized>(mesh: &M) -> Vec<CellClass> {
    (0..mesh.num_hexes())
        .map(|c| {
            let n = mesh.hex(c).iter().filter(|&&v| mesh.is_fixed(v)).count();
            CellClass::from_fixed_count(n)
        })
        .collect()
}

/// Counts of [`classify_cells`].
pub fn class_counts(classes: &[CellClass]) -> ClassCounts {
    let mut k = ClassCounts::default();
    for c in classes {
        match c {
            CellClass::Corner => k.corner += 1,
            CellClass::Edge => k.edge += 1,
            CellClass::Face => k.face += 1,
            CellClass::Interior => k.interior += 1,
            CellClass::Other(_) => k.other += 1,
        }
    }
    k
}

/// A fixed tetrahedron with `V ≤ 0`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FixedTetViolation {
    /// The cell.
    pub cell: usize,
    /// Row of [`HEX_TETS`].
    pub tet: usize,
    /// Its `V = 6 × signed volume`.
    pub v: f64,
}

/// The admissibility check of Def. 11.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Admissibility {
    /// Number of fixed tetrahedra checked.
    pub fixed_tets: usize,
    /// Smallest `V` among them (`+∞` if none).
    pub min_fixed_v: f64,
    /// The fixed tetrahedra with `V ≤ 0`.
    pub violations: Vec<FixedTetViolation>,
}

impl Admissibility {
    /// `true` iff every fixed tetrahedron is positive.
    pub fn is_admissible(&self) -> bool {
        self.violations.is_empty()
    }
}

/// Checks every tetrahedron of [`HEX_TETS`] whose four vertices are fixed.
pub fn admissibility<M: HasHexCells + FreeNodes + ?Sized>(mesh: &M) -> Admissibility {
    let x = mesh.nodes();
    let mut out = Admissibility {
        fixed_tets: 0,
        min_fixed_v: f64::INFINITY,
        violations: Vec::new(),
    };
    for c in 0..mesh.num_hexes() {
        let h = mesh.hex(c);
        for (t, tet) in HEX_TETS.iter().enumerate() {
            if tet.iter().all(|&l| mesh.is_fixed(h[l])) {
                let q = tet.map(|l| x[h[l]]);
                let v = tet_det(q[0], q[1], q[2], q[3]);
                out.fixed_tets += 1;
                out.min_fixed_v = out.min_fixed_v.min(v);
                if v.is_nan() || v <= 0.0 {
                    out.violations
                        .push(FixedTetViolation { cell: c, tet: t, v });
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::StructuredGrid3;
    use crate::traits::HasNodes;
    use glam::DVec3;

    fn grid(m: usize, n: usize, p: usize) -> StructuredGrid3 {
        StructuredGrid3::from_fn(m, n, p, |i, j, k| DVec3::new(i as f64, j as f64, k as f64))
            .unwrap()
    }

    #[test]
    fn class_counts_of_a_grid() {
        let (m, n, p) = (5, 6, 7);
        let g = grid(m, n, p);
        let k = class_counts(&classify_cells(&g));
        // 8 corners; 4 edges per direction of (cells − 2) each; 2 faces per pair of
        // (cells − 2)²; interior (cells − 2)³ with cells = nodes − 1
        let (a, b, c) = (m - 3, n - 3, p - 3);
        assert_eq!(k.corner, 8);
        assert_eq!(k.edge, 4 * (a + b + c));
        assert_eq!(k.face, 2 * (a * b + a * c + b * c));
        assert_eq!(k.interior, a * b * c);
        assert_eq!(k.other, 0);
        assert_eq!(k.corner + k.edge + k.face + k.interior, g.num_cells());
        // interior ⇔ 0-based 1 ≤ i ≤ m−3 (the thesis's 1 < i < m−1, 1-based)
        let cl = classify_cells(&g);
        assert_eq!(cl[g.num_cells() - 1], CellClass::Corner);
        let id = |i: usize, j: usize, kk: usize| (kk * (n - 1) + j) * (m - 1) + i;
        assert_eq!(cl[id(1, 1, 1)], CellClass::Interior);
        assert_eq!(cl[id(m - 3, n - 3, p - 3)], CellClass::Interior);
        assert_eq!(cl[id(0, 2, 2)], CellClass::Face);
        assert_eq!(cl[id(0, 0, 2)], CellClass::Edge);
        assert_eq!(class_counts(&classify_cells(&grid(2, 3, 3))).other, 4);
    }

    #[test]
    fn corner_cells_have_five_fixed_tets_and_edge_cells_two() {
        // [Cortés Aguirre 2012, §3.3]: corner cell → 5 fixed tets, edge cell → 2, face/interior → 0
        let g = grid(5, 5, 5);
        let cls = classify_cells(&g);
        for (c, cl) in cls.iter().enumerate() {
            let h = g.hex(c);
            let fixed = HEX_TETS
                .iter()
                .filter(|t| t.iter().all(|&l| g.is_fixed(h[l])))
                .count();
            let want = match cl {
                CellClass::Corner => 5,
                CellClass::Edge => 2,
                _ => 0,
            };
            assert_eq!(fixed, want, "cell {c} {cl:?}");
        }
        let a = admissibility(&g);
        assert!(a.is_admissible());
        // 8 corners × 5 + 4·3·2 edges × 2 = 40 + 48
        assert_eq!(a.fixed_tets, 88);
        // unit cubes: corner tets have V = 1
        assert_eq!(a.min_fixed_v, 1.0);
    }

    #[test]
    fn a_dented_corner_is_inadmissible() {
        let mut g = grid(4, 4, 4);
        // push the boundary node (1, 0, 0) deep inward: the corner cell (0,0,0) has fixed tets
        // on it that invert
        let id = g.index(1, 0, 0);
        g.nodes_mut()[id] = DVec3::new(1.0, 3.5, 3.5);
        let a = admissibility(&g);
        assert!(!a.is_admissible());
        assert!(a.violations.iter().all(|v| v.v <= 0.0));
        assert!(a.violations.iter().any(|v| v.cell == 0));
    }
}
