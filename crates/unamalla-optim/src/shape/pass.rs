//! The pass's working state and its moves: the cells around a node, their residuals, the
//! Gauss–Newton step of an interior node, the slide of a boundary node and the guards.

use unamalla_mesh::quality::quad::{corner_alphas, mu};
use unamalla_mesh::{DVec2, SegmentIndex};

use super::geometry::{centroid, Ring};
use super::{
    ShapeOptions, FD_STEP, LINE_SEARCH_HALVINGS, MAX_AROUND, MAX_STEP, SLIDE_REACH, SLIDE_SAMPLES,
};

/// `(τ − μ)₊²`.
#[inline]
pub(super) fn shortfall(target: f64, m: f64) -> f64 {
    let d = (target - m).max(0.0);
    d * d
}

/// The cells around one node and the state the guards compare against.
#[derive(Debug, Clone, Copy)]
pub(super) struct Local {
    /// `Σ (τ − μ)₊²` over the node's cells.
    pub(super) phi: f64,
    /// Smallest μ over the node's cells.
    min_mu: f64,
    /// Smallest corner α over the node's cells.
    min_alpha: f64,
    /// Bit `k`: the node's `k`-th cell has μ ≥ keep.
    pub(super) good: u64,
}

/// Residuals `(τ − μ)₊` of the cells around one node, in [`Pass::around`] order (zero-padded).
pub(super) type Residuals = [f64; MAX_AROUND];

/// The pass's working state: the cells, their incidence and orientation, the guards' data.
pub(super) struct Pass<'a> {
    pub(super) cells: &'a [[usize; 4]],
    /// Cell ids around each node (CSR: `adj[start[v]..start[v + 1]]`, in cell order).
    pub(super) start: Vec<usize>,
    adj: Vec<usize>,
    /// Orientation sign of the mesh (+1: counter-clockwise cells).
    sign: f64,
    pub(super) opts: &'a ShapeOptions,
    /// Guard 1's `ε·ᾱ`.
    alpha_floor: f64,
    /// The region's ring edges (guard 3), when a region is known.
    pub(super) index: Option<&'a SegmentIndex>,
    /// Cells with a fixed node (only their centroids can cross the boundary when an interior
    /// node moves).
    touches: Vec<bool>,
    /// Guard 4: the sum of the four corner α (four times the area) of every cell at the start.
    area0: Vec<f64>,
}

impl<'a> Pass<'a> {
    pub(super) fn new(
        x: &[DVec2],
        cells: &'a [[usize; 4]],
        fixed: &[bool],
        opts: &'a ShapeOptions,
        index: Option<&'a SegmentIndex>,
    ) -> Self {
        let nn = x.len();
        let mut start = vec![0usize; nn + 1];
        for c in cells {
            for &v in c {
                start[v + 1] += 1;
            }
        }
        for v in 0..nn {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut adj = vec![0usize; start[nn]];
        for (ci, c) in cells.iter().enumerate() {
            for &v in c {
                adj[fill[v]] = ci;
                fill[v] += 1;
            }
        }
        let total_alpha: f64 = cells
            .iter()
            .map(|q| {
                corner_alphas(&[x[q[0]], x[q[1]], x[q[2]], x[q[3]]])
                    .iter()
                    .sum::<f64>()
            })
            .sum();
        let sign = if total_alpha < 0.0 { -1.0 } else { 1.0 };
        let alpha_bar = (total_alpha * sign / (4 * cells.len().max(1)) as f64).max(0.0);
        Self {
            cells,
            start,
            adj,
            sign,
            opts,
            alpha_floor: opts.eps * alpha_bar,
            index,
            touches: cells.iter().map(|q| q.iter().any(|&w| fixed[w])).collect(),
            area0: cells
                .iter()
                .map(|q| {
                    sign * corner_alphas(&[x[q[0]], x[q[1]], x[q[2]], x[q[3]]])
                        .iter()
                        .sum::<f64>()
                })
                .collect(),
        }
    }

    pub(super) fn around(&self, v: usize) -> &[usize] {
        &self.adj[self.start[v]..self.start[v + 1]]
    }

    /// Cell `c` (counter-clockwise) with node `v` at `p`.
    pub(super) fn quad(&self, x: &[DVec2], c: usize, v: usize, p: DVec2) -> [DVec2; 4] {
        let q = self.cells[c];
        let mut pts = [x[q[0]], x[q[1]], x[q[2]], x[q[3]]];
        for k in 0..4 {
            if q[k] == v {
                pts[k] = p;
            }
        }
        if self.sign < 0.0 {
            pts.reverse();
        }
        pts
    }

    /// μ of cell `c` as it is.
    pub(super) fn cell_mu(&self, x: &[DVec2], c: usize) -> f64 {
        mu(&self.quad(x, c, usize::MAX, DVec2::ZERO))
    }

    /// The local state with node `v` at `p`, or `None` if a cell is not convex or the node
    /// has more than [`MAX_AROUND`] cells.
    pub(super) fn local(&self, x: &[DVec2], v: usize, p: DVec2) -> Option<Local> {
        let around = self.around(v);
        if around.len() > MAX_AROUND {
            return None;
        }
        let mut l = Local {
            phi: 0.0,
            min_mu: f64::INFINITY,
            min_alpha: f64::INFINITY,
            good: 0,
        };
        for (k, &c) in around.iter().enumerate() {
            let q = self.quad(x, c, v, p);
            let a = corner_alphas(&q);
            let amin = a[0].min(a[1]).min(a[2]).min(a[3]);
            if amin.is_nan() || amin <= 0.0 {
                return None;
            }
            // guard 4
            let ratio = (a[0] + a[1] + a[2] + a[3]) / self.area0[c];
            let rho = self.opts.max_area_change;
            if !(ratio * rho >= 1.0 && ratio <= rho) {
                return None;
            }
            let m = mu(&q);
            l.phi += shortfall(self.opts.target, m);
            l.min_mu = l.min_mu.min(m);
            l.min_alpha = l.min_alpha.min(amin);
            if m >= self.opts.keep {
                l.good |= 1 << k;
            }
        }
        Some(l)
    }

    /// The residuals with node `v` at `p`; `None` if a cell is not convex or the node has
    /// more than [`MAX_AROUND`] cells.
    pub(super) fn residuals(&self, x: &[DVec2], v: usize, p: DVec2) -> Option<Residuals> {
        let around = self.around(v);
        if around.len() > MAX_AROUND {
            return None;
        }
        let mut out = [0.0; MAX_AROUND];
        for (k, &c) in around.iter().enumerate() {
            let m = mu(&self.quad(x, c, v, p));
            if m.is_nan() || m <= 0.0 {
                return None;
            }
            out[k] = (self.opts.target - m).max(0.0);
        }
        Some(out)
    }

    /// Guards 1–2 of a candidate against the node's state `old`, and whether it improves on
    /// `best` (lower `Φ`, ties broken by a larger smallest μ).
    fn better(&self, old: &Local, best: &Local, cand: Option<Local>) -> Option<Local> {
        let c = cand?;
        if c.min_alpha < old.min_alpha.min(self.alpha_floor) {
            return None;
        }
        if c.min_mu < old.min_mu.min(self.opts.keep) || old.good & !c.good != 0 {
            return None;
        }
        let improves = c.phi < best.phi - 1e-15 * (1.0 + best.phi)
            || (c.phi <= best.phi && c.min_mu > best.min_mu + 1e-12);
        improves.then_some(c)
    }

    /// Guard 3: `true` if moving node `v` from `p0` to `p` moves the centroid of one of its
    /// cells across a ring edge (all its cells for a boundary node, those with a fixed node for
    /// an interior one).
    pub(super) fn crosses(&self, x: &[DVec2], v: usize, p0: DVec2, p: DVec2, all: bool) -> bool {
        let Some(index) = self.index else {
            return false;
        };
        self.around(v).iter().any(|&c| {
            (all || self.touches[c]) && {
                let c0 = centroid(&self.quad(x, c, v, p0));
                let c1 = centroid(&self.quad(x, c, v, p));
                index.intersecting(c0, c1).next().is_some()
            }
        })
    }

    /// The node's local size `ℓ`: over its cells, the smallest largest distance from the node
    /// to a corner.
    pub(super) fn size(&self, x: &[DVec2], v: usize) -> f64 {
        self.around(v)
            .iter()
            .map(|&c| {
                self.cells[c]
                    .iter()
                    .map(|&w| x[w].distance(x[v]))
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The new position of interior node `v` (state `old`, residuals `r0`): a Gauss–Newton
    /// step on `Φ = Σ r²` with the 2-column Jacobian by central differences (Levenberg-damped,
    /// at most [`MAX_STEP`]`·ℓ` long), halved until the guards pass and `Φ` decreases.
    pub(super) fn interior_move(
        &self,
        x: &[DVec2],
        v: usize,
        old: &Local,
        r0: &Residuals,
    ) -> Option<DVec2> {
        let p0 = x[v];
        let size = self.size(x, v);
        let h = FD_STEP * size;
        let mut j = [[0.0; 2]; MAX_AROUND];
        for (axis, e) in [DVec2::X, DVec2::Y].into_iter().enumerate() {
            let rp = self.residuals(x, v, p0 + h * e)?;
            let rm = self.residuals(x, v, p0 - h * e)?;
            for c in 0..MAX_AROUND {
                j[c][axis] = (rp[c] - rm[c]) / (2.0 * h);
            }
        }
        let (mut a11, mut a12, mut a22, mut g1, mut g2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for c in 0..MAX_AROUND {
            a11 += j[c][0] * j[c][0];
            a12 += j[c][0] * j[c][1];
            a22 += j[c][1] * j[c][1];
            g1 += j[c][0] * r0[c];
            g2 += j[c][1] * r0[c];
        }
        let lam = 1e-9 * (a11 + a22) + f64::MIN_POSITIVE;
        let (a11, a22) = (a11 + lam, a22 + lam);
        let det = a11 * a22 - a12 * a12;
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let mut d = -DVec2::new(a22 * g1 - a12 * g2, a11 * g2 - a12 * g1) / det;
        let len = d.length();
        if len.is_nan() || len <= 0.0 {
            return None;
        }
        if len > MAX_STEP * size {
            d *= MAX_STEP * size / len;
        }
        let mut t = 1.0;
        for _ in 0..LINE_SEARCH_HALVINGS {
            let q = p0 + t * d;
            t *= 0.5;
            if self.better(old, old, self.local(x, v, q)).is_some()
                && !self.crosses(x, v, p0, q, false)
            {
                return Some(q);
            }
        }
        None
    }

    /// The new position and arc position of boundary node `v` sliding on `ring` (its arc
    /// position `arc`, its neighbours' offsets along the ring `offs`): among the Gauss–Newton
    /// step along the arc with its halvings and [`SLIDE_SAMPLES`] samples of the reach on
    /// either side (the objective along a ring need not be unimodal), the best candidate that
    /// passes the three guards.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn slide_move(
        &self,
        x: &[DVec2],
        v: usize,
        old: &Local,
        r0: &Residuals,
        ring: &Ring,
        arc: f64,
        offs: [f64; 2],
    ) -> Option<(DVec2, f64)> {
        let (lo, hi) = (offs[0].min(offs[1]), offs[0].max(offs[1]));
        if !(lo < 0.0 && hi > 0.0) {
            return None;
        }
        let reach_hi = (SLIDE_REACH * hi).min(ring.next_feature(arc).unwrap_or(f64::INFINITY));
        let reach_lo = (SLIDE_REACH * -lo).min(ring.prev_feature(arc).unwrap_or(f64::INFINITY));
        let h = (FD_STEP * self.size(x, v))
            .min(0.5 * reach_hi)
            .min(0.5 * reach_lo);
        // the Gauss–Newton step along the arc (none if the difference quotients fail)
        let step = match (
            self.residuals(x, v, ring.at(arc + h)),
            self.residuals(x, v, ring.at(arc - h)),
        ) {
            (Some(rp), Some(rm)) if h > 0.0 => {
                let (mut jj, mut jr) = (0.0, 0.0);
                for c in 0..MAX_AROUND {
                    let jc = (rp[c] - rm[c]) / (2.0 * h);
                    jj += jc * jc;
                    jr += jc * r0[c];
                }
                let s = (-jr / (jj + f64::MIN_POSITIVE)).clamp(-reach_lo, reach_hi);
                if s.is_finite() {
                    s
                } else {
                    0.0
                }
            }
            _ => 0.0,
        };
        let gn = (0..LINE_SEARCH_HALVINGS)
            .map(|k| step * 0.5f64.powi(k as i32))
            .filter(|&o| o != 0.0);
        let samples = (1..=SLIDE_SAMPLES).flat_map(|k| {
            let f = k as f64 / SLIDE_SAMPLES as f64;
            [f * reach_hi, -f * reach_lo]
        });
        let p0 = x[v];
        let mut best = (*old, None);
        for off in gn.chain(samples) {
            let q = ring.at(arc + off);
            let Some(l) = self.better(old, &best.0, self.local(x, v, q)) else {
                continue;
            };
            if !self.crosses(x, v, p0, q, true) {
                best = (l, Some((q, arc + off)));
            }
        }
        best.1
    }
}
