//! Control nets, the boundary curves of Lemma 4 and the convexity tests of Definitions 1–2.
//!
//! # Indexing
//! A [`ControlNet`] has `n` points along ξ and `m` along η (the paper's `n × m`, §1.1). Point
//! `P_{i,j}` of the paper (1-based) is [`ControlNet::get`]`(i − 1, j − 1)`, stored at
//! `j·n + i`, which is the node `(i, j)` of a [`StructuredGrid2`] of `n × m` nodes (the grid's
//! first size is the count along the bottom side). Cells are counter-clockwise
//! `P_{i,j}, P_{i+1,j}, P_{i+1,j+1}, P_{i,j+1}`.
//!
//! # Edge vectors and triangles ([Abelló et al., §1.2])
//! `h_{i,s} = P_{i+1,s} − P_{i,s}` ("horizontal", (15)), `v_{r,j} = P_{r,j+1} − P_{r,j}`
//! ("vertical", (16)). Cell `c_{ij}` is split by its diagonals into the four counter-clockwise
//! triangles `t¹ = △(P_{ij}, P_{i+1,j}, P_{i+1,j+1})`, `t² = △(P_{ij}, P_{i+1,j+1}, P_{i,j+1})`,
//! `t³ = △(P_{ij}, P_{i+1,j}, P_{i,j+1})`, `t⁴ = △(P_{i+1,j}, P_{i+1,j+1}, P_{i,j+1})`; the cell is
//! convex iff all four doubled areas are positive (Definition 1, index range corrected to
//! `i ≤ n−1, j ≤ m−1`; the paper prints `i = 1..n, j = 1..m`). The proof of
//! Theorem 1 swaps the labels `t¹` and `t³`; correctly:
//! `det[h_{ij}|v_{ij}] = 2·area(t³)`, `det[h_{i,j+1}|v_{ij}] = 2·area(t²)`,
//! `det[h_{ij}|v_{i+1,j}] = 2·area(t¹)`, `det[h_{i,j+1}|v_{i+1,j}] = 2·area(t⁴)`.
//!
//! ε-convexity (Definition 2, §2.2, which compares an "area" with `ε·ᾱ`, `ᾱ` a mean of doubled
//! areas; here both are doubled areas): every triangle has `α > ε·ᾱ`, `α` the doubled area, `ᾱ`
//! the mean α, which is fixed by the boundary: `ᾱ = area(Ω')/((n−1)(m−1))` (the four triangles
//! of a cell add up to twice its doubled area, and the cells tile `Ω'`).
//!
//! # Boundary (Lemma 4, [Abelló et al., §2.1])
//! [`BoundaryCurves`] holds the control points of the south `x_b` (Q→R, `n` points), east `x_r`
//! (R→S, `m`), north `x_t` (T→S, `n`) and west `x_l` (Q→T, `m`) curves. Lemma 4 sets
//! `P_{i,1} = H^b_i`, `P_{i,m} = H^t_i`, `P_{1,j} = V^l_j`, `P_{n,j} = V^r_j` ((48)–(49); (49) is
//! printed with `V^l_i`, `V^r_i` for `V^l_j`, `V^r_j`); then the biquadratic map reproduces the
//! four curves on `∂U`. [`BoundaryCurves::validate`] checks counts, corner identities,
//! counter-clockwise orientation, a simple control polygon `∂Ω'` and strictly convex corners (a
//! corner belongs to a single cell, so a reflex corner makes a convex net impossible).

use glam::DVec2;
use unamalla_mesh::geometry::orient2d;
use unamalla_mesh::{tfi2, Polygon, StructuredGrid2, TfiParams};

use crate::error::BsplineError;

/// An `n × m` grid of control points (see the module docs for the indexing).
#[derive(Debug, Clone, PartialEq)]
pub struct ControlNet {
    n: usize,
    m: usize,
    pts: Vec<DVec2>,
}

/// Convexity statistics of a control net (Definitions 1 and 2).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NetConvexity {
    /// Minimum doubled triangle area `α₋` over the `4(n−1)(m−1)` diagonal triangles.
    pub min_alpha: f64,
    /// The mean `ᾱ`.
    pub alpha_bar: f64,
    /// The cell `(i, j)` (0-based) holding `α₋`.
    pub worst_cell: (usize, usize),
    /// Number of cells with some `α ≤ 0` (non-convex or degenerate).
    pub nonconvex_cells: usize,
}

impl NetConvexity {
    /// Every cell is strictly convex (Definition 1).
    pub fn convex(&self) -> bool {
        self.nonconvex_cells == 0 && self.min_alpha > 0.0
    }
    /// `α₋ > ε·ᾱ` (Definition 2).
    pub fn eps_convex(&self, eps: f64) -> bool {
        self.min_alpha > eps * self.alpha_bar
    }
    /// `α₋/ᾱ`.
    pub fn min_alpha_rel(&self) -> f64 {
        self.min_alpha / self.alpha_bar
    }
}

impl ControlNet {
    /// A net of `n × m ≥ 2 × 2` finite points stored at `j·n + i`.
    pub fn new(n: usize, m: usize, pts: Vec<DVec2>) -> Result<Self, BsplineError> {
        if n < 2 || m < 2 {
            return Err(BsplineError::Count {
                what: "control net",
                got: n.min(m),
                need: "at least 2 × 2".into(),
            });
        }
        if pts.len() != n * m {
            return Err(BsplineError::Count {
                what: "control net",
                got: pts.len(),
                need: format!("{} for {n} × {m}", n * m),
            });
        }
        if let Some(i) = pts.iter().position(|p| !p.is_finite()) {
            return Err(BsplineError::NonFinite {
                what: "control net",
                index: i,
            });
        }
        Ok(Self { n, m, pts })
    }

    /// The net of a function `f(i, j)`.
    pub fn from_fn(
        n: usize,
        m: usize,
        mut f: impl FnMut(usize, usize) -> DVec2,
    ) -> Result<Self, BsplineError> {
        let mut pts = Vec::with_capacity(n.saturating_mul(m));
        for j in 0..m {
            for i in 0..n {
                pts.push(f(i, j));
            }
        }
        Self::new(n, m, pts)
    }

    /// The nodes of a structured grid as a net (node `(i, j)` ↦ `P_{i,j}`).
    pub fn from_grid(g: &StructuredGrid2) -> Self {
        use unamalla_mesh::HasNodes;
        Self {
            n: g.m(),
            m: g.n(),
            pts: g.nodes().to_vec(),
        }
    }

    /// The net as a structured grid of `n × m` nodes (boundary nodes fixed, interior free, as
    /// the optimizers expect).
    pub fn to_grid(&self) -> Result<StructuredGrid2, BsplineError> {
        Ok(StructuredGrid2::new(self.n, self.m, self.pts.clone())?)
    }

    /// Number of control points along ξ.
    pub fn n(&self) -> usize {
        self.n
    }
    /// Number of control points along η.
    pub fn m(&self) -> usize {
        self.m
    }
    /// All points, `j·n + i` order.
    pub fn points(&self) -> &[DVec2] {
        &self.pts
    }
    /// `P_{i,j}` (0-based).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> DVec2 {
        self.pts[j * self.n + i]
    }
    /// Sets `P_{i,j}` (0-based).
    pub fn set(&mut self, i: usize, j: usize, p: DVec2) {
        self.pts[j * self.n + i] = p;
    }
    /// `h_{i,s} = P_{i+1,s} − P_{i,s}` (0-based, `i < n−1`).
    #[inline]
    pub fn h(&self, i: usize, s: usize) -> DVec2 {
        self.get(i + 1, s) - self.get(i, s)
    }
    /// `v_{r,j} = P_{r,j+1} − P_{r,j}` (0-based, `j < m−1`).
    #[inline]
    pub fn v(&self, r: usize, j: usize) -> DVec2 {
        self.get(r, j + 1) - self.get(r, j)
    }

    /// Doubled signed areas of the four diagonal triangles `[t¹, t², t³, t⁴]` of cell `(i, j)`.
    pub fn cell_triangles(&self, i: usize, j: usize) -> [f64; 4] {
        let (p0, p1, p2, p3) = (
            self.get(i, j),
            self.get(i + 1, j),
            self.get(i + 1, j + 1),
            self.get(i, j + 1),
        );
        let a = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
        [a(p0, p1, p2), a(p0, p2, p3), a(p0, p1, p3), a(p1, p2, p3)]
    }

    /// The boundary control polygon `∂Ω'`, counter-clockwise from `P_{0,0}` (south, east,
    /// north reversed, west reversed), without repeating the first point.
    pub fn boundary_polygon(&self) -> Vec<DVec2> {
        let (n, m) = (self.n, self.m);
        let mut v = Vec::with_capacity(2 * (n + m) - 4);
        v.extend((0..n - 1).map(|i| self.get(i, 0)));
        v.extend((0..m - 1).map(|j| self.get(n - 1, j)));
        v.extend((1..n).rev().map(|i| self.get(i, m - 1)));
        v.extend((1..m).rev().map(|j| self.get(0, j)));
        v
    }

    /// `ᾱ = 4·area(Ω')/(4(n−1)(m−1))`: the mean doubled triangle area, fixed by the boundary.
    pub fn alpha_bar(&self) -> f64 {
        unamalla_mesh::region::signed_area(&self.boundary_polygon())
            / ((self.n - 1) * (self.m - 1)) as f64
    }

    /// Convexity statistics (Definitions 1 and 2).
    pub fn convexity(&self) -> NetConvexity {
        let mut c = NetConvexity {
            min_alpha: f64::INFINITY,
            alpha_bar: self.alpha_bar(),
            worst_cell: (0, 0),
            nonconvex_cells: 0,
        };
        for j in 0..self.m - 1 {
            for i in 0..self.n - 1 {
                let t = self.cell_triangles(i, j);
                let mn = t.iter().fold(f64::INFINITY, |a, &b| a.min(b));
                if mn <= 0.0 || mn.is_nan() {
                    c.nonconvex_cells += 1;
                }
                if mn < c.min_alpha || mn.is_nan() {
                    c.min_alpha = if mn.is_nan() { f64::NEG_INFINITY } else { mn };
                    c.worst_cell = (i, j);
                }
            }
        }
        c
    }

    /// The south/east/north/west control polygons of the net (the inverse of Lemma 4).
    pub fn boundary_curves(&self) -> BoundaryCurves {
        let (n, m) = (self.n, self.m);
        BoundaryCurves {
            south: (0..n).map(|i| self.get(i, 0)).collect(),
            east: (0..m).map(|j| self.get(n - 1, j)).collect(),
            north: (0..n).map(|i| self.get(i, m - 1)).collect(),
            west: (0..m).map(|j| self.get(0, j)).collect(),
        }
    }

    /// Lemma 4 assembly: the boundary of the net from the four curves' control points, the
    /// interior by discrete TFI of the boundary control polygon (arc-length parameters; the paper
    /// names no start — it may be folded, the optimizer of
    /// [`crate::interior`] untangles it). The curves are validated first
    /// ([`BoundaryCurves::validate`]).
    pub fn from_boundary(b: &BoundaryCurves) -> Result<Self, BsplineError> {
        b.validate()?;
        let g = tfi2(&b.south, &b.east, &b.north, &b.west, TfiParams::ArcLength)?;
        let mut net = Self::from_grid(&g);
        // Lemma 4 exactly (TFI reproduces the boundary lists, but make it bit-exact)
        let (n, m) = (net.n, net.m);
        for i in 0..n {
            net.set(i, 0, b.south[i]);
            net.set(i, m - 1, b.north[i]);
        }
        for j in 0..m {
            net.set(0, j, b.west[j]);
            net.set(n - 1, j, b.east[j]);
        }
        Ok(net)
    }
}

/// The control points of the four boundary curves ([Abelló et al., §2.1]): south `Q→R` and
/// north `T→S` with `n` points, west `Q→T` and east `R→S` with `m` points; corners shared.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryCurves {
    /// `H^b_1..H^b_n`, from Q to R.
    pub south: Vec<DVec2>,
    /// `V^r_1..V^r_m`, from R to S.
    pub east: Vec<DVec2>,
    /// `H^t_1..H^t_n`, from T to S.
    pub north: Vec<DVec2>,
    /// `V^l_1..V^l_m`, from Q to T.
    pub west: Vec<DVec2>,
}

impl BoundaryCurves {
    /// Number of control points along ξ (south/north).
    pub fn n(&self) -> usize {
        self.south.len()
    }
    /// Number of control points along η (west/east).
    pub fn m(&self) -> usize {
        self.west.len()
    }

    /// The boundary control polygon `∂Ω'` counter-clockwise from Q (open ring).
    pub fn polygon(&self) -> Vec<DVec2> {
        let mut v = Vec::new();
        let (n, m) = (self.n(), self.m());
        v.extend_from_slice(&self.south[..n.saturating_sub(1)]);
        v.extend_from_slice(&self.east[..m.saturating_sub(1)]);
        v.extend(self.north.iter().rev().take(n.saturating_sub(1)));
        v.extend(self.west.iter().rev().take(m.saturating_sub(1)));
        v
    }

    /// Checks that the curves can bound a convex control net (the paper assumes it): at least 3
    /// points per curve (quadratic curves), equal counts on opposite sides, finite points,
    /// the corner identities `Q, R, S, T` (within `1e-12` of the polygon's size), a
    /// counter-clockwise and simple control polygon and strictly convex corners.
    pub fn validate(&self) -> Result<(), BsplineError> {
        let (n, m) = (self.n(), self.m());
        for (what, len, need) in [
            ("south curve", self.south.len(), 3),
            ("north curve", self.north.len(), 3),
            ("west curve", self.west.len(), 3),
            ("east curve", self.east.len(), 3),
        ] {
            if len < need {
                return Err(BsplineError::Count {
                    what,
                    got: len,
                    need: format!("at least {need}"),
                });
            }
        }
        if self.north.len() != n {
            return Err(BsplineError::Count {
                what: "north curve",
                got: self.north.len(),
                need: format!("{n} (as many as the south curve)"),
            });
        }
        if self.east.len() != m {
            return Err(BsplineError::Count {
                what: "east curve",
                got: self.east.len(),
                need: format!("{m} (as many as the west curve)"),
            });
        }
        for (what, c) in [
            ("south curve", &self.south),
            ("east curve", &self.east),
            ("north curve", &self.north),
            ("west curve", &self.west),
        ] {
            if let Some(i) = c.iter().position(|p| !p.is_finite()) {
                return Err(BsplineError::NonFinite { what, index: i });
            }
        }
        let scale = self
            .south
            .iter()
            .chain(&self.north)
            .fold(0.0f64, |s, p| s.max(p.abs().max_element()))
            .max(1.0);
        let tol = 1e-12 * scale;
        let corners = [
            ('Q', "south", self.south[0], "west", self.west[0]),
            ('R', "south", self.south[n - 1], "east", self.east[0]),
            ('S', "north", self.north[n - 1], "east", self.east[m - 1]),
            ('T', "north", self.north[0], "west", self.west[m - 1]),
        ];
        for (corner, a, pa, b, pb) in corners {
            let d = pa.distance(pb);
            if d > tol {
                return Err(BsplineError::CornerMismatch {
                    corner,
                    a,
                    b,
                    distance: d,
                });
            }
        }
        let poly = self.polygon();
        let area = unamalla_mesh::region::signed_area(&poly);
        if area <= 0.0 {
            return Err(BsplineError::Clockwise { signed_area: area });
        }
        Polygon::new(poly.clone()).map_err(|e| BsplineError::NotSimple(e.to_string()))?;
        // corners Q, R, S, T are polygon vertices 0, n−1, n+m−2, 2n+m−3
        let len = poly.len();
        for (corner, k) in [
            ('Q', 0),
            ('R', n - 1),
            ('S', n + m - 2),
            ('T', 2 * n + m - 3),
        ] {
            let turn = orient2d(poly[(k + len - 1) % len], poly[k], poly[(k + 1) % len]);
            if turn <= 0.0 {
                return Err(BsplineError::ReflexCorner { corner, turn });
            }
        }
        Ok(())
    }

    /// A control polygon from a polyline (the paper does not say how its boundary curves were
    /// made; this is the closest reading of its "control polygon"): a counter-clockwise ring
    /// split at four corner indices
    /// `c0 < c1 < c2 < c3` (cyclically, counter-clockwise; `c0` = Q), each side resampled by
    /// arc length to `n` (south/north) or `m` (west/east) points, which are used directly as
    /// control points.
    pub fn from_ring(
        ring: &[DVec2],
        corners: [usize; 4],
        n: usize,
        m: usize,
    ) -> Result<Self, BsplineError> {
        let [b, r, t, l] = unamalla_mesh::tfi::sides_from_ring(ring, corners, n, m)?;
        Ok(Self {
            south: b,
            east: r,
            north: t,
            west: l,
        })
    }
}

/// Names of the four sides in the order of [`RingFit`]'s arrays.
pub const SIDE_NAMES: [&str; 4] = ["south", "east", "north", "west"];

/// The result of [`BoundaryCurves::fit_ring`].
#[derive(Debug, Clone)]
pub struct RingFit {
    /// The fitted boundary curves.
    pub curves: BoundaryCurves,
    /// Fit residuals of the south, east, north and west sides.
    pub residuals: [crate::fit::FitReport; 4],
    /// The fairing weight `λ` used on the south, east, north and west sides.
    pub fairing: [f64; 4],
}

impl BoundaryCurves {
    /// Option (b) of the boundary preparation: a counter-clockwise ring split at four corner
    /// indices (as [`BoundaryCurves::from_ring`]), each side **fitted** by least squares
    /// ([`crate::fit::fit_polyline`]: quadratic, uniform knots (23)/(24), end points fixed to
    /// the corners; Piegl & Tiller 1997, §9.4.1) with `n` (south/north) or `m` (west/east)
    /// control points and the fairing weight `fairing` (a fixed `λ`, or [`crate::fit::Fairing::Auto`]:
    /// every side starts at `λ = 0`, and while [`BoundaryCurves::validate`] fails, the sides
    /// its error names — the two sides of a crossing, the two at a reflex corner — go one step
    /// up [`crate::fit::FAIRING_LADDER`], so a ragged side is faired without smoothing the
    /// others; at most `4 × 16` fits). Returns the curves, their residuals and the `λ` of each
    /// side.
    pub fn fit_ring(
        ring: &[DVec2],
        corners: [usize; 4],
        n: usize,
        m: usize,
        kind: crate::fit::FitParameters,
        fairing: crate::fit::Fairing,
    ) -> Result<RingFit, BsplineError> {
        // the sides as dense polylines: every ring vertex of the side is kept
        let len = ring.len();
        if corners.iter().any(|&c| c >= len) {
            return Err(BsplineError::Fit(format!(
                "corner indices {corners:?} out of range for a ring of {len} points"
            )));
        }
        let arc = |a: usize, b: usize| unamalla_mesh::tfi::ring_arc(ring, a, b);
        let mut top = arc(corners[2], corners[3]);
        top.reverse();
        let mut left = arc(corners[3], corners[0]);
        left.reverse();
        let sides = [
            (arc(corners[0], corners[1]), n),
            (arc(corners[1], corners[2]), m),
            (top, n),
            (left, m),
        ];
        let fit_sides = |lambda: [f64; 4]| -> Result<RingFit, BsplineError> {
            let fit = |s: usize| crate::fit::fit_polyline(&sides[s].0, sides[s].1, kind, lambda[s]);
            let [(south, rs), (east, re), (north, rn), (west, rw)] =
                [fit(0)?, fit(1)?, fit(2)?, fit(3)?];
            Ok(RingFit {
                curves: Self {
                    south,
                    east,
                    north,
                    west,
                },
                residuals: [rs, re, rn, rw],
                fairing: lambda,
            })
        };
        let ladder = &crate::fit::FAIRING_LADDER;
        match fairing {
            crate::fit::Fairing::Fixed(lambda) => fit_sides([lambda; 4]),
            crate::fit::Fairing::Auto => {
                // raise λ one ladder step on the sides the failed check names, until valid
                let mut level = [0usize; 4];
                loop {
                    let f = fit_sides(level.map(|l| ladder[l]))?;
                    let e = match f.curves.validate() {
                        Ok(()) => return Ok(f),
                        Err(e) => e,
                    };
                    let Some(named) = f.curves.sides_named_by(&e) else {
                        return Err(e);
                    };
                    for (s, l) in level.iter_mut().enumerate() {
                        if named[s] {
                            if *l + 1 == ladder.len() {
                                return Err(BsplineError::Fit(format!(
                                    "no fairing weight up to λ = {} on the {} side gives a valid boundary control polygon (there: {e})",
                                    ladder[*l],
                                    SIDE_NAMES[s]
                                )));
                            }
                            *l += 1;
                        }
                    }
                }
            }
        }
    }

    /// The sides (south, east, north, west) a failed [`BoundaryCurves::validate`] names:
    /// the two sides of a crossing of the control polygon, the two sides meeting at a reflex
    /// corner, all four for a clockwise polygon; `None` for errors fairing cannot mend (counts,
    /// non-finite points, corner mismatch).
    fn sides_named_by(&self, e: &BsplineError) -> Option<[bool; 4]> {
        let (n, m) = (self.n(), self.m());
        // edge k of `polygon()` runs from vertex k to k + 1
        let side_of_edge = |k: usize| {
            if k + 1 < n {
                0
            } else if k + 2 < n + m {
                1
            } else if k + 3 < 2 * n + m {
                2
            } else {
                3
            }
        };
        let mut named = [false; 4];
        match e {
            BsplineError::Clockwise { .. } => named = [true; 4],
            BsplineError::ReflexCorner { corner, .. } => {
                let (a, b) = match corner {
                    'Q' => (3, 0),
                    'R' => (0, 1),
                    'S' => (1, 2),
                    _ => (2, 3),
                };
                named[a] = true;
                named[b] = true;
            }
            BsplineError::NotSimple(_) => match Polygon::new(self.polygon()) {
                Err(unamalla_mesh::GeometryError::SelfIntersection { edge_a, edge_b, .. }) => {
                    named[side_of_edge(edge_a)] = true;
                    named[side_of_edge(edge_b)] = true;
                }
                _ => named = [true; 4],
            },
            _ => return None,
        }
        Some(named)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 × 10 square whose east side has a slit 6 long and 0.1 wide (a lagoon behind a
    /// barrier island): counter-clockwise ring and the corner indices of the square.
    fn square_with_a_slit() -> (Vec<DVec2>, [usize; 4]) {
        let mut ring = vec![DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0)];
        for y in [4.95, 5.05] {
            let tip = DVec2::new(4.0, y);
            if y < 5.0 {
                ring.extend([DVec2::new(10.0, y), tip]);
            } else {
                ring.extend([tip, DVec2::new(10.0, y)]);
            }
        }
        let r = ring.len();
        ring.extend([DVec2::new(10.0, 10.0), DVec2::new(0.0, 10.0)]);
        (ring, [0, 1, r, r + 1])
    }

    #[test]
    fn auto_fairing_smooths_only_the_ragged_side() {
        let (ring, corners) = square_with_a_slit();
        let (n, m) = (6, 8);
        let kind = crate::fit::FitParameters::ChordLength;
        // the plain least-squares east curve follows the slit and the polygon is invalid
        let plain =
            BoundaryCurves::fit_ring(&ring, corners, n, m, kind, crate::fit::Fairing::Fixed(0.0))
                .unwrap();
        assert!(plain.curves.validate().is_err());
        let auto = BoundaryCurves::fit_ring(&ring, corners, n, m, kind, crate::fit::Fairing::Auto)
            .unwrap();
        auto.curves.validate().unwrap();
        // straight sides are fitted exactly at λ = 0; only the east side is faired
        assert_eq!(auto.fairing[0], 0.0);
        assert_eq!(auto.fairing[2], 0.0);
        assert_eq!(auto.fairing[3], 0.0);
        assert!(auto.fairing[1] > 0.0, "{:?}", auto.fairing);
        for s in [0, 2, 3] {
            assert!(auto.residuals[s].max < 1e-9, "{}", SIDE_NAMES[s]);
        }
        // the faired east side cuts across the slit: it misses the slit's tip by about its
        // depth (6) at most, and the curves are a valid net boundary
        assert!(
            auto.residuals[1].max <= 6.0 + 1e-9,
            "{:?}",
            auto.residuals[1]
        );
        ControlNet::from_boundary(&auto.curves).unwrap();
    }

    #[test]
    fn triangle_labels_match_edge_determinants() {
        // Theorem 1's proof swaps t¹ and t³; correctly det[h_ij|v_ij] = 2·area(t³),
        // det[h_ij|v_{i+1,j}] = 2·area(t¹), …
        let net = ControlNet::new(
            2,
            2,
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.1),
                DVec2::new(0.2, 0.9),
                DVec2::new(1.3, 1.2),
            ],
        )
        .unwrap();
        let t = net.cell_triangles(0, 0);
        let d = |a: DVec2, b: DVec2| a.perp_dot(b);
        assert!((d(net.h(0, 0), net.v(0, 0)) - t[2]).abs() < 1e-14);
        assert!((d(net.h(0, 1), net.v(0, 0)) - t[1]).abs() < 1e-14);
        assert!((d(net.h(0, 0), net.v(1, 0)) - t[0]).abs() < 1e-14);
        assert!((d(net.h(0, 1), net.v(1, 0)) - t[3]).abs() < 1e-14);
    }
}
