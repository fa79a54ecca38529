//! The compatibility system `A m = b` ([Méndez 2023, §5.2.1, (5.1)–(5.4)]) and the block sizes
//! (5.5)/(5.6).

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::error::CompatError;
use crate::problem::{CompatProblem, Side};

/// What a row of `A m = b` expresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum EquationKind {
    /// Row `2k−1` (5.2): bottom vs top of the block with position `block` (0-based) in `blocks`.
    BottomTop {
        /// 0-based block position.
        block: usize,
    },
    /// Row `2k` (5.3): right vs left of the block with position `block`.
    RightLeft {
        /// 0-based block position.
        block: usize,
    },
    /// Row `2n+i` (5.1): the two copies of cut `cut` (0-based position in `cuts`).
    Cut {
        /// 0-based cut position.
        cut: usize,
    },
}

/// One row of `A m = b`: sparse coefficients on curve indices and the right-hand side.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Equation {
    /// What the row expresses.
    pub kind: EquationKind,
    /// `(curve index, coefficient)` pairs, coefficients ±1, in side order.
    pub terms: Vec<(usize, i64)>,
    /// Right-hand side `b_row`.
    pub rhs: i64,
}

impl Equation {
    /// `Σ a_j m_j − b` for integer counts; `None` if a term's curve index is outside `counts`.
    pub fn residual(&self, counts: &[usize]) -> Option<i128> {
        let mut s = -(self.rhs as i128);
        for &(j, a) in &self.terms {
            s += a as i128 * *counts.get(j)? as i128;
        }
        Some(s)
    }
}

/// The assembled system `A m = b`, `A ∈ Z^{(2n+q)×p}`, rows ordered as in (5.4): for each block its b/t row
/// then its r/l row, then one row per cut.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompatSystem {
    /// The rows.
    pub equations: Vec<Equation>,
    /// Number of columns `p` (curves).
    pub num_curves: usize,
    /// Curve ids, used to print `m{id}`.
    pub curve_ids: Vec<usize>,
    /// Block ids, used to print row labels.
    pub block_ids: Vec<usize>,
}

impl CompatSystem {
    /// Assemble `A m = b` from a validated decomposition:
    /// `a_{2k−1,j} = +1 (j ∈ J_{k,b}), −1 (j ∈ J_{k,t})`, `b_{2k−1} = s_{k,b} − s_{k,t}`;
    /// `a_{2k,j} = +1 (j ∈ J_{k,r}), −1 (j ∈ J_{k,l})`, `b_{2k} = s_{k,r} − s_{k,l}`;
    /// `a_{2n+i,ι_i} = +1`, `a_{2n+i,ς_i} = −1`, `b_{2n+i} = 0`.
    pub fn assemble(problem: &CompatProblem) -> Result<Self, CompatError> {
        problem.validate()?;
        let mut equations = Vec::with_capacity(2 * problem.blocks.len() + problem.cuts.len());
        for (k, block) in problem.blocks.iter().enumerate() {
            for (kind, plus, minus) in [
                (
                    EquationKind::BottomTop { block: k },
                    Side::Bottom,
                    Side::Top,
                ),
                (
                    EquationKind::RightLeft { block: k },
                    Side::Right,
                    Side::Left,
                ),
            ] {
                let mut terms: Vec<(usize, i64)> =
                    block.side(plus).iter().map(|&j| (j, 1)).collect();
                terms.extend(block.side(minus).iter().map(|&j| (j, -1)));
                equations.push(Equation {
                    kind,
                    terms,
                    rhs: block.count(plus) as i64 - block.count(minus) as i64,
                });
            }
        }
        for (i, cut) in problem.cuts.iter().enumerate() {
            equations.push(Equation {
                kind: EquationKind::Cut { cut: i },
                terms: vec![(cut.first, 1), (cut.second, -1)],
                rhs: 0,
            });
        }
        Ok(CompatSystem {
            equations,
            num_curves: problem.curves.len(),
            curve_ids: problem.curves.iter().map(|c| c.id).collect(),
            block_ids: problem.blocks.iter().map(|b| b.id).collect(),
        })
    }

    /// Dense `A` (row-major).
    pub fn matrix(&self) -> Vec<Vec<i64>> {
        self.equations
            .iter()
            .map(|e| {
                let mut row = vec![0i64; self.num_curves];
                for &(j, a) in &e.terms {
                    if let Some(x) = row.get_mut(j) {
                        *x += a;
                    }
                }
                row
            })
            .collect()
    }

    /// The right-hand side `b`.
    pub fn rhs(&self) -> Vec<i64> {
        self.equations.iter().map(|e| e.rhs).collect()
    }

    /// `A m − b` for integer counts (length checked).
    pub fn residuals(&self, counts: &[usize]) -> Result<Vec<i128>, CompatError> {
        if counts.len() != self.num_curves {
            return Err(CompatError::DimensionMismatch(format!(
                "{} counts for {} curves",
                counts.len(),
                self.num_curves
            )));
        }
        self.equations
            .iter()
            .map(|e| {
                e.residual(counts).ok_or_else(|| {
                    CompatError::DimensionMismatch("an equation references a missing curve".into())
                })
            })
            .collect()
    }

    /// Whether integer counts satisfy every equation.
    pub fn is_satisfied(&self, counts: &[usize]) -> bool {
        self.residuals(counts)
            .map(|r| r.iter().all(|&x| x == 0))
            .unwrap_or(false)
    }

    /// Human-readable label of a row, e.g. `Ω2,b vs Ω2,t` or `cut 1`.
    pub fn row_label(&self, row: usize) -> String {
        let block_id = |k: usize| self.block_ids.get(k).copied().unwrap_or(k + 1);
        match self.equations.get(row).map(|e| e.kind) {
            Some(EquationKind::BottomTop { block }) => {
                let id = block_id(block);
                format!("Ω{id},b vs Ω{id},t")
            }
            Some(EquationKind::RightLeft { block }) => {
                let id = block_id(block);
                format!("Ω{id},r vs Ω{id},l")
            }
            Some(EquationKind::Cut { cut }) => format!("cut {}", cut + 1),
            None => String::new(),
        }
    }

    /// A row written like the thesis, e.g. `m6 + m7 + m8 − m10 − m11 − m12 = 0`.
    pub fn format_equation(&self, row: usize) -> String {
        let Some(e) = self.equations.get(row) else {
            return String::new();
        };
        let mut s = String::new();
        for (t, &(j, a)) in e.terms.iter().enumerate() {
            let id = self.curve_ids.get(j).copied().unwrap_or(j + 1);
            let mag = a.unsigned_abs();
            let coef = if mag == 1 {
                String::new()
            } else {
                mag.to_string()
            };
            if t == 0 {
                if a < 0 {
                    s.push('−');
                }
            } else {
                s.push_str(if a < 0 { " − " } else { " + " });
            }
            s.push_str(&format!("{coef}m{id}"));
        }
        if e.rhs < 0 {
            s.push_str(&format!(" = −{}", e.rhs.unsigned_abs()));
        } else {
            s.push_str(&format!(" = {}", e.rhs));
        }
        s
    }
}

impl fmt::Display for CompatSystem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for row in 0..self.equations.len() {
            writeln!(
                f,
                "{:<36} {}",
                self.format_equation(row),
                self.row_label(row)
            )?;
        }
        Ok(())
    }
}

/// Size `M_k × N_k` of one block's structured grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct BlockSize {
    /// Block id.
    pub block: usize,
    /// `M_k` (5.5): points on the bottom (= top) side.
    pub m: usize,
    /// `N_k` (5.6): points on the right (= left) side.
    pub n: usize,
}

/// Block sizes (5.5)/(5.6): `M_k = Σ_{j∈J_{k,b}} m_j − s_{k,b} + 1`, `N_k = Σ_{j∈J_{k,r}} m_j − s_{k,r} + 1`
/// (shared junction points counted once).
pub fn block_sizes(
    problem: &CompatProblem,
    counts: &[usize],
) -> Result<Vec<BlockSize>, CompatError> {
    if counts.len() != problem.curves.len() {
        return Err(CompatError::DimensionMismatch(format!(
            "{} counts for {} curves",
            counts.len(),
            problem.curves.len()
        )));
    }
    let side_points = |list: &[usize]| -> Result<usize, CompatError> {
        let mut total = 1usize;
        for &j in list {
            let m = *counts.get(j).ok_or_else(|| {
                CompatError::DimensionMismatch(format!("curve index {j} out of range"))
            })?;
            if m == 0 {
                return Err(CompatError::DimensionMismatch(format!(
                    "curve {} has count 0",
                    problem.curves[j].id
                )));
            }
            total += m - 1;
        }
        Ok(total)
    };
    problem
        .blocks
        .iter()
        .map(|b| {
            Ok(BlockSize {
                block: b.id,
                m: side_points(b.side(Side::Bottom))?,
                n: side_points(b.side(Side::Right))?,
            })
        })
        .collect()
}
