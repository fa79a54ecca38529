//! [Cortés Aguirre 2012, Appendix A] (the references are listed in `docs/references.md` of the
//! repository): counting variables against planarity constraints.
//!
//! For an `m × n × p` grid (`m, n, p ≥ 4` nodes) with `M = m−2`, `N = n−2`, `P = p−2`
//! (free nodes per direction):
//!
//! | quantity | formula |
//! |---|---|
//! | cells `C_T` | `(m−1)(n−1)(p−1)` |
//! | interior cells `C_int` | `(m−3)(n−3)(p−3)` |
//! | variables `N_var` | `3MNP` |
//! | faces `F_T` | `m(n−1)(p−1) + n(m−1)(p−1) + p(m−1)(n−1)` |
//! | faces of the interior block `F_Cint` | `(m−2)(n−3)(p−3) + (n−2)(m−3)(p−3) + (p−2)(m−3)(n−3)` |
//! | neighbour block `Bloq_{(m−2)(n−2)}` | `(m−2)(n−3) + (n−2)(m−3)` (×2 per pair) |
//! | `F_int` (A.6) | `F_Cint + 2ΣBloq = 3mnp − 4(mn+mp+np) + m+n+p + 18` |
//!
//! Theorems (margins = variables − constraints):
//! * **A.1** `F_Cint < N_var`; the margin (the tables' "DOF") is (A.8)
//!   `2(MN+MP+NP) − (M+N+P)` — Table A1's samples 4³ → 18, 5³ → 45, 6³ → 84, 7³ → 135,
//!   8³ → 198, 10³ → 360.
//! * **A.2** `F_int > N_var`, by `F_int − N_var = 2(MN+MP+NP) − 3(M+N+P)` (Table A2's "Dif").
//! * **A.3** removing three neighbour blocks, the two of the pair with the largest product
//!   `MN` and one more, gives the margins `2MN − 2NP + N + 2P` (third block of the `MP`
//!   pair) and `2MN − 2MP + M + 2P` (third block of the `NP` pair), `P` the smallest size.
//!   Derivation: `N_var − (F_int − 2Bloq_MN − Bloq_X)` with `Bloq_MN = 2MN − M − N`.
//! * **A.4** freeing the interior nodes of the two largest opposite boundary faces adds
//!   `6MN` variables; margin `4MN − 2MP − 2NP + 3(M+N+P)`.
//!
//! The thesis imposes planarity only on the interior block (`F_Cint`, the well-posed choice
//! of A.1), which is what Algorithm B's penalty does. All counts use `i64`-free `usize`
//! arithmetic except the margins, which can be negative and are `i64`.

use super::error::HexGenError;

/// The appendix A counts of one grid size (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct PlanarityCounts {
    /// Node counts `(m, n, p)`.
    pub dims: (usize, usize, usize),
    /// `C_T`.
    pub cells: usize,
    /// `C_int`.
    pub interior_cells: usize,
    /// `N_var`.
    pub variables: usize,
    /// `F_T`.
    pub faces: usize,
    /// `F_Cint` (faces of the interior block, shared faces once).
    pub interior_block_faces: usize,
    /// `Bloq_{(m−2)(n−2)}`, `Bloq_{(m−2)(p−2)}`, `Bloq_{(n−2)(p−2)}`.
    pub blocks: (usize, usize, usize),
    /// `F_int` (A.6).
    pub f_int: usize,
    /// A.1 margin `N_var − F_Cint` (> 0).
    pub dof: i64,
    /// A.2 excess `F_int − N_var` (> 0).
    pub excess: i64,
    /// A.3 margins (third block from the `MP` pair, from the `NP` pair).
    pub margin_a3: (i64, i64),
    /// A.4 margin.
    pub margin_a4: i64,
}

/// Appendix A counts for an `m × n × p` grid, `m, n, p ≥ 4`. For A.3/A.4 the sizes are
/// ordered as the theorems assume (`P` the smallest, `MN` the largest pair); the other
/// fields follow the given order.
///
/// ```
/// use unamalla_mesh::hexgen::planarity_counts;
/// assert_eq!(planarity_counts(4, 4, 4).unwrap().dof, 18);
/// assert_eq!(planarity_counts(5, 5, 5).unwrap().dof, 45);
/// assert_eq!(planarity_counts(10, 10, 10).unwrap().dof, 360);
/// ```
pub fn planarity_counts(m: usize, n: usize, p: usize) -> Result<PlanarityCounts, HexGenError> {
    if m < 4 || n < 4 || p < 4 {
        return Err(HexGenError::TooSmall {
            dims: (m, n, p),
            reason: "appendix A needs at least 4 nodes per direction",
        });
    }
    let cells = (m - 1) * (n - 1) * (p - 1);
    let interior_cells = (m - 3) * (n - 3) * (p - 3);
    let (mm, nn, pp) = (m - 2, n - 2, p - 2);
    let variables = 3 * mm * nn * pp;
    let faces = m * (n - 1) * (p - 1) + n * (m - 1) * (p - 1) + p * (m - 1) * (n - 1);
    let interior_block_faces =
        (m - 2) * (n - 3) * (p - 3) + (n - 2) * (m - 3) * (p - 3) + (p - 2) * (m - 3) * (n - 3);
    let bloq = |a: usize, b: usize| (a - 2) * (b - 3) + (b - 2) * (a - 3);
    let blocks = (bloq(m, n), bloq(m, p), bloq(n, p));
    let f_int = interior_block_faces + 2 * (blocks.0 + blocks.1 + blocks.2);
    let (mi, ni, pi) = (mm as i64, nn as i64, pp as i64);
    let dof = variables as i64 - interior_block_faces as i64;
    let excess = f_int as i64 - variables as i64;
    // theorem ordering: P smallest, then M ≥ N
    let mut s = [mi, ni, pi];
    s.sort_unstable_by(|a, b| b.cmp(a));
    let (a, b, c) = (s[0], s[1], s[2]);
    let margin_a3 = (
        2 * a * b - 2 * b * c + b + 2 * c,
        2 * a * b - 2 * a * c + a + 2 * c,
    );
    let margin_a4 = 4 * a * b - 2 * a * c - 2 * b * c + 3 * (a + b + c);
    Ok(PlanarityCounts {
        dims: (m, n, p),
        cells,
        interior_cells,
        variables,
        faces,
        interior_block_faces,
        blocks,
        f_int,
        dof,
        excess,
        margin_a3,
        margin_a4,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_a1_samples() {
        // [Cortés Aguirre 2012, Table A1]: 444→18, 555→45, 666→84, 777→135, 888→198, 10³→360
        for (n, want) in [(4, 18), (5, 45), (6, 84), (7, 135), (8, 198), (10, 360)] {
            assert_eq!(planarity_counts(n, n, n).unwrap().dof, want, "{n}³");
        }
    }

    #[test]
    fn table_a2_samples() {
        // 444 → Nvar 24, Fint 30, Dif 6, bq 4/4/4; 777 → 375/480/105/40/40/40
        let c = planarity_counts(4, 4, 4).unwrap();
        assert_eq!(
            (c.variables, c.f_int, c.excess, c.blocks),
            (24, 30, 6, (4, 4, 4))
        );
        let c = planarity_counts(7, 7, 7).unwrap();
        assert_eq!(
            (c.variables, c.f_int, c.excess, c.blocks),
            (375, 480, 105, (40, 40, 40))
        );
    }

    #[test]
    fn closed_forms_agree_with_the_sums_for_all_table_sizes() {
        for m in 4..=10 {
            for n in 4..=10 {
                for p in 4..=10 {
                    let c = planarity_counts(m, n, p).unwrap();
                    let (mi, ni, pi) = (m as i64, n as i64, p as i64);
                    // (A.6)
                    let a6 =
                        3 * mi * ni * pi - 4 * (mi * ni + mi * pi + ni * pi) + mi + ni + pi + 18;
                    assert_eq!(c.f_int as i64, a6);
                    let (mm, nn, pp) = (mi - 2, ni - 2, pi - 2);
                    // (A.8) and Thm A.2
                    assert_eq!(c.dof, 2 * (mm * nn + mm * pp + nn * pp) - (mm + nn + pp));
                    assert_eq!(
                        c.excess,
                        2 * (mm * nn + mm * pp + nn * pp) - 3 * (mm + nn + pp)
                    );
                    assert_eq!(
                        c.excess,
                        2 * (mi * ni + mi * pi + ni * pi) - 11 * (mi + ni + pi) + 42
                    );
                    // Theorems A.1 and A.2
                    assert!(c.dof > 0 && c.excess > 0);
                    // interior cells × 6 faces − shared faces = F_Cint
                    let shared = (m as i64 - 4) * (n as i64 - 3) * (p as i64 - 3)
                        + (m as i64 - 3) * (n as i64 - 4) * (p as i64 - 3)
                        + (m as i64 - 3) * (n as i64 - 3) * (p as i64 - 4);
                    assert_eq!(
                        c.interior_block_faces as i64,
                        6 * c.interior_cells as i64 - shared
                    );
                }
            }
        }
    }

    #[test]
    fn appendix_examples() {
        // 5³: removing 3 blocks of 12 leaves 72 constraints for 81 variables (margin 9);
        // freeing 9 boundary nodes gives 108 = 108 (margin 0: an equality, though the thesis
        // calls it well posed, [Cortés Aguirre 2012, §A.3.4])
        let c = planarity_counts(5, 5, 5).unwrap();
        assert_eq!(
            (c.variables, c.interior_block_faces, c.f_int),
            (81, 36, 108)
        );
        assert_eq!(c.blocks.0, 12);
        assert_eq!(c.margin_a3, (9, 9));
        assert_eq!(c.variables as i64 + 27 - c.f_int as i64, 0);
        // 6×6×7: 36 interior cells, 240 variables, (a) 141, (b) 313
        let c = planarity_counts(6, 6, 7).unwrap();
        assert_eq!(
            (
                c.interior_cells,
                c.variables,
                c.interior_block_faces,
                c.f_int
            ),
            (36, 240, 141, 313)
        );
        // A.4: freeing the two 6 × 7 faces (M = 4, N = 5 largest pair) adds 6·20 = 120 → 360
        assert_eq!(c.margin_a4, 360 - 313);
        // A.3 with sizes (M, N, P) ordered (5, 4, 4): Bloq = 2MN − M − N = 31 for the two
        // largest pairs and 24 for the last. The thesis removes 31, 31 and 24, leaving 227
        // constraints: margin 240 − 227 = 13, the second A.3 margin; removing 31, 31, 31
        // instead leaves 313 − 93 = 220, margin 20, the first.
        assert_eq!(c.blocks, (24, 31, 31));
        assert_eq!(c.margin_a3, (240 - 220, 240 - 227));
        assert!(planarity_counts(3, 5, 5).is_err());
    }
}
