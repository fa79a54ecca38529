//! Initial hexahedral meshes from a 2D mesh ([Cortés Aguirre 2012, §2.2.2–§2.2.3];
//! the references are listed in `docs/references.md` of the repository): the 2D nodes
//! are projected vertically onto a plane or a surface `z = f(x, y)` and the volume is built by
//!
//! * **(i) layers** ([`Extrusion::Layers`]): project once, onto the base (copies stacked
//!   upward) or the top (copies stacked downward), with a list of layer thicknesses
//!   `t₀, t₁, …` (uniform or varying): with the base surface `s`,
//!   `z_k = s(x, y) + Σ_{l<k} t_l`; with the top surface, `z_k = s(x, y) − Σ_{l≥k} t_l`;
//! * **(ii) top/base interpolation** ([`Extrusion::Between`]): project twice and interpolate
//!   linearly, `z_k = (1 − τ_k)·b(x, y) + τ_k·t(x, y)` with `τ_k = Σ_{l<k} w_l / Σ w_l` for
//!   layer weights `w_l` (uniform weights give `τ_k = k/(p−1)`).
//!
//! The surfaces are anything implementing [`HeightField`]: a [`Plane`], a closure
//! `Fn(f64, f64) -> f64` (e.g. the thesis's `0.5x³ − 0.3y²`), or a [`Shepard`] interpolant of
//! scattered data. Vertical columns keep every cell's side faces vertical; convexity is not
//! guaranteed in case (ii) ([Cortés Aguirre 2012, §2.2.2]), which is why Algorithm A follows.
//!
//! Layer `k` of a 2D grid `m × n` becomes the `k`-th `(i, j)` slice of an `m × n × p` grid, so
//! counter-clockwise 2D cells give hexahedra in VTK order with positive orientation.

use glam::{DVec2, DVec3};

use super::error::HexGenError;
use super::shepard::Shepard;
use crate::grid::{StructuredGrid2, StructuredGrid3};
use crate::traits::HasQuadCells;
use crate::unstructured::HexMesh;

/// A surface `z = f(x, y)`.
pub trait HeightField: Sync {
    /// The height at `(x, y)`.
    fn z(&self, x: f64, y: f64) -> f64;
}

impl<F: Fn(f64, f64) -> f64 + Sync> HeightField for F {
    fn z(&self, x: f64, y: f64) -> f64 {
        self(x, y)
    }
}

impl HeightField for Shepard {
    fn z(&self, x: f64, y: f64) -> f64 {
        self.eval(x, y)
    }
}

/// The plane `z = z0 + slope.x·x + slope.y·y`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plane {
    /// Height at the origin.
    pub z0: f64,
    /// `(∂z/∂x, ∂z/∂y)`.
    pub slope: DVec2,
}

impl Plane {
    /// The horizontal plane `z = z0`.
    pub fn horizontal(z0: f64) -> Self {
        Self {
            z0,
            slope: DVec2::ZERO,
        }
    }
}

impl HeightField for Plane {
    fn z(&self, x: f64, y: f64) -> f64 {
        self.z0 + self.slope.x * x + self.slope.y * y
    }
}

/// Which surface a layered extrusion starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Anchor {
    /// The projected mesh is the base; copies go up.
    Base,
    /// The projected mesh is the top; copies go down.
    Top,
}

/// How to build the layers of an extrusion (see the module documentation).
pub enum Extrusion<'a> {
    /// Project once onto `surface` and stack copies with the given layer thicknesses
    /// (bottom layer first); `p = thicknesses.len() + 1` node layers.
    Layers {
        /// The surface the 2D mesh is projected onto.
        surface: &'a dyn HeightField,
        /// Whether that surface is the base or the top.
        anchor: Anchor,
        /// Layer thicknesses, bottom first, each finite and > 0.
        thicknesses: Vec<f64>,
    },
    /// Project onto `base` and `top` and interpolate linearly with relative layer weights
    /// (bottom first, each finite and > 0); `p = weights.len() + 1` node layers.
    Between {
        /// The base surface.
        base: &'a dyn HeightField,
        /// The top surface; must lie strictly above the base at every node.
        top: &'a dyn HeightField,
        /// Relative layer thicknesses.
        weights: Vec<f64>,
    },
}

impl<'a> Extrusion<'a> {
    /// `p − 1` equal layers between `base` and `top`.
    pub fn uniform_between(base: &'a dyn HeightField, top: &'a dyn HeightField, p: usize) -> Self {
        Extrusion::Between {
            base,
            top,
            weights: vec![1.0; p.saturating_sub(1)],
        }
    }

    fn layers(&self) -> &[f64] {
        match self {
            Extrusion::Layers { thicknesses, .. } => thicknesses,
            Extrusion::Between { weights, .. } => weights,
        }
    }

    fn check(&self) -> Result<(), HexGenError> {
        let l = self.layers();
        if l.is_empty() {
            return Err(HexGenError::TooSmall {
                dims: (0, 0, l.len() + 1),
                reason: "an extrusion needs at least one layer",
            });
        }
        if let Some(&t) = l.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
            return Err(HexGenError::InvalidParameter {
                name: "layer thickness",
                value: t,
                reason: "layer thicknesses (weights) must be finite and > 0",
            });
        }
        Ok(())
    }

    /// The `p` heights of the column over `(x, y)`; `node` names the 2D node in errors.
    fn column(&self, q: DVec2, node: usize) -> Result<Vec<f64>, HexGenError> {
        let l = self.layers();
        let mut z = Vec::with_capacity(l.len() + 1);
        match self {
            Extrusion::Layers {
                surface, anchor, ..
            } => {
                let s = surface.z(q.x, q.y);
                if !s.is_finite() {
                    return Err(HexGenError::NonFinite {
                        what: "surface height at a 2D node",
                        index: node,
                    });
                }
                let total: f64 = l.iter().sum();
                let mut acc = match anchor {
                    Anchor::Base => s,
                    Anchor::Top => s - total,
                };
                z.push(acc);
                for t in l {
                    acc += t;
                    z.push(acc);
                }
                if *anchor == Anchor::Top {
                    // exact top
                    if let Some(last) = z.last_mut() {
                        *last = s;
                    }
                }
            }
            Extrusion::Between { base, top, .. } => {
                let (b, t) = (base.z(q.x, q.y), top.z(q.x, q.y));
                if !(b.is_finite() && t.is_finite()) {
                    return Err(HexGenError::NonFinite {
                        what: "surface height at a 2D node",
                        index: node,
                    });
                }
                if t <= b {
                    return Err(HexGenError::InvalidParameter {
                        name: "top − base",
                        value: t - b,
                        reason: "the top surface must lie above the base at every 2D node",
                    });
                }
                let total: f64 = l.iter().sum();
                let mut acc = 0.0;
                z.push(b);
                for (k, w) in l.iter().enumerate() {
                    acc += w;
                    let tau = if k + 1 == l.len() { 1.0 } else { acc / total };
                    z.push((1.0 - tau) * b + tau * t);
                }
            }
        }
        Ok(z)
    }
}

/// Extrudes a structured 2D grid (`m × n`) into an `m × n × p` grid.
///
/// ```
/// use unamalla_mesh::hexgen::{extrude_grid, Extrusion, Plane};
/// use unamalla_mesh::{DVec2, StructuredGrid2};
/// let g2 = StructuredGrid2::from_fn(5, 4, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
/// let top = |x: f64, y: f64| 0.5 * x * x * x / 64.0 - 0.3 * y * y / 9.0 + 3.0;
/// let base = Plane::horizontal(0.0);
/// let g = extrude_grid(&g2, &Extrusion::uniform_between(&base, &top, 4)).unwrap();
/// assert_eq!(g.dims(), (5, 4, 4));
/// assert!((g.node(4, 3, 3).z - top(4.0, 3.0)).abs() < 1e-12);
/// ```
pub fn extrude_grid(
    g: &StructuredGrid2,
    e: &Extrusion<'_>,
) -> Result<StructuredGrid3, HexGenError> {
    e.check()?;
    let (m, n) = (g.m(), g.n());
    let p = e.layers().len() + 1;
    let mut cols = Vec::with_capacity(m * n);
    for j in 0..n {
        for i in 0..m {
            cols.push(e.column(g.node(i, j), g.index(i, j))?);
        }
    }
    Ok(StructuredGrid3::from_fn(m, n, p, |i, j, k| {
        let q = g.node(i, j);
        DVec3::new(q.x, q.y, cols[j * m + i][k])
    })?)
}

/// Extrudes any quad mesh (cells counter-clockwise seen from `+z`) into a hex mesh: node
/// `v` of layer `k` gets id `k·N + v`, cell `c` of layer `k` is
/// `[q₀, q₁, q₂, q₃]` at layer `k` followed by the same at `k + 1` (VTK order). Boundary
/// nodes (on faces used by one cell) are fixed, as in [`HexMesh::new`].
pub fn extrude_mesh<M: HasQuadCells + ?Sized>(
    mesh: &M,
    e: &Extrusion<'_>,
) -> Result<HexMesh, HexGenError> {
    e.check()?;
    let nn = mesh.num_nodes();
    let p = e.layers().len() + 1;
    let cols: Vec<Vec<f64>> = mesh
        .nodes()
        .iter()
        .enumerate()
        .map(|(v, &q)| e.column(q, v))
        .collect::<Result<_, _>>()?;
    let mut nodes = Vec::with_capacity(nn * p);
    for k in 0..p {
        for (q, col) in mesh.nodes().iter().zip(&cols) {
            nodes.push(DVec3::new(q.x, q.y, col[k]));
        }
    }
    let mut cells = Vec::with_capacity(mesh.num_quads() * (p - 1));
    for k in 0..p - 1 {
        for c in 0..mesh.num_quads() {
            let q = mesh.quad(c);
            let lo = q.map(|v| k * nn + v);
            let hi = q.map(|v| (k + 1) * nn + v);
            cells.push([lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]]);
        }
    }
    Ok(HexMesh::new(nodes, cells)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::hex_non_convex_count;
    use crate::traits::{FreeNodes, HasHexCells, HasNodes};
    use crate::unstructured::QuadMesh;

    fn square(m: usize, n: usize) -> StructuredGrid2 {
        StructuredGrid2::from_fn(m, n, |i, j| DVec2::new(i as f64 * 0.5, j as f64 * 0.25)).unwrap()
    }

    #[test]
    fn layers_from_the_base_stack_the_thicknesses() {
        let g2 = square(4, 3);
        let base = |x: f64, y: f64| 0.5 * x * x * x - 0.3 * y * y;
        let e = Extrusion::Layers {
            surface: &base,
            anchor: Anchor::Base,
            thicknesses: vec![1.0, 0.5, 2.0],
        };
        let g = extrude_grid(&g2, &e).unwrap();
        assert_eq!(g.dims(), (4, 3, 4));
        // z_k = s + Σ_{l<k} t_l: offsets 0, 1, 1.5, 3.5
        for (k, off) in [0.0, 1.0, 1.5, 3.5].into_iter().enumerate() {
            let q = g.node(3, 2, k);
            assert_eq!((q.x, q.y), (1.5, 0.5));
            assert!((q.z - (base(1.5, 0.5) + off)).abs() < 1e-12);
        }
        assert_eq!(hex_non_convex_count(&g, 0.0), 0);
    }

    #[test]
    fn layers_from_the_top_end_exactly_on_the_surface() {
        let g2 = square(3, 3);
        let top = Plane {
            z0: 2.0,
            slope: DVec2::new(0.1, -0.2),
        };
        let e = Extrusion::Layers {
            surface: &top,
            anchor: Anchor::Top,
            thicknesses: vec![0.3, 0.7],
        };
        let g = extrude_grid(&g2, &e).unwrap();
        for j in 0..3 {
            for i in 0..3 {
                let q = g.node(i, j, 2);
                assert_eq!(q.z, top.z(q.x, q.y));
                // 1.0 below the top at the bottom, 0.7 below it in the middle
                assert!((g.node(i, j, 0).z - (q.z - 1.0)).abs() < 1e-12);
                assert!((g.node(i, j, 1).z - (q.z - 0.7)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn between_interpolates_linearly_with_weights() {
        let g2 = square(3, 2);
        let base = Plane::horizontal(-1.0);
        let top = |x: f64, _y: f64| 1.0 + x;
        let e = Extrusion::Between {
            base: &base,
            top: &top,
            weights: vec![1.0, 3.0],
        };
        let g = extrude_grid(&g2, &e).unwrap();
        // τ = 0, 1/4, 1: at x = 1, base −1, top 2 → −1, −0.25, 2
        let z: Vec<f64> = (0..3).map(|k| g.node(2, 1, k).z).collect();
        assert!(
            (z[0] + 1.0).abs() < 1e-12 && (z[1] + 0.25).abs() < 1e-12 && (z[2] - 2.0).abs() < 1e-12
        );
    }

    #[test]
    fn crossing_surfaces_and_bad_thicknesses_are_errors() {
        let g2 = square(3, 3);
        let base = Plane::horizontal(0.0);
        let top = |x: f64, _y: f64| x - 0.5; // below the base for x < 0.5
        let e = Extrusion::uniform_between(&base, &top, 3);
        assert!(matches!(
            extrude_grid(&g2, &e),
            Err(HexGenError::InvalidParameter {
                name: "top − base",
                ..
            })
        ));
        let e = Extrusion::Layers {
            surface: &base,
            anchor: Anchor::Base,
            thicknesses: vec![1.0, -1.0],
        };
        assert!(matches!(
            extrude_grid(&g2, &e),
            Err(HexGenError::InvalidParameter {
                name: "layer thickness",
                ..
            })
        ));
        let e = Extrusion::Layers {
            surface: &base,
            anchor: Anchor::Base,
            thicknesses: vec![],
        };
        assert!(matches!(
            extrude_grid(&g2, &e),
            Err(HexGenError::TooSmall { .. })
        ));
    }

    #[test]
    fn mesh_extrusion_matches_grid_extrusion() {
        let g2 = square(4, 3);
        let q = QuadMesh::from_grid(&g2);
        let base = Plane::horizontal(0.0);
        let top = |x: f64, y: f64| 2.0 + 0.1 * x - 0.2 * y;
        let e = Extrusion::uniform_between(&base, &top, 4);
        let hg = extrude_grid(&g2, &e).unwrap();
        let hm = extrude_mesh(&q, &e).unwrap();
        assert_eq!(hm.num_hexes(), hg.num_hexes());
        // same numbering: node k·N + v
        assert_eq!(hm.nodes(), hg.nodes());
        for c in 0..hm.num_hexes() {
            assert_eq!(hm.hex(c), hg.hex(c));
        }
        // interior nodes of the 4 × 3 × 4 grid: 2·1·2
        assert_eq!(hm.num_free(), 4);
    }
}
