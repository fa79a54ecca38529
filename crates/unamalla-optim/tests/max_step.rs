//! The fraction-to-the-boundary step (`Session::max_step`, `Session::max_step_within`) against
//! a brute-force search: along `x + t·d` the first `t` at which some corner triangle of a cell
//! with a free node reaches the safeguard's threshold, found by scanning `t` on a fine grid and
//! bisecting the first sign change of `min α(t) − thr`.

use std::sync::Arc;

use proptest::prelude::*;
use unamalla_functionals::prelude::*;
use unamalla_functionals::{Length, QuadFunctional, QuadTopology};
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::monitor::{NullObserver, Session};

/// `min α(x + t·d)` over the corner triangles that move (have a free node).
fn min_measure(p: &QuadFunctional, moving: &[bool], x: &[f64], d: &[f64], t: f64) -> f64 {
    let xt: Vec<f64> = x.iter().zip(d).map(|(a, b)| a + t * b).collect();
    let mut m = vec![0.0; p.num_elements()];
    p.element_measures(&xt, &mut m);
    m.iter()
        .zip(moving)
        .filter(|(_, &k)| k)
        .map(|(v, _)| *v)
        .fold(f64::INFINITY, f64::min)
}

/// The first crossing of `thr` on `(0, t_max]` by scanning 4000 steps and bisecting (`∞` if
/// none).
fn brute_force(
    p: &QuadFunctional,
    moving: &[bool],
    x: &[f64],
    d: &[f64],
    thr: f64,
    t_max: f64,
) -> f64 {
    let n = 4000;
    let mut lo = 0.0;
    for k in 1..=n {
        let t = t_max * k as f64 / n as f64;
        if min_measure(p, moving, x, d, t) <= thr {
            let mut hi = t;
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if min_measure(p, moving, x, d, mid) <= thr {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return hi;
        }
        lo = t;
    }
    f64::INFINITY
}

fn setup() -> (QuadFunctional, Vec<f64>, Vec<bool>) {
    let g = sinusoidal(9, 9, 0.1, 1.0).expect("grid");
    let topo = Arc::new(QuadTopology::from_mesh(&g).expect("topology"));
    let x = topo.initial_x();
    let p = QuadFunctional::new(topo, Length);
    // the triangles that move: their measure changes when the free variables move (by
    // different amounts: a translation of all three nodes would not change a triangle)
    let mut a = vec![0.0; p.num_elements()];
    let mut b = vec![0.0; p.num_elements()];
    p.element_measures(&x, &mut a);
    let xp: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * (1.0 + (i % 7) as f64))
        .collect();
    p.element_measures(&xp, &mut b);
    let moving = a.iter().zip(&b).map(|(u, v)| u != v).collect();
    (p, x, moving)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// For random directions (each free coordinate in `[−s, s]`, `s` a tenth to twice the
    /// cell width): `max_step` is the brute-force first crossing of the threshold, and
    /// `max_step_within(h)` agrees with it below `h` and is at least `h` otherwise.
    #[test]
    fn the_fraction_to_the_boundary_step_is_the_first_crossing(
        seed in any::<u64>(),
        scale in 0.1f64..2.0,
        horizon in 0.25f64..3.0,
        thr_share in 0.0f64..0.5,
    ) {
        let (p, x, moving) = setup();
        let h = 1.0 / 8.0;
        let mut state = seed | 1;
        let d: Vec<f64> = (0..x.len())
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                scale * h * (2.0 * ((state >> 11) as f64 / (1u64 << 53) as f64) - 1.0)
            })
            .collect();
        let mut obs = NullObserver;
        let mut session = Session::new(&p, &x, &mut obs);
        let a0 = session.masked_min(&p, &x);
        session.guard_threshold = thr_share * a0;
        prop_assert!(session.guard_active(a0));
        let thr = session.threshold();
        let t = session.max_step(&p, &x, &d);
        let expected = brute_force(&p, &moving, &x, &d, thr, 8.0);
        if expected.is_finite() {
            prop_assert!((t - expected).abs() <= 1e-6 * expected.max(1e-3), "t {t} vs {expected}");
        } else {
            prop_assert!(t > 8.0 * (1.0 - 1.0 / 4000.0), "t {t}, no crossing up to 8");
        }
        let tw = session.max_step_within(&p, &x, &d, horizon);
        if t < horizon {
            prop_assert_eq!(tw, t);
        } else {
            prop_assert!(tw >= horizon, "within {tw} < horizon {horizon} (exact {t})");
        }
    }
}
