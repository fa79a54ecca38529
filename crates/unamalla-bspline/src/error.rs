//! The error type of `unamalla-bspline`.

use thiserror::Error;

/// Everything that can go wrong with user input to this crate. Each variant names the offending
/// item (which knot, which boundary curve, which corner, which option).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum BsplineError {
    /// The order (degree + 1) is outside the supported range.
    #[error("order {order} is not supported here ({reason})")]
    Order {
        /// The requested order.
        order: usize,
        /// Which orders are allowed.
        reason: &'static str,
    },
    /// A knot vector is invalid.
    #[error("knot vector: {0}")]
    Knots(String),
    /// Too few control points for the order, or counts that do not match.
    #[error("{what}: {got} control point(s), need {need}")]
    Count {
        /// Which list (e.g. "south curve", "control net along ξ").
        what: &'static str,
        /// How many were given.
        got: usize,
        /// How many are needed.
        need: String,
    },
    /// A coordinate is NaN or infinite.
    #[error("{what}: control point {index} is not finite")]
    NonFinite {
        /// Which list.
        what: &'static str,
        /// The point index (0-based).
        index: usize,
    },
    /// Two boundary curves do not meet at a corner.
    #[error("corner {corner}: the {a} and {b} curves do not meet (distance {distance:e})")]
    CornerMismatch {
        /// `Q`, `R`, `S` or `T` ([Abelló et al., §2.1]).
        corner: char,
        /// First curve.
        a: &'static str,
        /// Second curve.
        b: &'static str,
        /// Distance between their end control points.
        distance: f64,
    },
    /// The boundary control polygon Q→R→S→T is clockwise.
    #[error("the boundary control polygon Q→R→S→T is clockwise (signed area {signed_area:e}); reverse it or swap the east and west curves")]
    Clockwise {
        /// Its signed area (negative).
        signed_area: f64,
    },
    /// The boundary control polygon is not simple.
    #[error("the boundary control polygon is not simple: {0}")]
    NotSimple(String),
    /// A corner is not a strictly convex vertex of the boundary control polygon, so no convex
    /// control net exists (a corner belongs to a single cell of the net).
    #[error("corner {corner} is not a strictly convex vertex of the boundary control polygon (turn {turn:e}); no convex control net exists")]
    ReflexCorner {
        /// `Q`, `R`, `S` or `T`.
        corner: char,
        /// `cross(incoming, outgoing)` at the corner (≤ 0).
        turn: f64,
    },
    /// An option is out of range.
    #[error("option {name} = {value}: {reason}")]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        reason: &'static str,
    },
    /// A least-squares boundary fit is not well posed (too few samples, degenerate polyline).
    #[error("boundary fit: {0}")]
    Fit(String),
    /// The interior optimization failed on its input.
    #[error("interior control points: {0}")]
    Optimization(String),
    /// A mesh operation (TFI, grid construction) failed.
    #[error(transparent)]
    Mesh(#[from] unamalla_mesh::MeshError),
}
