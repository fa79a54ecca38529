//! Knot vectors and the B-spline basis: Cox–de Boor recursion and derivatives.
//!
//! Indices here are **0-based**; the paper's ([Abelló et al.]) are 1-based, so the paper's `B^k_i`
//! is [`KnotVector::basis`]`(i − 1, t)` and its knot `t_i` is `knots()[i − 1]`.
//!
//! * **Clamped uniform knots** ([`KnotVector::clamped_uniform`]): for order `k` (degree
//!   `k − 1`) and `n ≥ k` basis functions, `k` knots at 0, the `n − k` interior breakpoints
//!   `l/(n − k + 1)`, `k` knots at 1 (`n + k` knots). Order 2 gives the bilinear knots (4)/(5)
//!   `{0, ξ_1, …, ξ_n, 1}` with `ξ_i = (i−1)/(n−1)` (ends doubled); order 3 the biquadratic knots
//!   (23)/(24) `{0, 0, ξ_1, …, ξ_{n−1}, 1, 1}` with `ξ_i = (i−1)/(n−2)` (ends tripled) —
//!   [Abelló et al., §1.2, §1.3].
//! * **Cox–de Boor** ([Piegl & Tiller 1997, Ch. 2]; the paper cites de Boor without formulas):
//!   `B^1_i(t) = 1` if `t_i ≤ t < t_{i+1}` (at the right end of the
//!   domain the last non-empty interval is used), and
//!   `B^k_i = (t − t_i)/(t_{i+k−1} − t_i)·B^{k−1}_i + (t_{i+k} − t)/(t_{i+k} − t_{i+1})·B^{k−1}_{i+1}`
//!   with `0/0 := 0` ([`KnotVector::basis_of_order`], the literal recursion, and
//!   [`KnotVector::nonzero_basis`], de Boor's triangular scheme for the `k` non-zero values).
//! * **Derivatives**, eq. (33) for general order:
//!   `dB^k_i/dt = (k−1)·(B^{k−1}_i/(t_{i+k−1} − t_i) − B^{k−1}_{i+1}/(t_{i+k} − t_{i+1}))`, where
//!   the `B^{k−1}` are the lower-order B-splines **on the same knot sequence**
//!   (not the basis of the bilinear map). The uniform special case (34) holds only for `n ≥ 4`
//!   (for `n = 3`, a single interval, it is wrong); (33) is always used.
//! * **Greville abscissae** `g_i = (t_{i+1} + … + t_{i+k−1})/(k−1)`: a curve with control points
//!   `P_i = g_i` reproduces the identity (S1 check (i) of
//!   [`crate::synthetic`]).

use crate::error::BsplineError;

/// The largest supported order (the fast evaluator works on fixed-size buffers).
pub const MAX_ORDER: usize = 16;

/// A non-decreasing knot sequence for B-splines of a fixed order `k` (degree `k − 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    order: usize,
    knots: Vec<f64>,
}

impl KnotVector {
    /// A knot vector of `order ≥ 1` from explicit knots: finite, non-decreasing, at least
    /// `2·order` of them, and a non-empty domain `[t_{k−1}, t_{n}]` (0-based, `n` = number of
    /// basis functions = `knots.len() − order`).
    pub fn new(order: usize, knots: Vec<f64>) -> Result<Self, BsplineError> {
        if order == 0 || order > MAX_ORDER {
            return Err(BsplineError::Order {
                order,
                reason: "the order must be between 1 and 16",
            });
        }
        if knots.len() < 2 * order {
            return Err(BsplineError::Knots(format!(
                "order {order} needs at least {} knots, got {}",
                2 * order,
                knots.len()
            )));
        }
        if let Some(i) = knots.iter().position(|t| !t.is_finite()) {
            return Err(BsplineError::Knots(format!("knot {i} is not finite")));
        }
        if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
            return Err(BsplineError::Knots(format!(
                "knots must be non-decreasing: knot {} = {} < knot {i} = {}",
                i + 1,
                knots[i + 1],
                knots[i]
            )));
        }
        let n = knots.len() - order;
        if knots[n] <= knots[order - 1] {
            return Err(BsplineError::Knots(format!(
                "empty domain [{}, {}]",
                knots[order - 1],
                knots[n]
            )));
        }
        Ok(Self { order, knots })
    }

    /// Clamped uniform knots on `[0, 1]` for `n ≥ order` basis functions of order `order ≥ 1`
    /// (see the module docs; order 2 is (4)/(5), order 3 is (23)/(24) of [Abelló et al.]).
    pub fn clamped_uniform(order: usize, n: usize) -> Result<Self, BsplineError> {
        if order == 0 || order > MAX_ORDER {
            return Err(BsplineError::Order {
                order,
                reason: "the order must be between 1 and 16",
            });
        }
        if n < order {
            return Err(BsplineError::Count {
                what: "basis functions of a clamped knot vector",
                got: n,
                need: format!("at least the order {order}"),
            });
        }
        let pieces = n - order + 1;
        let mut knots = Vec::with_capacity(n + order);
        knots.extend(std::iter::repeat_n(0.0, order));
        for l in 1..pieces {
            knots.push(l as f64 / pieces as f64);
        }
        knots.extend(std::iter::repeat_n(1.0, order));
        Self::new(order, knots)
    }

    /// The bilinear knots (4)/(5) for `n ≥ 2` control points.
    pub fn bilinear(n: usize) -> Result<Self, BsplineError> {
        Self::clamped_uniform(2, n)
    }

    /// The biquadratic knots (23)/(24) for `n ≥ 3` control points.
    pub fn biquadratic(n: usize) -> Result<Self, BsplineError> {
        Self::clamped_uniform(3, n)
    }

    /// The order `k`.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The degree `k − 1`.
    pub fn degree(&self) -> usize {
        self.order - 1
    }

    /// The knots.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The number of basis functions (= control points) `n = #knots − k`.
    pub fn num_basis(&self) -> usize {
        self.knots.len() - self.order
    }

    /// The parameter domain `[t_{k−1}, t_n]` (0-based).
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.order - 1], self.knots[self.num_basis()])
    }

    /// The distinct breakpoints of the domain, increasing (e.g. `0, 1/(n−2), …, 1` for
    /// biquadratic knots). The intervals between them are the polynomial pieces.
    pub fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut v: Vec<f64> = Vec::new();
        for &t in &self.knots {
            if t >= a && t <= b && v.last() != Some(&t) {
                v.push(t);
            }
        }
        v
    }

    /// The knot span `μ` (0-based) with `t_μ ≤ t < t_{μ+1}` and `k−1 ≤ μ ≤ n−1`. `t` is clamped
    /// to the domain; at the right end the last non-empty interval is returned.
    pub fn span(&self, t: f64) -> usize {
        let k = self.order;
        let n = self.num_basis();
        let (a, b) = self.domain();
        let t = if t.is_nan() { a } else { t.clamp(a, b) };
        if t >= b {
            // last non-empty interval
            let mut mu = n - 1;
            while mu > k - 1 && self.knots[mu] >= self.knots[mu + 1] {
                mu -= 1;
            }
            return mu;
        }
        // binary search in [k−1, n−1]
        let (mut lo, mut hi) = (k - 1, n);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.knots[mid] <= t {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The literal Cox–de Boor recursion for `B^{order}_i(t)` on these knots (any
    /// `1 ≤ order ≤ k`, `0/0 := 0`, right-end convention of the module docs). Exponential in
    /// the order; a reference implementation for tests and for the closed forms (33)–(39) that
    /// need lower-order B-splines on the same knots.
    pub fn basis_of_order(&self, i: usize, order: usize, t: f64) -> f64 {
        let t_len = self.knots.len();
        if order == 0 || i + order > t_len {
            return 0.0;
        }
        if order == 1 {
            let (a, b) = self.domain();
            let tc = if t.is_nan() { a } else { t.clamp(a, b) };
            // B^1_i is the indicator of the span that contains t
            return if i == self.span(tc) { 1.0 } else { 0.0 };
        }
        let tk = &self.knots;
        let mut v = 0.0;
        let d1 = tk[i + order - 1] - tk[i];
        if d1 > 0.0 {
            v += (t - tk[i]) / d1 * self.basis_of_order(i, order - 1, t);
        }
        let d2 = tk[i + order] - tk[i + 1];
        if d2 > 0.0 {
            v += (tk[i + order] - t) / d2 * self.basis_of_order(i + 1, order - 1, t);
        }
        v
    }

    /// `B^k_i(t)` of the full order `k` by the literal recursion (see
    /// [`basis_of_order`](Self::basis_of_order)). `0` for `i ≥ n`.
    pub fn basis(&self, i: usize, t: f64) -> f64 {
        if i >= self.num_basis() {
            return 0.0;
        }
        self.basis_of_order(i, self.order, t)
    }

    /// Derivative `dB^k_i/dt` by eq. (33) of [Abelló et al.] generalised to order `k`:
    /// `(k−1)(B^{k−1}_i/(t_{i+k−1} − t_i) − B^{k−1}_{i+1}/(t_{i+k} − t_{i+1}))`, `0/0 := 0`.
    pub fn basis_derivative(&self, i: usize, t: f64) -> f64 {
        let k = self.order;
        if k == 1 || i >= self.num_basis() {
            return 0.0;
        }
        let tk = &self.knots;
        let mut d = 0.0;
        let d1 = tk[i + k - 1] - tk[i];
        if d1 > 0.0 {
            d += self.basis_of_order(i, k - 1, t) / d1;
        }
        let d2 = tk[i + k] - tk[i + 1];
        if d2 > 0.0 {
            d -= self.basis_of_order(i + 1, k - 1, t) / d2;
        }
        (k - 1) as f64 * d
    }

    /// The `k` basis functions that may be non-zero at `t`, `B_{μ−k+1}, …, B_μ`, written to
    /// `out[0..k]` (de Boor's triangular Cox–de Boor scheme), and their derivatives to
    /// `dout[0..k]` if given. Returns the span `μ`. `t` is clamped to the domain.
    ///
    /// # Panics
    /// If `out` (or `dout`) is shorter than the order (the order is at most [`MAX_ORDER`]).
    pub fn nonzero_basis(&self, t: f64, out: &mut [f64], dout: Option<&mut [f64]>) -> usize {
        let k = self.order;
        let mu = self.span(t);
        let (a, b) = self.domain();
        let t = if t.is_nan() { a } else { t.clamp(a, b) };
        let tk = &self.knots;
        // N[0..r+1] hold the order-(r+1) functions B_{μ−r..μ}
        let mut left = [0.0f64; MAX_ORDER];
        let mut right = [0.0f64; MAX_ORDER];
        let mut nb = [0.0f64; MAX_ORDER];
        let mut lower = [0.0f64; MAX_ORDER]; // order k−1 values for the derivative
        nb[0] = 1.0;
        for r in 1..k {
            if r == k - 1 {
                lower[..r].copy_from_slice(&nb[..r]);
            }
            left[r] = t - tk[mu + 1 - r];
            right[r] = tk[mu + r] - t;
            let mut saved = 0.0;
            for s in 0..r {
                let den = right[s + 1] + left[r - s];
                let tmp = if den != 0.0 { nb[s] / den } else { 0.0 };
                nb[s] = saved + right[s + 1] * tmp;
                saved = left[r - s] * tmp;
            }
            nb[r] = saved;
        }
        out[..k].copy_from_slice(&nb[..k]);
        if let Some(d) = dout {
            if k == 1 {
                d[0] = 0.0;
            } else {
                // lower[s] = B^{k−1}_{μ−k+2+s}, s = 0..k−1
                for s in 0..k {
                    let i = mu + 1 - k + s; // global index of B^k_i
                    let mut v = 0.0;
                    // B^{k−1}_i is lower[s−1] (if s ≥ 1)
                    if s >= 1 {
                        let den = tk[i + k - 1] - tk[i];
                        if den > 0.0 {
                            v += lower[s - 1] / den;
                        }
                    }
                    if s + 1 < k {
                        let den = tk[i + k] - tk[i + 1];
                        if den > 0.0 {
                            v -= lower[s] / den;
                        }
                    }
                    d[s] = (k - 1) as f64 * v;
                }
            }
        }
        mu
    }

    /// Greville abscissae `g_i = (t_{i+1} + … + t_{i+k−1})/(k−1)`, `i = 0..n` (for order 1 the
    /// interval midpoints).
    pub fn greville(&self) -> Vec<f64> {
        let k = self.order;
        (0..self.num_basis())
            .map(|i| {
                if k == 1 {
                    0.5 * (self.knots[i] + self.knots[i + 1])
                } else {
                    self.knots[i + 1..i + k].iter().sum::<f64>() / (k - 1) as f64
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamped_knots_match_the_paper() {
        // (4): n = 4 → {0, 0, 1/3, 2/3, 1, 1}
        let k = KnotVector::bilinear(4).unwrap();
        let want = [0.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0];
        assert_eq!(k.knots().len(), want.len());
        for (a, b) in k.knots().iter().zip(want) {
            assert!((a - b).abs() < 1e-15);
        }
        // (23): n = 5 → {0,0,0,1/3,2/3,1,1,1} (n + 3 knots, ξ_i = (i−1)/(n−2))
        let k = KnotVector::biquadratic(5).unwrap();
        assert_eq!(k.knots().len(), 8);
        assert!((k.knots()[3] - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(k.breakpoints().len(), 4);
    }

    #[test]
    fn span_right_end_and_clamping() {
        let k = KnotVector::biquadratic(5).unwrap();
        assert_eq!(k.span(0.0), 2);
        assert_eq!(k.span(0.5), 3);
        assert_eq!(k.span(1.0), 4);
        assert_eq!(k.span(7.0), 4);
        assert_eq!(k.span(-1.0), 2);
    }

    #[test]
    fn invalid_knots_are_errors() {
        assert!(KnotVector::new(2, vec![0.0, 1.0, 0.5, 1.0]).is_err());
        assert!(KnotVector::new(3, vec![0.0, 1.0]).is_err());
        assert!(KnotVector::new(2, vec![0.0, 0.0, 0.0, 0.0]).is_err());
        assert!(KnotVector::clamped_uniform(3, 2).is_err());
    }
}
