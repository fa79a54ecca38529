//! The synthetic test regions S1–S5 (our design): the four regions of [Abelló et al., §3]
//! (Lake Titicaca, a jigsaw-puzzle piece, England, Havana Bay) come without coordinates, so
//! these exactly constructible stand-ins exercise the same features. Each builds the four
//! boundary control polygons for an `n × m` net ([`BoundaryCurves`], as in
//! [`BoundaryCurves::from_ring`]: polyline vertices used directly as quadratic B-spline control
//! points, opposite sides with equal counts).
//!
//! * **S1** unit square, boundary points uniformly spaced. ([`greville_square`] gives the net
//!   at the Greville abscissae, for which the biquadratic map is the identity.)
//! * **S2** wavy square: each side of `[0,1]²` moved along its outward normal by
//!   `a·sin(2πkt)` at uniform `t`, `a = 0.04`, `k = 5`, `t` running counter-clockwise along `∂Ω`
//!   on every side. (With `t` running T→S on the north and Q→T on the west side, both
//!   neighbours of corners S and Q move inward for most `n`, and at `n = 30` the control polygon
//!   folds back on itself at S.)
//! * **S3** star-shaped lake `r(θ) = 1 + 0.25 sin 7θ + 0.1 cos 13θ`, each side sampled uniformly in
//!   θ. **Deviation** from the first design: with corners at `θ = −3π/4, −π/4, π/4, 3π/4` the
//!   corners R and S are reflex vertices of the control polygon (the curve is locally concave
//!   there: `r² + 2r'² − r r'' < 0`), so no convex net can exist; [`star_literal`] keeps that
//!   variant as a negative test. [`Synthetic::S3Star`] moves each corner to the maximum of
//!   `r² + 2r'² − r r''` within 0.2 rad of those angles:
//!   `θ_Q = −2.412, θ_R = −0.585, θ_S = 0.963, θ_T = 2.408`.
//! * **S4** puzzle piece: the unit square with a knob on the south and east sides and a notch on
//!   the north and west sides. Knob: a neck of width 0.12 and length 0.1 leaving the side at its
//!   midpoint, ending in a circle of radius 0.15 through the neck's ends (centre
//!   `0.1 + √(0.15² − 0.06²) ≈ 0.2375` from the side). **Deviation** from the first design, which
//!   put the centre 0.1 from the side: then the circle crosses the side and no neck forms. The
//!   outline is resampled by arc length to `n` (`m`) points per side.
//! * **S5** bay: the rectangle `[0, 1.5] × [0, 1]` whose north side has an inlet 0.1 wide and
//!   0.6 deep centred at `x = 0.75`, resampled by arc length.

use std::f64::consts::{FRAC_PI_4, TAU};

use glam::DVec2;
use unamalla_mesh::resample_arc_length;

use crate::error::BsplineError;
use crate::knots::KnotVector;
use crate::net::{BoundaryCurves, ControlNet};

/// One of the synthetic regions S1–S5.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Synthetic {
    /// S1 unit square.
    S1Square,
    /// S2 wavy square.
    S2Wavy,
    /// S3 star-shaped lake.
    S3Star,
    /// S4 puzzle piece.
    S4Puzzle,
    /// S5 bay with a narrow inlet.
    S5Bay,
}

impl Synthetic {
    /// All five, in order.
    pub const ALL: [Synthetic; 5] = [
        Synthetic::S1Square,
        Synthetic::S2Wavy,
        Synthetic::S3Star,
        Synthetic::S4Puzzle,
        Synthetic::S5Bay,
    ];

    /// Short name (`S1` … `S5`).
    pub fn name(self) -> &'static str {
        match self {
            Synthetic::S1Square => "S1",
            Synthetic::S2Wavy => "S2",
            Synthetic::S3Star => "S3",
            Synthetic::S4Puzzle => "S4",
            Synthetic::S5Bay => "S5",
        }
    }

    /// One-line description.
    pub fn description(self) -> &'static str {
        match self {
            Synthetic::S1Square => "unit square",
            Synthetic::S2Wavy => "wavy square (a = 0.04, k = 5)",
            Synthetic::S3Star => "star lake r = 1 + 0.25 sin 7θ + 0.1 cos 13θ",
            Synthetic::S4Puzzle => "puzzle piece (2 knobs, 2 notches)",
            Synthetic::S5Bay => "bay: 1.5 × 1 rectangle, inlet 0.1 × 0.6",
        }
    }

    /// The boundary control polygons for an `n × m` net (`n, m ≥ 3`).
    pub fn boundary(self, n: usize, m: usize) -> Result<BoundaryCurves, BsplineError> {
        if n < 3 || m < 3 {
            return Err(BsplineError::Count {
                what: "synthetic region net",
                got: n.min(m),
                need: "at least 3 × 3".into(),
            });
        }
        match self {
            Synthetic::S1Square => {
                let u = |k: usize, c: usize| k as f64 / (c - 1) as f64;
                Ok(BoundaryCurves {
                    south: (0..n).map(|i| DVec2::new(u(i, n), 0.0)).collect(),
                    east: (0..m).map(|j| DVec2::new(1.0, u(j, m))).collect(),
                    north: (0..n).map(|i| DVec2::new(u(i, n), 1.0)).collect(),
                    west: (0..m).map(|j| DVec2::new(0.0, u(j, m))).collect(),
                })
            }
            Synthetic::S2Wavy => {
                let (a, k) = (0.04, 5.0);
                // exactly 0 at the corners (sin 2πk is not 0 in floating point)
                let w = |t: f64| {
                    if t <= 0.0 || t >= 1.0 {
                        0.0
                    } else {
                        a * (TAU * k * t).sin()
                    }
                };
                let u = |l: usize, c: usize| l as f64 / (c - 1) as f64;
                Ok(BoundaryCurves {
                    south: (0..n).map(|i| DVec2::new(u(i, n), -w(u(i, n)))).collect(),
                    east: (0..m)
                        .map(|j| DVec2::new(1.0 + w(u(j, m)), u(j, m)))
                        .collect(),
                    // t runs counter-clockwise on every side: T→S and Q→T are reversed
                    north: (0..n)
                        .map(|i| DVec2::new(u(i, n), 1.0 + w(1.0 - u(i, n))))
                        .collect(),
                    west: (0..m)
                        .map(|j| DVec2::new(-w(1.0 - u(j, m)), u(j, m)))
                        .collect(),
                })
            }
            Synthetic::S3Star => Ok(star([-2.412, -0.585, 0.963, 2.408], n, m)),
            Synthetic::S4Puzzle => {
                let c = [
                    DVec2::new(0.0, 0.0),
                    DVec2::new(1.0, 0.0),
                    DVec2::new(1.0, 1.0),
                    DVec2::new(0.0, 1.0),
                ];
                // counter-clockwise pieces: south and east knobs (+1), north and west notches (−1)
                let south = knob_side(c[0], c[1], 1.0);
                let east = knob_side(c[1], c[2], 1.0);
                let north = knob_side(c[2], c[3], -1.0);
                let west = knob_side(c[3], c[0], -1.0);
                from_ccw_pieces(&south, &east, &north, &west, n, m)
            }
            Synthetic::S5Bay => {
                let wdt = 1.5;
                let south = [DVec2::new(0.0, 0.0), DVec2::new(wdt, 0.0)];
                let east = [DVec2::new(wdt, 0.0), DVec2::new(wdt, 1.0)];
                let north = [
                    DVec2::new(wdt, 1.0),
                    DVec2::new(0.8, 1.0),
                    DVec2::new(0.8, 0.4),
                    DVec2::new(0.7, 0.4),
                    DVec2::new(0.7, 1.0),
                    DVec2::new(0.0, 1.0),
                ];
                let west = [DVec2::new(0.0, 1.0), DVec2::new(0.0, 0.0)];
                from_ccw_pieces(&south, &east, &north, &west, n, m)
            }
        }
    }
}

/// S3 with the literal corners `θ = −3π/4, −π/4, π/4, 3π/4` (reflex corners R and S:
/// a negative test, [`BoundaryCurves::validate`] rejects it).
pub fn star_literal(n: usize, m: usize) -> BoundaryCurves {
    star(
        [-3.0 * FRAC_PI_4, -FRAC_PI_4, FRAC_PI_4, 3.0 * FRAC_PI_4],
        n,
        m,
    )
}

fn star(theta: [f64; 4], n: usize, m: usize) -> BoundaryCurves {
    let r = |t: f64| 1.0 + 0.25 * (7.0 * t).sin() + 0.1 * (13.0 * t).cos();
    let p = |t: f64| r(t) * DVec2::new(t.cos(), t.sin());
    let side = |a: f64, b: f64, k: usize| -> Vec<DVec2> {
        (0..k)
            .map(|l| p(a + (b - a) * l as f64 / (k - 1) as f64))
            .collect()
    };
    let [q, rr, s, t] = theta;
    let mut south = side(q, rr, n);
    let mut east = side(rr, s, m);
    let mut north = side(t, s, n);
    let mut west = side(q, t - TAU, m);
    // exact shared corners
    let (pq, pr, ps, pt) = (south[0], south[n - 1], east[m - 1], north[0]);
    east[0] = pr;
    north[n - 1] = ps;
    west[0] = pq;
    west[m - 1] = pt;
    south[0] = pq;
    BoundaryCurves {
        south,
        east,
        north,
        west,
    }
}

/// A straight side `a → b` (counter-clockwise ring order) with a knob (`sign = +1`, outward) or a
/// notch (`−1`, inward) at its midpoint, finely sampled.
fn knob_side(a: DVec2, b: DVec2, sign: f64) -> Vec<DVec2> {
    let len = a.distance(b);
    let d = (b - a) / len;
    let out = DVec2::new(d.y, -d.x); // right of d = outward for a counter-clockwise ring
    let y_dir = sign * out;
    let at = |x: f64, y: f64| a + x * len * d + y * len * y_dir;
    let (w2, neck, rad): (f64, f64, f64) = (0.06, 0.1, 0.15);
    let h = (rad * rad - w2 * w2).sqrt();
    let cy = neck + h;
    let mut v = Vec::new();
    let lin = |v: &mut Vec<DVec2>, p: DVec2, q: DVec2, k: usize| {
        for l in 0..k {
            v.push(p + (q - p) * (l as f64 / k as f64));
        }
    };
    lin(&mut v, at(0.0, 0.0), at(0.5 - w2, 0.0), 60);
    lin(&mut v, at(0.5 - w2, 0.0), at(0.5 - w2, neck), 12);
    // arc from angle θs + 2π down to θe in the local frame (x along d, y along y_dir)
    let ts = (-h).atan2(-w2) + TAU;
    let te = (-h).atan2(w2);
    let k = 120;
    for l in 0..k {
        let t = ts + (te - ts) * l as f64 / k as f64;
        v.push(at(0.5 + rad * t.cos(), cy + rad * t.sin()));
    }
    lin(&mut v, at(0.5 + w2, neck), at(0.5 + w2, 0.0), 12);
    lin(&mut v, at(0.5 + w2, 0.0), at(1.0, 0.0), 60);
    v.push(at(1.0, 0.0));
    v
}

/// Resamples four counter-clockwise ring pieces (south Q→R, east R→S, north S→T, west T→Q) by
/// arc length and orients north (T→S) and west (Q→T) as [`BoundaryCurves`] expects.
fn from_ccw_pieces(
    south: &[DVec2],
    east: &[DVec2],
    north: &[DVec2],
    west: &[DVec2],
    n: usize,
    m: usize,
) -> Result<BoundaryCurves, BsplineError> {
    let s = resample_arc_length(south, n)?;
    let e = resample_arc_length(east, m)?;
    let mut nn = resample_arc_length(north, n)?;
    let mut w = resample_arc_length(west, m)?;
    nn.reverse();
    w.reverse();
    Ok(BoundaryCurves {
        south: s,
        east: e,
        north: nn,
        west: w,
    })
}

/// S1 check (i): the `n × m` net at the Greville abscissae of the biquadratic knots, for which
/// the biquadratic map is the identity of `[0,1]²` (`det J ≡ 1`).
pub fn greville_square(n: usize, m: usize) -> Result<ControlNet, BsplineError> {
    let gx = KnotVector::biquadratic(n)?.greville();
    let gy = KnotVector::biquadratic(m)?.greville();
    ControlNet::from_fn(n, m, |i, j| DVec2::new(gx[i], gy[j]))
}

/// S1 check (ii): the square net with uniformly spaced points `(i/(n−1), j/(m−1))`.
pub fn uniform_square(n: usize, m: usize) -> Result<ControlNet, BsplineError> {
    ControlNet::from_fn(n, m, |i, j| {
        DVec2::new(i as f64 / (n - 1) as f64, j as f64 / (m - 1) as f64)
    })
}
