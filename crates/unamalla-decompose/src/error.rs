//! The error type of the decomposition stage.

/// Why a decomposition could not be computed, loaded or validated. Every variant names the
/// offending block, cut, ring or vertex.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DecomposeError {
    /// No admissible pair of cuts removes this hole of a piece (hole numbers are region hole
    /// numbers, 0-based).
    #[error("hole {hole}: no admissible pair of cuts joins it to the rest of the boundary")]
    HoleNotRemoved {
        /// The hole.
        hole: usize,
    },
    /// The chord layout could not be built (the triangulation of the boundary samples failed
    /// or the rings are not connected by admissible chords).
    #[error("chord layout: {0}")]
    Layout(String),
    /// The decomposition file is not valid JSON or does not have the documented shape.
    #[error("decomposition file, line {line}, column {column}: {message}")]
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What serde_json reported.
        message: String,
    },
    /// The file's `format`/`version` header is not one this library reads.
    #[error("decomposition file: {0}")]
    Format(String),
    /// A coordinate in the file is NaN or infinite.
    #[error("{what}: non-finite coordinate")]
    NonFinite {
        /// Where (e.g. "block 3, ring point 7").
        what: String,
    },
    /// Ids must be exactly 0..n−1 without repetition.
    #[error("{what} ids must be 0..{count} without repetition; found id {id}")]
    BadId {
        /// "block" or "cut".
        what: &'static str,
        /// The offending id.
        id: usize,
        /// How many items there are.
        count: usize,
    },
    /// A cut endpoint given as a boundary vertex reference is out of range.
    #[error("cut {cut}: endpoint refers to vertex {vertex} of ring {ring}, which does not exist")]
    VertexOutOfRange {
        /// The cut.
        cut: usize,
        /// Ring number (0 = outer, k = hole k−1).
        ring: usize,
        /// The vertex.
        vertex: usize,
    },
    /// A cut endpoint is not on the region boundary.
    #[error("cut {cut}: endpoint {endpoint} ({x}, {y}) is not on the region boundary")]
    CutEndNotOnBoundary {
        /// The cut.
        cut: usize,
        /// `'a'` or `'b'`.
        endpoint: char,
        /// x.
        x: f64,
        /// y.
        y: f64,
    },
    /// A cut leaves the region or crosses its boundary.
    #[error("cut {cut}: the segment ({ax}, {ay})–({bx}, {by}) does not lie inside the region (it crosses or touches the boundary)")]
    CutCrossesBoundary {
        /// The cut.
        cut: usize,
        /// a.x
        ax: f64,
        /// a.y
        ay: f64,
        /// b.x
        bx: f64,
        /// b.y
        by: f64,
    },
    /// Two cuts cross, overlap or one ends inside the other.
    #[error("cuts {cut_a} and {cut_b} intersect (cuts may share endpoints only)")]
    CutsIntersect {
        /// First cut.
        cut_a: usize,
        /// Second cut.
        cut_b: usize,
    },
    /// After applying the cuts of a file, a piece still has a hole (a hole needs two cuts).
    #[error("hole {hole} is not separated by the given cuts (every hole needs at least two cuts)")]
    HoleNotSeparated {
        /// The hole (0-based).
        hole: usize,
    },
    /// A block ring has fewer than three points.
    #[error("block {block}: ring has {count} point(s), at least 3 are needed")]
    BlockTooSmall {
        /// The block.
        block: usize,
        /// Number of points.
        count: usize,
    },
    /// A block ring is clockwise or has zero area.
    #[error("block {block}: ring is not counter-clockwise (signed area {area})")]
    BlockNotCounterClockwise {
        /// The block.
        block: usize,
        /// Its signed area.
        area: f64,
    },
    /// A block ring intersects itself.
    #[error("block {block}: ring is not simple (edges {edge_a} and {edge_b} intersect)")]
    BlockNotSimple {
        /// The block.
        block: usize,
        /// First edge.
        edge_a: usize,
        /// Second edge.
        edge_b: usize,
    },
    /// A block edge is neither a listed cut nor part of the region boundary.
    #[error("block {block}, edge {edge} ({ax}, {ay})–({bx}, {by}): neither a cut nor a piece of the region boundary")]
    BlockEdgeUnexplained {
        /// The block.
        block: usize,
        /// Edge index (`ring[edge] → ring[edge+1]`).
        edge: usize,
        /// a.x
        ax: f64,
        /// a.y
        ay: f64,
        /// b.x
        bx: f64,
        /// b.y
        by: f64,
    },
    /// A cut is not an edge of exactly two blocks (in opposite directions).
    #[error("cut {cut}: it must be an edge of exactly two blocks in opposite directions, found {count} use(s)")]
    CutNotShared {
        /// The cut.
        cut: usize,
        /// How many block edges use it.
        count: usize,
    },
    /// The blocks a cut separates differ from the ones the file lists.
    #[error("cut {cut}: file says it separates blocks {listed:?}, the rings say {found:?}")]
    CutBlocksMismatch {
        /// The cut.
        cut: usize,
        /// Listed in the file.
        listed: [usize; 2],
        /// Found from the rings.
        found: [usize; 2],
    },
    /// The blocks do not cover a piece of the region boundary exactly once.
    #[error("ring {ring} (0 = outer, k = hole k−1), edge {edge}: not covered exactly once by block edges")]
    BoundaryNotCovered {
        /// Ring number.
        ring: usize,
        /// Edge of that ring.
        edge: usize,
    },
    /// The block areas do not add up to the region's area.
    #[error("block areas sum to {blocks}, the region's area is {region}")]
    AreaMismatch {
        /// Sum of block areas.
        blocks: f64,
        /// Region area.
        region: f64,
    },
    /// A block's corners are invalid.
    #[error("block {block}: invalid corners: {reason}")]
    BadCorners {
        /// The block.
        block: usize,
        /// Why.
        reason: String,
    },
    /// A block id referenced by a cut does not exist.
    #[error("cut {cut}: unknown block {block}")]
    UnknownBlock {
        /// The cut.
        cut: usize,
        /// The missing block id.
        block: usize,
    },
}
