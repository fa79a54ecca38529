//! Automatic corner choice for a roughly four-sided ring ([Méndez 2023, §5.1.1]).
//!
//! The choice itself is the decomposition stage's corner selection
//! ([`unamalla_decompose::select_corners`]: four non-reflex, non-flat vertices with balanced
//! opposite sides — one implementation for blocks and for single-block TFI). This module only
//! adds the orientation: which pair of opposite sides becomes bottom/top, so that the grid's
//! aspect `(M−1)/(N−1)` matches the region's.

use unamalla_decompose::{select_corners, CornerWeights};
use unamalla_mesh::Polygon;

use crate::CoreError;

/// Why four block corners could not be chosen, or the given ones are not valid.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CornersError {
    /// No four vertices pass the admissibility filter (convex, not flat, balanced sides).
    #[error("no four admissible corners (convex, not flat, balanced sides) among the {vertices} vertices")]
    NoAdmissibleQuadruple {
        /// Vertices of the polygon.
        vertices: usize,
    },
    /// A given corner index is not a vertex of the outer ring.
    #[error("corner index {index} is not a vertex of the outer ring as given (the ring has {vertices} vertices after cleaning)")]
    NotAVertex {
        /// The index given.
        index: usize,
        /// Vertices of the ring after cleaning.
        vertices: usize,
    },
    /// The given corners are not four distinct vertices.
    #[error("corners {corners:?} are not four distinct vertices")]
    NotDistinct {
        /// The indices given.
        corners: [usize; 4],
    },
}

/// Chooses four corners of `poly` (indices into its points, counter-clockwise order). When
/// `aspect` (the wanted ratio bottom-side length / left-side length, e.g. `(M−1)/(N−1)` for an
/// `M × N` grid) is given, the quadruple is rotated so that the bottom/top pair best matches it.
///
/// Errors: no admissible quadruple (e.g. fewer than four convex, non-flat vertices).
pub fn auto_corners(poly: &Polygon, aspect: Option<f64>) -> Result<[usize; 4], CoreError> {
    let n = poly.len();
    let (mut q, _) = select_corners(poly.points(), &CornerWeights::default()).ok_or(
        CoreError::Corners(CornersError::NoAdmissibleQuadruple { vertices: n }),
    )?;
    if let Some(aspect) = aspect.filter(|a| a.is_finite() && *a > 0.0) {
        let pts = poly.points();
        let arc = |a: usize, b: usize| {
            let mut s = 0.0;
            let mut k = a;
            while k != b {
                let k2 = (k + 1) % n;
                s += pts[k].distance(pts[k2]);
                k = k2;
            }
            s
        };
        let l: Vec<f64> = (0..4).map(|s| arc(q[s], q[(s + 1) % 4])).collect();
        let ratio0 = (l[0] + l[2]) / (l[1] + l[3]);
        // rotating by one swaps the roles of the two side pairs
        if (ratio0.ln() - aspect.ln()).abs() > ((1.0 / ratio0).ln() - aspect.ln()).abs() {
            q.rotate_left(1);
        }
    }
    Ok(q)
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::DVec2;

    use super::*;

    #[test]
    fn rectangle_with_extra_points_gets_its_four_corners() {
        // 6 × 2 rectangle with collinear points on every side; starting vertex mid-side
        let pts = vec![
            DVec2::new(3., 0.),
            DVec2::new(6., 0.),
            DVec2::new(6., 1.),
            DVec2::new(6., 2.),
            DVec2::new(2., 2.),
            DVec2::new(0., 2.),
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
        ];
        let poly = Polygon::new(pts).unwrap();
        let mut q = auto_corners(&poly, None).unwrap();
        q.sort_unstable();
        assert_eq!(q, [1, 3, 5, 6]);
        // aspect 3: the long sides (length 6) must be bottom/top
        let q = auto_corners(&poly, Some(3.0)).unwrap();
        let p = poly.points();
        assert_eq!((p[q[1]] - p[q[0]]).length(), 6.0);
        // aspect 1/3: the long sides become left/right
        let q = auto_corners(&poly, Some(1.0 / 3.0)).unwrap();
        assert_eq!((p[q[1]] - p[q[0]]).length(), 2.0);
    }

    #[test]
    fn triangle_has_no_four_corners() {
        let poly = Polygon::new(vec![DVec2::ZERO, DVec2::X, DVec2::Y]).unwrap();
        assert!(matches!(
            auto_corners(&poly, None),
            Err(CoreError::Corners(_))
        ));
    }

    #[test]
    fn reflex_vertex_is_never_a_corner() {
        // an L-shape: its reflex vertex (2) must not be chosen
        let poly = Polygon::new(vec![
            DVec2::new(0., 0.),
            DVec2::new(4., 0.),
            DVec2::new(4., 1.),
            DVec2::new(1., 1.),
            DVec2::new(1., 4.),
            DVec2::new(0., 4.),
        ])
        .unwrap();
        let q = auto_corners(&poly, None).unwrap();
        assert!(!q.contains(&3));
        for &c in &q {
            assert!(!poly.is_reflex(c));
        }
    }
}
