//! The radial map of the cube `[−1, 1]³` onto the unit ball, and ellipsoids by scaling
//! ([Cortés Aguirre 2012, §2.1.1, §3.4.3]; the references are listed in `docs/references.md` of
//! the repository). The thesis names the radial map of the cube but does not print its formula;
//! the one below is our choice.
//!
//! ```text
//! R(x) = x · ‖x‖∞ / ‖x‖₂          (R(0) = 0)
//! E(x) = (a·R(x)ₓ, b·R(x)_y, c·R(x)_z) + centre
//! ```
//!
//! `R` maps every cube shell `‖x‖∞ = t` onto the sphere of radius `t`, so each cube face
//! becomes one sixth of the sphere (one face of the logically hexahedral ball) and the
//! boundary of a uniform cube grid lies exactly on the sphere. It is continuous and piecewise
//! smooth; the cube's edges leave kinks along the diagonal planes (the thesis notes that they
//! propagate into the mesh, [Cortés Aguirre 2012, §3.4.3]), and the eight corner cells have a
//! nearly flat (close to 180°) boundary angle, so their fixed tetrahedra are thin but positive.

use glam::DVec3;

use super::error::HexGenError;
use crate::grid::StructuredGrid3;

/// `R(x) = x·‖x‖∞/‖x‖₂` (0 at the origin).
pub fn cube_to_ball(x: DVec3) -> DVec3 {
    let l2 = x.length();
    if l2 > 0.0 {
        x * (x.abs().max_element() / l2)
    } else {
        DVec3::ZERO
    }
}

/// The uniform `m × n × p` grid of `[−1, 1]³` mapped by [`cube_to_ball`] and scaled by the
/// semi-axes `axes = (a, b, c)` about `centre`: every node is mapped, so the start is the
/// convex "radial" mesh of the Esfera / Elipsoide examples ([Cortés Aguirre 2012, §3.4.3, §5.2]).
///
/// ```
/// use unamalla_mesh::hexgen::ellipsoid_grid;
/// use unamalla_mesh::DVec3;
/// let g = ellipsoid_grid((9, 9, 9), DVec3::new(0.5, 1.0, 0.5), DVec3::ZERO).unwrap();
/// let q = g.node(8, 3, 5); // on the boundary
/// let r = (q.x / 0.5).powi(2) + q.y.powi(2) + (q.z / 0.5).powi(2);
/// assert!((r - 1.0).abs() < 1e-12);
/// ```
pub fn ellipsoid_grid(
    dims: (usize, usize, usize),
    axes: DVec3,
    centre: DVec3,
) -> Result<StructuredGrid3, HexGenError> {
    let (m, n, p) = dims;
    if m < 2 || n < 2 || p < 2 {
        return Err(HexGenError::TooSmall {
            dims,
            reason: "the radial map needs at least 2 nodes per direction",
        });
    }
    for v in axes.to_array() {
        if !(v.is_finite() && v > 0.0) {
            return Err(HexGenError::InvalidParameter {
                name: "semi-axis",
                value: v,
                reason: "semi-axes must be finite and > 0",
            });
        }
    }
    if !centre.is_finite() {
        return Err(HexGenError::NonFinite {
            what: "centre",
            index: 0,
        });
    }
    let t = |i: usize, k: usize| -1.0 + 2.0 * i as f64 / (k - 1) as f64;
    Ok(StructuredGrid3::from_fn(m, n, p, |i, j, k| {
        centre + axes * cube_to_ball(DVec3::new(t(i, m), t(j, n), t(k, p)))
    })?)
}

/// The unit ball: [`ellipsoid_grid`] with semi-axes `(1, 1, 1)` about the origin.
pub fn ball_grid(dims: (usize, usize, usize)) -> Result<StructuredGrid3, HexGenError> {
    ellipsoid_grid(dims, DVec3::ONE, DVec3::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::hex_non_convex_count;
    use proptest::prelude::*;

    #[test]
    fn boundary_nodes_of_the_ball_have_radius_one_and_the_centre_is_fixed() {
        let g = ball_grid((7, 8, 9)).unwrap();
        let mut boundary = 0;
        for k in 0..9 {
            for j in 0..8 {
                for i in 0..7 {
                    let q = g.node(i, j, k);
                    if g.is_boundary(i, j, k) {
                        // ‖x‖∞ = 1 on the cube's surface, so |R(x)| = ‖x‖∞ = 1
                        assert!((q.length() - 1.0).abs() < 1e-14, "{i} {j} {k}: {q}");
                        boundary += 1;
                    } else {
                        assert!(q.length() < 1.0);
                    }
                }
            }
        }
        // boundary nodes: all − interior = 7·8·9 − 5·6·7
        assert_eq!(boundary, 7 * 8 * 9 - 5 * 6 * 7);
        // odd sizes put a node at the origin: (3, ·, 4) is the middle of 7 and 9 nodes
        let g = ball_grid((7, 7, 7)).unwrap();
        assert_eq!(g.node(3, 3, 3), DVec3::ZERO);
    }

    #[test]
    fn the_radial_start_is_convex() {
        // [Cortés Aguirre 2012, §3.4.3]: the radial mesh is convex (before the perturbation)
        for n in [5, 10, 20] {
            let g = ellipsoid_grid((n, n, n), DVec3::new(0.5, 1.0, 0.5), DVec3::ZERO).unwrap();
            assert_eq!(hex_non_convex_count(&g, 0.0), 0, "n = {n}");
        }
    }

    #[test]
    fn bad_axes_are_rejected() {
        let e = ellipsoid_grid((3, 3, 3), DVec3::new(1.0, 0.0, 1.0), DVec3::ZERO).unwrap_err();
        assert!(matches!(
            e,
            HexGenError::InvalidParameter {
                name: "semi-axis",
                ..
            }
        ));
        assert!(ball_grid((1, 3, 3)).is_err());
    }

    proptest! {
        #[test]
        fn cube_shells_go_to_spheres(x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0) {
            let v = DVec3::new(x, y, z);
            let r = cube_to_ball(v);
            // |R(x)| = ‖x‖∞ and R(x) is parallel to x
            prop_assert!((r.length() - v.abs().max_element()).abs() < 1e-12);
            prop_assert!(r.cross(v).length() < 1e-12);
        }
    }
}
