//! Error type of the crate and the infeasibility report.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::problem::Side;

/// Errors returned by this crate. Every variant that comes from user input names the offending block,
/// side, curve or cut by the **ids** the user gave them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CompatError {
    /// The problem has no block.
    #[error("the decomposition has no block")]
    NoBlocks,
    /// A curve length is not finite or not strictly positive.
    #[error("curve {curve}: length {length} is not a finite positive number")]
    InvalidLength {
        /// Id of the curve.
        curve: usize,
        /// The offending length.
        length: f64,
    },
    /// Two curves share the same id.
    #[error("curve id {id} is used by more than one curve")]
    DuplicateCurveId {
        /// The repeated id.
        id: usize,
    },
    /// Two blocks share the same id.
    #[error("block id {id} is used by more than one block")]
    DuplicateBlockId {
        /// The repeated id.
        id: usize,
    },
    /// A block side has no curve.
    #[error("block {block}: {side} side has no curve")]
    EmptySide {
        /// Id of the block.
        block: usize,
        /// The empty side.
        side: Side,
    },
    /// A block side references a curve index that does not exist.
    #[error("block {block}: {side} side references curve index {index}, but there are only {num_curves} curves")]
    CurveIndexOutOfRange {
        /// Id of the block.
        block: usize,
        /// The side holding the bad reference.
        side: Side,
        /// The bad index.
        index: usize,
        /// Number of curves in the problem.
        num_curves: usize,
    },
    /// A curve is used by two block sides (or twice by the same side).
    #[error("curve {curve} is used twice: by block {first_block} ({first_side}) and by block {second_block} ({second_side})")]
    CurveUsedTwice {
        /// Id of the curve.
        curve: usize,
        /// Id of the first block using it.
        first_block: usize,
        /// Side of the first use.
        first_side: Side,
        /// Id of the second block using it.
        second_block: usize,
        /// Side of the second use.
        second_side: Side,
    },
    /// A curve is not used by any block side.
    #[error("curve {curve} does not lie on any block side")]
    CurveUnused {
        /// Id of the curve.
        curve: usize,
    },
    /// A cut pair references a curve index that does not exist.
    #[error("cut {cut}: curve index {index} does not exist (there are {num_curves} curves)")]
    CutCurveOutOfRange {
        /// Position of the cut in the cut list (1-based, like the thesis' i).
        cut: usize,
        /// The bad index.
        index: usize,
        /// Number of curves in the problem.
        num_curves: usize,
    },
    /// A cut pairs a curve with itself.
    #[error("cut {cut}: both copies are curve {curve}")]
    CutSelfPair {
        /// Position of the cut (1-based).
        cut: usize,
        /// Id of the curve.
        curve: usize,
    },
    /// A curve is a copy in two different cut pairs.
    #[error("curve {curve} belongs to cut {first_cut} and to cut {second_cut}; a cut copy belongs to one cut only")]
    CurveInTwoCuts {
        /// Id of the curve.
        curve: usize,
        /// First cut (1-based).
        first_cut: usize,
        /// Second cut (1-based).
        second_cut: usize,
    },
    /// A pinned count is smaller than 2 (a curve has two end points).
    #[error("curve {curve}: pinned count {count} is below 2 (a curve has two end points)")]
    PinnedTooSmall {
        /// Id of the curve.
        curve: usize,
        /// The pinned count.
        count: usize,
    },
    /// A count or lower bound is too large for the solvers (limit [`crate::MAX_COUNT`]).
    #[error("curve {curve}: count bound {value} exceeds the supported maximum {max}")]
    CountTooLarge {
        /// Id of the curve.
        curve: usize,
        /// The value that is too large.
        value: f64,
        /// The limit.
        max: usize,
    },
    /// A solver parameter (density, cell size, weight, angle ...) is invalid.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// A count vector has the wrong length or a block index is out of range.
    #[error("dimension mismatch: {0}")]
    DimensionMismatch(String),
    /// The integer program has no solution. The report names a small set of conflicting constraints.
    #[error("{0}")]
    Infeasible(InfeasibilityReport),
    /// Interval assignment (3) or vertex classification (6)/(8) has no solution.
    #[error("{program} has no solution: {reason}")]
    ProgramInfeasible {
        /// Which program (e.g. "interval assignment (3)").
        program: &'static str,
        /// Human-readable reason naming the conflicting edges or vertices.
        reason: String,
    },
    /// No solver path produced a solution that passed the independent verification.
    #[error("no solver path produced a verified solution: {}", .attempts.join("; "))]
    SolverFailed {
        /// What was tried and why each attempt was rejected.
        attempts: Vec<String>,
    },
}

/// One constraint group of the compatibility program (5.10) that takes part in a conflict.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum ConflictItem {
    /// Equation (5.2) or (5.3) of one block: `Σ m(first side) − Σ m(second side) = rhs`.
    SideEquation {
        /// Id of the block.
        block: usize,
        /// Bottom (for the b/t equation) or Right (for the r/l equation).
        first_side: Side,
        /// Top or Left.
        second_side: Side,
        /// Curve ids on the first side.
        first_curves: Vec<usize>,
        /// Curve ids on the second side.
        second_curves: Vec<usize>,
        /// Right-hand side `s_first − s_second`.
        rhs: i64,
    },
    /// Cut equation (5.1): the two copies of a cut have equal counts.
    CutEquation {
        /// Position of the cut (1-based).
        cut: usize,
        /// Curve id of the copy ι.
        first_curve: usize,
        /// Curve id of the copy ς.
        second_curve: usize,
        /// Block and side holding ι.
        first_place: (usize, Side),
        /// Block and side holding ς.
        second_place: (usize, Side),
    },
    /// A user-pinned count `m_j = count`.
    Pin {
        /// Curve id.
        curve: usize,
        /// Pinned count.
        count: usize,
    },
}

impl fmt::Display for ConflictItem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fn list(ids: &[usize]) -> String {
            ids.iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        }
        match self {
            ConflictItem::SideEquation {
                block,
                first_side,
                second_side,
                first_curves,
                second_curves,
                rhs,
            } => write!(
                f,
                "block {block}: {first_side} (curves {}) vs {second_side} (curves {}) must satisfy Σm({first_side}) − Σm({second_side}) = {rhs}",
                list(first_curves),
                list(second_curves)
            ),
            ConflictItem::CutEquation {
                cut,
                first_curve,
                second_curve,
                first_place,
                second_place,
            } => write!(
                f,
                "cut {cut}: copies m{first_curve} (block {} {}) and m{second_curve} (block {} {}) must be equal",
                first_place.0, first_place.1, second_place.0, second_place.1
            ),
            ConflictItem::Pin { curve, count } => write!(f, "pinned count m{curve} = {count}"),
        }
    }
}

/// The lower bound of a curve that takes part in a conflict.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BoundInfo {
    /// Curve id.
    pub curve: usize,
    /// Lower bound `m_j ≥ bound` in force (from density, cell size, or 2).
    pub bound: usize,
}

/// Why problem (5.10) has no integer solution: a small set of constraint groups that is infeasible on its own
/// (together with the always-present lower bounds), found by a deletion filter.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InfeasibilityReport {
    /// The conflicting groups.
    pub conflict: Vec<ConflictItem>,
    /// Lower bounds of the curves that appear in the conflicting groups.
    pub bounds: Vec<BoundInfo>,
    /// `true` when every group was tested by the deletion filter, so removing any single group of
    /// `conflict` makes the rest feasible (an irreducible infeasible subset).
    pub irreducible: bool,
}

impl fmt::Display for InfeasibilityReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the compatibility equations have no integer solution with the requested bounds; conflicting constraints: "
        )?;
        for (i, item) in self.conflict.iter().enumerate() {
            if i > 0 {
                write!(f, "; ")?;
            }
            write!(f, "{item}")?;
        }
        if !self.bounds.is_empty() {
            write!(f, "; with lower bounds ")?;
            for (i, b) in self.bounds.iter().enumerate() {
                if i > 0 {
                    write!(f, ", ")?;
                }
                write!(f, "m{} ≥ {}", b.curve, b.bound)?;
            }
        }
        if !self.irreducible {
            write!(f, " (conflict set not minimised)")?;
        }
        Ok(())
    }
}
