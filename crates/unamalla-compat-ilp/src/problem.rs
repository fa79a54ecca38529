//! Input description of a decomposition: curves `Q_j`, blocks with four sides, cut pairs
//! ([Méndez 2023, §5.1, §5.2.1]).

use std::collections::HashMap;
use std::fmt;

use serde::{Deserialize, Serialize};

use crate::error::CompatError;

/// Largest point count (and lower bound) accepted on a curve. Keeps every value exactly representable
/// in the solvers' `f64`/`i32` arithmetic.
pub const MAX_COUNT: usize = 1 << 30;

/// One side of a block, in the thesis order bottom, right, top, left (counter-clockwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Side {
    /// Bottom side `Ω_{k,b}`.
    Bottom,
    /// Right side `Ω_{k,r}`.
    Right,
    /// Top side `Ω_{k,t}`.
    Top,
    /// Left side `Ω_{k,l}`.
    Left,
}

impl Side {
    /// The four sides in the order b, r, t, l used for `Block::sides`.
    pub const ALL: [Side; 4] = [Side::Bottom, Side::Right, Side::Top, Side::Left];

    /// Position of the side in `Block::sides` (0 = bottom … 3 = left).
    pub fn index(self) -> usize {
        match self {
            Side::Bottom => 0,
            Side::Right => 1,
            Side::Top => 2,
            Side::Left => 3,
        }
    }

    /// The opposite side (bottom ↔ top, right ↔ left).
    pub fn opposite(self) -> Side {
        match self {
            Side::Bottom => Side::Top,
            Side::Right => Side::Left,
            Side::Top => Side::Bottom,
            Side::Left => Side::Right,
        }
    }

    /// One-letter abbreviation used by the thesis (`b`, `r`, `t`, `l`).
    pub fn letter(self) -> char {
        match self {
            Side::Bottom => 'b',
            Side::Right => 'r',
            Side::Top => 't',
            Side::Left => 'l',
        }
    }
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::Bottom => "bottom",
            Side::Right => "right",
            Side::Top => "top",
            Side::Left => "left",
        })
    }
}

/// A boundary curve `Q_j` of the decomposition: a piece of `∂Ω` or one copy of a cut.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    /// User-facing id, used in messages and printed equations (`m{id}`). Ids must be unique.
    pub id: usize,
    /// Length `ℓ_j` (finite, > 0).
    pub length: f64,
    /// Optional user-pinned point count: the solver enforces `m_j = pinned` (instead of the length bound).
    pub pinned: Option<usize>,
    /// Optional free-form label (e.g. "cut 1 copy in block 2").
    pub label: Option<String>,
}

impl Curve {
    /// A curve with the given id and length, no pin and no label.
    pub fn new(id: usize, length: f64) -> Self {
        Curve {
            id,
            length,
            pinned: None,
            label: None,
        }
    }

    /// Builder: pin the point count of this curve.
    pub fn with_pin(mut self, count: usize) -> Self {
        self.pinned = Some(count);
        self
    }

    /// Builder: attach a label.
    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }
}

/// A block `Ω_k` with its four sides. Each side is an ordered list of **indices** into
/// [`CompatProblem::curves`] (0-based), in the traversal order of the side.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Block {
    /// User-facing id, used in messages. Ids must be unique.
    pub id: usize,
    /// Curve indices of the sides in the order bottom, right, top, left.
    pub sides: [Vec<usize>; 4],
}

impl Block {
    /// A block from its four sides in the order bottom, right, top, left.
    pub fn new(
        id: usize,
        bottom: Vec<usize>,
        right: Vec<usize>,
        top: Vec<usize>,
        left: Vec<usize>,
    ) -> Self {
        Block {
            id,
            sides: [bottom, right, top, left],
        }
    }

    /// Curve indices of one side.
    pub fn side(&self, side: Side) -> &[usize] {
        &self.sides[side.index()]
    }

    /// Number of curves `s_{k,side}` on one side.
    pub fn count(&self, side: Side) -> usize {
        self.sides[side.index()].len()
    }
}

/// The two copies `(ι_i, ς_i)` of one cut, as indices into [`CompatProblem::curves`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct CutPair {
    /// Index of the copy `ι_i` (coefficient +1 in the cut equation).
    pub first: usize,
    /// Index of the copy `ς_i` (coefficient −1 in the cut equation).
    pub second: usize,
}

impl CutPair {
    /// A cut pair from two curve indices.
    pub fn new(first: usize, second: usize) -> Self {
        CutPair { first, second }
    }
}

/// The input of the compatibility stage: the curves `Q_1..Q_p`, the blocks `Ω_1..Ω_n` and the cuts
/// `(ι_i, ς_i)`, `i = 1..q` ([Méndez 2023, §5.2.1]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompatProblem {
    /// The curves `Q_j`.
    pub curves: Vec<Curve>,
    /// The blocks, each with four sides.
    pub blocks: Vec<Block>,
    /// The cut pairs.
    pub cuts: Vec<CutPair>,
}

/// Where a curve lies: block position (0-based index into `blocks`) and side.
pub(crate) type Place = (usize, Side);

impl CompatProblem {
    /// Bundle curves, blocks and cuts. Nothing is checked here; see [`CompatProblem::validate`].
    pub fn new(curves: Vec<Curve>, blocks: Vec<Block>, cuts: Vec<CutPair>) -> Self {
        CompatProblem {
            curves,
            blocks,
            cuts,
        }
    }

    /// Build a problem with the thesis' index-set convention `J_{k,side}` ([Méndez 2023, §5.2.1]):
    /// curves are numbered consecutively block by block and, inside a block, side by side in the order
    /// b, r, t, l. `side_counts[k] = [s_{k,b}, s_{k,r}, s_{k,t}, s_{k,l}]`; `lengths[j]` is the length of the
    /// curve with 0-based index `j` (id `j + 1`); `cuts` are pairs of 0-based curve indices. Block ids are
    /// `1..=n`, curve ids `1..=p`.
    pub fn from_index_sets(
        side_counts: &[[usize; 4]],
        lengths: &[f64],
        cuts: &[(usize, usize)],
    ) -> Result<Self, CompatError> {
        let p: usize = side_counts.iter().map(|s| s.iter().sum::<usize>()).sum();
        if p != lengths.len() {
            return Err(CompatError::DimensionMismatch(format!(
                "the side counts describe {p} curves but {} lengths were given",
                lengths.len()
            )));
        }
        let curves = lengths
            .iter()
            .enumerate()
            .map(|(j, &l)| Curve::new(j + 1, l))
            .collect();
        let mut next = 0usize;
        let blocks = side_counts
            .iter()
            .enumerate()
            .map(|(k, counts)| {
                let mut sides: [Vec<usize>; 4] = Default::default();
                for (s, &c) in counts.iter().enumerate() {
                    sides[s] = (next..next + c).collect();
                    next += c;
                }
                Block { id: k + 1, sides }
            })
            .collect();
        let cuts = cuts.iter().map(|&(a, b)| CutPair::new(a, b)).collect();
        let problem = CompatProblem::new(curves, blocks, cuts);
        problem.validate()?;
        Ok(problem)
    }

    /// Number of curves `p`.
    pub fn num_curves(&self) -> usize {
        self.curves.len()
    }

    /// Number of blocks `n`.
    pub fn num_blocks(&self) -> usize {
        self.blocks.len()
    }

    /// Check the decomposition: at least one block; every side non-empty; every curve index valid and used by
    /// exactly one block side; unique ids; lengths finite and > 0; cut pairs reference existing, distinct
    /// curves and no curve is in two cuts; pins ≥ 2 and ≤ [`MAX_COUNT`].
    pub fn validate(&self) -> Result<(), CompatError> {
        self.places().map(|_| ())
    }

    /// Validate and return, for each curve, the block position and side it lies on.
    pub(crate) fn places(&self) -> Result<Vec<Place>, CompatError> {
        if self.blocks.is_empty() {
            return Err(CompatError::NoBlocks);
        }
        let p = self.curves.len();
        let mut ids = HashMap::new();
        for c in &self.curves {
            if ids.insert(c.id, ()).is_some() {
                return Err(CompatError::DuplicateCurveId { id: c.id });
            }
            if !(c.length.is_finite() && c.length > 0.0) {
                return Err(CompatError::InvalidLength {
                    curve: c.id,
                    length: c.length,
                });
            }
            if let Some(pin) = c.pinned {
                if pin < 2 {
                    return Err(CompatError::PinnedTooSmall {
                        curve: c.id,
                        count: pin,
                    });
                }
                if pin > MAX_COUNT {
                    return Err(CompatError::CountTooLarge {
                        curve: c.id,
                        value: pin as f64,
                        max: MAX_COUNT,
                    });
                }
            }
        }
        let mut block_ids = HashMap::new();
        let mut place: Vec<Option<Place>> = vec![None; p];
        for (k, block) in self.blocks.iter().enumerate() {
            if block_ids.insert(block.id, ()).is_some() {
                return Err(CompatError::DuplicateBlockId { id: block.id });
            }
            for side in Side::ALL {
                let list = block.side(side);
                if list.is_empty() {
                    return Err(CompatError::EmptySide {
                        block: block.id,
                        side,
                    });
                }
                for &j in list {
                    if j >= p {
                        return Err(CompatError::CurveIndexOutOfRange {
                            block: block.id,
                            side,
                            index: j,
                            num_curves: p,
                        });
                    }
                    if let Some((k0, s0)) = place[j] {
                        return Err(CompatError::CurveUsedTwice {
                            curve: self.curves[j].id,
                            first_block: self.blocks[k0].id,
                            first_side: s0,
                            second_block: block.id,
                            second_side: side,
                        });
                    }
                    place[j] = Some((k, side));
                }
            }
        }
        let mut in_cut: Vec<Option<usize>> = vec![None; p];
        for (i, cut) in self.cuts.iter().enumerate() {
            for j in [cut.first, cut.second] {
                if j >= p {
                    return Err(CompatError::CutCurveOutOfRange {
                        cut: i + 1,
                        index: j,
                        num_curves: p,
                    });
                }
            }
            if cut.first == cut.second {
                return Err(CompatError::CutSelfPair {
                    cut: i + 1,
                    curve: self.curves[cut.first].id,
                });
            }
            for j in [cut.first, cut.second] {
                if let Some(i0) = in_cut[j] {
                    return Err(CompatError::CurveInTwoCuts {
                        curve: self.curves[j].id,
                        first_cut: i0 + 1,
                        second_cut: i + 1,
                    });
                }
                in_cut[j] = Some(i);
            }
        }
        place
            .into_iter()
            .enumerate()
            .map(|(j, pl)| {
                pl.ok_or(CompatError::CurveUnused {
                    curve: self.curves[j].id,
                })
            })
            .collect()
    }
}

/// How the lower bounds `m_j ≥ L_j` of problem (5.10) are derived from the curve lengths.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum LowerBounds {
    /// Density mode (eq. (5.9), with its ceiling; (5.10) prints a floor): `L_j = max(2, d·⌈ℓ_j/ℓ_min⌉)`, `d ≥ 1`.
    Density(usize),
    /// Target cell size `h > 0`: at least `⌈ℓ_j/h⌉` segments, i.e. `L_j = max(2, ⌈ℓ_j/h⌉ + 1)` points,
    /// so no cell along the curve is longer than `h`.
    CellSize(f64),
}

/// `⌈x⌉`, but values within a relative `1e-9` of an integer are taken as that integer, so that
/// `ℓ_j/ℓ_min = 3·(1 ± ε)` gives 3.
pub(crate) fn tolerant_ceil(x: f64) -> f64 {
    let r = x.round();
    if (x - r).abs() <= 1e-9 * x.abs().max(1.0) {
        r
    } else {
        x.ceil()
    }
}

impl LowerBounds {
    /// The bound `L_j` for every curve (pins are **not** applied here; a pinned curve is fixed to its pin by
    /// the solver instead). Validates the parameter and the problem.
    pub fn compute(&self, problem: &CompatProblem) -> Result<Vec<usize>, CompatError> {
        problem.validate()?;
        let raw: Vec<f64> = match *self {
            LowerBounds::Density(d) => {
                if d == 0 {
                    return Err(CompatError::InvalidParameter(
                        "the density factor d must be at least 1".into(),
                    ));
                }
                let lmin = problem
                    .curves
                    .iter()
                    .map(|c| c.length)
                    .fold(f64::INFINITY, f64::min);
                problem
                    .curves
                    .iter()
                    .map(|c| d as f64 * tolerant_ceil(c.length / lmin))
                    .collect()
            }
            LowerBounds::CellSize(h) => {
                if !(h.is_finite() && h > 0.0) {
                    return Err(CompatError::InvalidParameter(format!(
                        "the target cell size must be finite and > 0, got {h}"
                    )));
                }
                problem
                    .curves
                    .iter()
                    .map(|c| tolerant_ceil(c.length / h) + 1.0)
                    .collect()
            }
        };
        raw.iter()
            .zip(&problem.curves)
            .map(|(&v, c)| {
                if v.is_nan() || v > MAX_COUNT as f64 {
                    Err(CompatError::CountTooLarge {
                        curve: c.id,
                        value: v,
                        max: MAX_COUNT,
                    })
                } else {
                    Ok((v as usize).max(2))
                }
            })
            .collect()
    }
}
