//! One structured grid on a roughly four-sided region (no holes) by TFI.
//!
//! The outer ring is split at four corners into bottom, right, top and left sides; bottom/top
//! are resampled with `m` points and left/right with `n` points equidistant in arc length
//! ([Méndez 2023, §5.3]); the interior is filled by the discrete Coons patch (§6.1). The
//! result may fold on strongly non-convex regions — that is what the optimizers are for; the
//! quality report says so.

use unamalla_mesh::tfi::sides_from_ring;
use unamalla_mesh::{tfi2, Region, StructuredGrid2, TfiParams};

use crate::corners::{auto_corners, CornersError};
use crate::CoreError;

/// How the four corners are chosen.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Corners {
    /// Automatically ([`crate::corners::auto_corners`]), orienting the bottom side to match
    /// the grid's aspect.
    Auto,
    /// Four vertex indices into the outer ring **as given in the input** (first point 0,
    /// closing duplicate not counted). The bottom side starts at the first index and the others
    /// follow counter-clockwise.
    Input([usize; 4]),
    /// Four indices into the stored (counter-clockwise) outer ring, in counter-clockwise order.
    Stored([usize; 4]),
}

/// Resolves a corner choice into stored ring indices in counter-clockwise order.
pub fn resolve_corners(
    region: &Region,
    corners: &Corners,
    m: usize,
    n: usize,
) -> Result<[usize; 4], CoreError> {
    let len = region.outer().len();
    match corners {
        Corners::Auto => {
            let aspect = (m.max(2) - 1) as f64 / (n.max(2) - 1) as f64;
            auto_corners(region.outer(), Some(aspect))
        }
        Corners::Stored(c) => Ok(*c),
        Corners::Input(c) => {
            let mut s = [0usize; 4];
            for (k, &i) in c.iter().enumerate() {
                s[k] = region.outer_index_from_input(i).ok_or(CoreError::Corners(
                    CornersError::NotAVertex {
                        index: i,
                        vertices: len,
                    },
                ))?;
            }
            // order counter-clockwise starting at the first given corner
            let first = s[0];
            let mut rel: Vec<(usize, usize)> =
                s.iter().map(|&v| ((v + len - first) % len, v)).collect();
            rel.sort_unstable();
            rel.dedup_by_key(|r| r.0);
            if rel.len() != 4 {
                return Err(CoreError::Corners(CornersError::NotDistinct {
                    corners: *c,
                }));
            }
            Ok([rel[0].1, rel[1].1, rel[2].1, rel[3].1])
        }
    }
}

/// TFI grid of `m × n` nodes on a region without holes.
pub fn tfi_region(
    region: &Region,
    corners: Corners,
    m: usize,
    n: usize,
) -> Result<StructuredGrid2, CoreError> {
    if !region.holes().is_empty() {
        return Err(CoreError::HolesInSingleBlock {
            holes: region.holes().len(),
        });
    }
    if m < 2 || n < 2 {
        return Err(CoreError::Mesh(unamalla_mesh::MeshError::InvalidSize(
            format!("grid size must be at least 2 × 2 nodes, got {m} × {n}"),
        )));
    }
    let c = resolve_corners(region, &corners, m, n)?;
    let [b, r, t, l] = sides_from_ring(region.outer().points(), c, m, n)?;
    Ok(tfi2(&b, &r, &t, &l, TfiParams::ArcLength)?)
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::{DVec2, HasNodes};

    use super::*;

    #[test]
    fn input_corners_follow_the_file_numbering_for_a_clockwise_ring() {
        // clockwise 4 × 2 rectangle as in a file: corners are input vertices 0..4
        let ring = vec![
            DVec2::new(0., 0.),
            DVec2::new(0., 2.),
            DVec2::new(4., 2.),
            DVec2::new(4., 0.),
        ];
        let region = Region::new(ring, vec![]).unwrap();
        let g = tfi_region(&region, Corners::Input([0, 3, 2, 1]), 5, 3).unwrap();
        // bottom side runs from input vertex 0 (0,0) to input vertex 3 (4,0)
        assert_eq!(g.node(0, 0), DVec2::new(0., 0.));
        assert_eq!(g.node(4, 0), DVec2::new(4., 0.));
        assert_eq!(g.node(4, 2), DVec2::new(4., 2.));
        assert_eq!(g.node(2, 1), DVec2::new(2., 1.));
        assert_eq!(g.nodes().len(), 15);
    }

    #[test]
    fn holes_and_bad_corners_are_errors() {
        let sq = |h: f64| {
            vec![
                DVec2::new(-h, -h),
                DVec2::new(h, -h),
                DVec2::new(h, h),
                DVec2::new(-h, h),
            ]
        };
        let region = Region::new(sq(2.0), vec![sq(1.0)]).unwrap();
        assert!(matches!(
            tfi_region(&region, Corners::Auto, 5, 5),
            Err(CoreError::HolesInSingleBlock { .. })
        ));
        let region = Region::new(sq(2.0), vec![]).unwrap();
        assert!(matches!(
            tfi_region(&region, Corners::Input([0, 1, 2, 7]), 5, 5),
            Err(CoreError::Corners(_))
        ));
        assert!(matches!(
            tfi_region(&region, Corners::Input([0, 1, 1, 2]), 5, 5),
            Err(CoreError::Corners(_))
        ));
    }
}
