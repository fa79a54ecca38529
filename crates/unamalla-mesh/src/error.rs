//! Error types of `unamalla-mesh`.

use std::fmt;

/// Which ring of a region an error refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum RingId {
    /// The outer boundary.
    Outer,
    /// Hole number `k` (0-based, in input order).
    Hole(usize),
}

impl fmt::Display for RingId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RingId::Outer => write!(f, "outer ring"),
            RingId::Hole(k) => write!(f, "hole {k}"),
        }
    }
}

/// Why a polygon or region was rejected. Vertex and edge indices refer to the ring **as given**
/// (before any orientation normalisation; edge `e` joins vertex `e` and vertex `e + 1`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// A ring needs at least three distinct points.
    #[error("{ring}: {count} distinct point(s), a ring needs at least 3")]
    TooFewPoints {
        /// The ring.
        ring: RingId,
        /// How many distinct points it had.
        count: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("{ring}, vertex {vertex}: non-finite coordinate ({x}, {y})")]
    NonFinite {
        /// The ring.
        ring: RingId,
        /// The vertex.
        vertex: usize,
        /// Its x coordinate.
        x: f64,
        /// Its y coordinate.
        y: f64,
    },
    /// A coordinate is finite but outside the range the exact predicates handle: non-zero
    /// magnitudes must lie in [`MIN_COORDINATE`](crate::region::MIN_COORDINATE) ..=
    /// [`MAX_COORDINATE`](crate::region::MAX_COORDINATE) (products of coordinate differences
    /// must neither overflow nor underflow).
    #[error("{ring}, vertex {vertex}: coordinate ({x:e}, {y:e}) is out of range; non-zero coordinates must have magnitudes between 1e-100 and 1e150")]
    CoordinateOutOfRange {
        /// The ring.
        ring: RingId,
        /// The vertex.
        vertex: usize,
        /// Its x coordinate.
        x: f64,
        /// Its y coordinate.
        y: f64,
    },
    /// Two consecutive points coincide (use the cleaning constructor to drop them).
    #[error("{ring}, vertex {vertex}: repeats the previous point; use Region::new_cleaned to remove repeated points")]
    RepeatedPoint {
        /// The ring.
        ring: RingId,
        /// The repeated vertex.
        vertex: usize,
    },
    /// The ring encloses zero area (all points collinear).
    #[error("{ring}: zero area (all points collinear)")]
    ZeroArea {
        /// The ring.
        ring: RingId,
    },
    /// Two edges of the same ring intersect or touch (or two consecutive edges fold back).
    #[error("{ring}: edge {edge_a} (from vertex {edge_a}) and edge {edge_b} (from vertex {edge_b}) intersect; the ring is not simple")]
    SelfIntersection {
        /// The ring.
        ring: RingId,
        /// First edge (index of its start vertex).
        edge_a: usize,
        /// Second edge.
        edge_b: usize,
    },
    /// Edges of two different rings intersect or touch.
    #[error("{ring_a} edge {edge_a} and {ring_b} edge {edge_b} intersect or touch; rings must be disjoint")]
    RingsIntersect {
        /// First ring.
        ring_a: RingId,
        /// Its edge.
        edge_a: usize,
        /// Second ring.
        ring_b: RingId,
        /// Its edge.
        edge_b: usize,
    },
    /// A hole lies outside the outer ring.
    #[error("hole {hole} lies outside the outer ring")]
    HoleOutside {
        /// The hole.
        hole: usize,
    },
    /// A hole lies inside another hole.
    #[error("hole {inner} lies inside hole {outer}; nested holes are not allowed")]
    NestedHole {
        /// The enclosing hole.
        outer: usize,
        /// The enclosed hole.
        inner: usize,
    },
}

/// Errors of mesh construction and mesh operations.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// A size is too small or inconsistent.
    #[error("invalid size: {0}")]
    InvalidSize(String),
    /// A cell references a node that does not exist.
    #[error("cell {cell} references node {node}, but the mesh has {num_nodes} nodes")]
    NodeOutOfRange {
        /// The cell.
        cell: usize,
        /// The bad node id.
        node: usize,
        /// Number of nodes.
        num_nodes: usize,
    },
    /// Boundary curves given to TFI do not meet at the corners.
    #[error("TFI boundary curves do not meet at the {corner} corner (distance {distance:e})")]
    CornerMismatch {
        /// Which corner (e.g. "bottom-left").
        corner: &'static str,
        /// How far apart the two curve ends are.
        distance: f64,
    },
    /// Opposite boundary curves have different point counts.
    #[error("opposite {which} sides have {a} and {b} points; they must match")]
    SideCountMismatch {
        /// Which pair of sides.
        which: &'static str,
        /// Count on the first side.
        a: usize,
        /// Count on the second side.
        b: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate")]
    NonFinite {
        /// The node.
        node: usize,
    },
    /// A polyline is degenerate (zero length) where a length is needed.
    #[error("degenerate polyline: {0}")]
    Degenerate(String),
}
