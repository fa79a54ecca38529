//! The window tests of `StopRules` and the explicit time limit (the smoothing stops on convergence,
//! not on the clock): a run ends where the rule, applied by hand to the history of a run without
//! it, says it must.

use std::sync::Arc;

use unamalla_functionals::QuadTopology;
use unamalla_mesh::StructuredGrid2;
use unamalla_optim::drivers::{smooth, SmoothOptions};
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::monitor::{quad_mu_share, HistoryObserver, Monitor};
use unamalla_optim::solver::{SolverOptions, StopRules};
use unamalla_optim::status::{Status, StopReason};

/// (6.8) σ = 0.1 with TN-TR, every one-step test off (FTOL = GTOL = 0), so only the window
/// rule (or MAXITER) can end the run.
fn opts(stop: StopRules, max_iter: usize) -> SmoothOptions {
    SmoothOptions::default().solver(
        SolverOptions::default()
            .max_iter(max_iter)
            .ftol(0.0)
            .gtol(0.0)
            .cg_max_iter(40)
            .stop(stop),
    )
}

/// Whether the per-iteration decrease of `f` grew by half again twice up to iterate `i`
/// (`d_i ≥ 1.5·d_{i−1} ≥ 1.5²·d_{i−2} > 0`, `d_j = f_{j−1} − f_j`): the regrowth guard of the
/// window tests, written out.
fn growing(f: &[f64], i: usize) -> bool {
    let d = |j: usize| f[j - 1] - f[j];
    i >= 3 && d(i - 2) > 0.0 && d(i - 1) >= 1.5 * d(i - 2) && d(i) >= 1.5 * d(i - 1)
}

fn grid() -> StructuredGrid2 {
    sinusoidal(21, 21, 0.08, 2.0).unwrap()
}

/// The classic-phase monitors of a run (one per accepted iterate).
fn run(stop: StopRules, max_iter: usize) -> (Vec<Monitor>, Status) {
    let mut g = grid();
    let mut h = HistoryObserver::default();
    let rep = smooth(&mut g, &opts(stop, max_iter), &mut h).unwrap();
    (h.history, rep.status)
}

#[test]
fn window_ftol_stops_where_the_rule_applied_to_the_free_run_says() {
    let (free, status) = run(StopRules::default(), 60);
    assert!(
        !matches!(
            status,
            Status::Stopped {
                reason: StopReason::WindowFtol,
                ..
            }
        ),
        "without the rule it cannot fire: {status}"
    );
    let w = 5;
    let tol = 1e-4;
    // first accepted iterate k (1-based) with F_{k−w} − F_k ≤ tol·|F_k| and F's decrease not
    // regrowing (all iterates are convex: the start is ε-convex and the safeguard keeps it so)
    let f: Vec<f64> = free.iter().map(|m| m.f).collect();
    assert!(free.iter().all(|m| m.inocon == 0));
    let k = (w..f.len())
        .find(|&i| f[i - w] - f[i] <= tol * f[i].abs() && !growing(&f, i))
        .expect("the free run must flatten out within 60 iterations")
        + 1;
    assert!(
        k > w + 1,
        "the rule must not fire at the first chance ({k})"
    );
    assert!(k < free.len(), "the free run went on past {k} ({status})");
    let rule = StopRules {
        window: w,
        window_ftol: tol,
        ..StopRules::default()
    };
    let (hist, status) = run(rule, 60);
    assert_eq!(
        status,
        Status::Stopped {
            reason: StopReason::WindowFtol,
            convex: true
        }
    );
    assert_eq!(
        hist.len(),
        k,
        "stopped after iterate {k} (derived from the free run)"
    );
    // and the iterates up to there are those of the free run
    for (a, b) in hist.iter().zip(&free) {
        assert_eq!(a.f, b.f);
    }
    assert_eq!(
        status.to_string(),
        "Convex grid, STOP by WINDOW FTOL condition"
    );
}

#[test]
fn quality_plateau_stops_where_alpha_and_the_mu_share_stop_moving() {
    // the free run's α₋/ᾱ per iterate from the monitor, its μ ≥ 0.8 share from the probe at
    // the iterates (recomputed here by re-running with max_iter = k, which is the same run
    // cut at k)
    let n = 30;
    let (free, _) = run(StopRules::default(), n);
    let q: Vec<f64> = free.iter().map(|m| m.alfamin / m.alpha_bar).collect();
    let topo = Arc::new(QuadTopology::from_mesh(&grid()).unwrap());
    let probe = quad_mu_share(topo.clone());
    let share: Vec<f64> = (1..=n)
        .map(|k| {
            let mut g = grid();
            smooth(
                &mut g,
                &opts(StopRules::default(), k),
                &mut HistoryObserver::default(),
            )
            .unwrap();
            let t = QuadTopology::from_mesh(&g).unwrap();
            probe(&t.initial_x())
        })
        .collect();
    let (w, pa, ps) = (4, 0.02, 0.5);
    let spread = |v: &[f64]| {
        v.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - v.iter().cloned().fold(f64::INFINITY, f64::min)
    };
    let f: Vec<f64> = free.iter().map(|m| m.f).collect();
    let k = (w..n)
        .find(|&i| {
            if growing(&f, i) {
                return false;
            }
            let qs = &q[i - w..=i];
            let qmax = qs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            spread(qs) <= pa * qmax && spread(&share[i - w..=i]) <= ps
        })
        .expect("the quality must settle within 30 iterations")
        + 1;
    assert!(
        k > w + 1,
        "the plateau must not be there from the start ({k})"
    );
    let rule = StopRules {
        window: w,
        plateau_alpha: pa,
        plateau_share: ps,
        ..StopRules::default()
    };
    let (hist, status) = run(rule, n);
    assert_eq!(
        status,
        Status::Stopped {
            reason: StopReason::Plateau,
            convex: true
        }
    );
    assert_eq!(
        hist.len(),
        k,
        "plateau after iterate {k} (derived from the free run)"
    );
    assert_eq!(status.to_string(), "Convex grid, STOP by QUALITY PLATEAU");
}

#[test]
fn stop_rules_check_by_hand() {
    let r = StopRules {
        window: 2,
        window_ftol: 0.1,
        plateau_alpha: 0.0,
        plateau_share: 0.0,
        plateau_window: 0,
    };
    // F: 10, 9, 8.5: over two iterations 1.5 > 0.1·8.5 = 0.85 → go on; then 8.2: 0.8 ≤ 0.82
    let h = |f: &[f64]| f.iter().map(|&f| (f, 0.1, None)).collect::<Vec<_>>();
    assert_eq!(r.check(&h(&[10.0, 9.0])), None, "window not full");
    assert_eq!(r.check(&h(&[10.0, 9.0, 8.5])), None);
    assert_eq!(
        r.check(&h(&[10.0, 9.0, 8.5, 8.2])),
        Some(StopReason::WindowFtol)
    );
    let p = StopRules {
        window: 2,
        window_ftol: 0.0,
        plateau_alpha: 0.01,
        plateau_share: 0.1,
        plateau_window: 0,
    };
    // α₋/ᾱ within 1 % of its max, share within 0.1 points → plateau; a share jump of 0.2 → not
    let flat = [
        (5.0, 0.200, Some(90.0)),
        (4.0, 0.199, Some(90.05)),
        (3.0, 0.2005, Some(90.1)),
    ];
    assert_eq!(p.check(&flat), Some(StopReason::Plateau));
    let jump = [
        (5.0, 0.200, Some(90.0)),
        (4.0, 0.199, Some(90.05)),
        (3.0, 0.2005, Some(90.2)),
    ];
    assert_eq!(p.check(&jump), None);
    let alpha_moves = [
        (5.0, 0.200, Some(90.0)),
        (4.0, 0.21, Some(90.0)),
        (3.0, 0.2, Some(90.0)),
    ];
    assert_eq!(p.check(&alpha_moves), None);
    // without a quality probe the plateau test cannot fire
    let no_probe = [(5.0, 0.2, None), (4.0, 0.2, None), (3.0, 0.2, None)];
    assert_eq!(p.check(&no_probe), None);
}

/// The default rules (`unamalla_core::pipeline::DEFAULT_STOP_RULES`) on a stretch like the one
/// the gulf-of-mexico run at 20,000 cells stopped in: a step cut by the safeguard shrank the trust
/// radius from 1.39 to 7.9·10⁻⁶, and the radius then doubles after each step, so the decrease of
/// F per iteration doubles (6.6·10⁻⁷, 1.0·10⁻⁶, 2.0·10⁻⁶, …) while α₋/ᾱ stays at the floor and the
/// μ ≥ 0.8 share does not move. The old plateau (spreads only) fired there; now no test fires
/// until the decrease stops growing.
#[test]
fn no_window_test_fires_while_the_trust_region_regrows() {
    let rules = StopRules {
        window: 10,
        window_ftol: 1e-4,
        plateau_alpha: 0.01,
        plateau_share: 0.05,
        plateau_window: 10,
    };
    // F_0 = 1.45, decreases d_i = 10⁻⁶·2^(i−1), i = 1..10: over the window F falls by
    // 10⁻⁶·(2¹⁰ − 1) = 1.023·10⁻³ > 10⁻⁴·1.449 (no window FTOL); α₋/ᾱ = 0.01 and the share
    // 92.9 % throughout (spreads 0: the plateau's spreads alone are met)
    let mut f = vec![1.45];
    for i in 1..=10 {
        let d = 1e-6 * f64::powi(2.0, i - 1);
        f.push(f[f.len() - 1] - d);
    }
    let hist: Vec<(f64, f64, Option<f64>)> = f.iter().map(|&f| (f, 0.01, Some(92.9))).collect();
    assert_eq!(hist.len(), 11);
    assert!(hist[0].0 - hist[10].0 > 1e-4 * hist[10].0);
    assert!(StopRules::regrowing(&hist));
    assert_eq!(rules.check(&hist), None, "regrowing: no test fires");
    // what the rule without the regrowth guard said: the spreads are within the thresholds
    let old = |h: &[(f64, f64, Option<f64>)]| {
        let w = &h[h.len() - 11..];
        let qs = w.iter().map(|x| x.1);
        let ss = w.iter().map(|x| x.2.unwrap());
        let spread = |v: &mut dyn Iterator<Item = f64>| {
            let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
            hi - lo
        };
        spread(&mut qs.clone()) <= 0.01 * 0.01 && spread(&mut ss.clone()) <= 0.05
    };
    assert!(old(&hist), "the old plateau fired here");
    // the growth stops (the next decrease is 0.9 of the last, 5.12·10⁻⁴·0.9): the plateau fires
    let mut stopped = hist.clone();
    let last = stopped[10].0;
    stopped.push((last - 0.9 * 5.12e-4, 0.01, Some(92.9)));
    assert!(!StopRules::regrowing(&stopped));
    assert_eq!(rules.check(&stopped), Some(StopReason::Plateau));
    // a share that moves by a cell in between (0.005 points) is still a plateau, one that moves by
    // 0.06 points over the window is not
    let mut moved = stopped.clone();
    moved[5].2 = Some(92.905);
    assert_eq!(rules.check(&moved), Some(StopReason::Plateau));
    moved[11].2 = Some(92.96);
    assert_eq!(rules.check(&moved), None);
}

/// A polish run (`StopRules::polish` of the default rules: window FTOL over 2 iterations, 2·10⁻⁵)
/// keeps the plateau's window of 10 and its 0.05 points: three iterates whose shares agree within
/// one cell (0.005 points at 20,000 cells) while F still falls by 10⁻⁴ per iteration are no
/// plateau (the scaled rule, 0.01 points over 3 iterates, fired there — quintana-roo's polish run
/// at 20,000 cells stopped so at 98.46 % against 98.91 % converged).
#[test]
fn a_polish_run_keeps_the_plateau_window() {
    let p = StopRules {
        window: 10,
        window_ftol: 1e-4,
        plateau_alpha: 0.01,
        plateau_share: 0.05,
        plateau_window: 0,
    }
    .polish();
    assert_eq!((p.window, p.plateau_len(), p.history_len()), (2, 10, 11));
    // F = 1.1220, 1.1219, 1.1218 (relative decrease over two iterations 1.8·10⁻⁴ > 2·10⁻⁵);
    // shares 97.400, 97.405, 97.400; α₋/ᾱ at its floor 0.01
    let three = [
        (1.1220, 0.01, Some(97.4)),
        (1.1219, 0.01, Some(97.405)),
        (1.1218, 0.01, Some(97.4)),
    ];
    assert!(!StopRules::regrowing(&three));
    assert_eq!(p.check(&three), None, "no plateau on three iterates");
    // eleven iterates, F falling by 10⁻⁴ each, shares within 0.05 points: the plateau fires
    let eleven: Vec<(f64, f64, Option<f64>)> = (0..11)
        .map(|i| {
            let s = if i % 2 == 0 { 97.4 } else { 97.43 };
            (1.1220 - 1e-4 * i as f64, 0.01, Some(s))
        })
        .collect();
    assert_eq!(p.check(&eleven), Some(StopReason::Plateau));
    // and the window FTOL still reads two iterations: F flat over the last two fires it
    let mut flat = three.to_vec();
    flat.push((1.1218, 0.01, Some(97.5)));
    flat.push((1.1218, 0.01, Some(97.6)));
    assert_eq!(p.check(&flat), Some(StopReason::WindowFtol));
}

#[test]
fn an_explicit_time_limit_is_its_own_status_never_by_user() {
    let mut g = grid();
    let o = (opts(StopRules::default(), 1000)).time_limit(Some(0.0));
    let rep = smooth(&mut g, &o, &mut HistoryObserver::default()).unwrap();
    assert_eq!(
        rep.status,
        Status::Stopped {
            reason: StopReason::TimeLimit,
            convex: true
        }
    );
    assert_eq!(rep.status.to_string(), "Convex grid, STOP by TIME LIMIT");
    assert!(rep.iterations() <= 1, "{}", rep.iterations());
    // a bad limit is a typed error naming the option
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let o = (opts(StopRules::default(), 10)).time_limit(Some(bad));
        match smooth(&mut grid(), &o, &mut HistoryObserver::default()) {
            Err(unamalla_optim::OptimError::InvalidOption { name, .. }) => {
                assert_eq!(name, "time_limit")
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
}

#[test]
fn sigma_continuation_runs_its_stage_first_and_rejects_a_bad_sigma() {
    // a first stage at σ = 0.5 capped at 3 iterations: the classic-phase monitors start with
    // exactly three iterates of that stage (their F differs from the σ = 0.1 run's start)
    let mut o = opts(StopRules::default(), 5);
    o.sigma_continuation = vec![0.5];
    o.continuation_iter = 3;
    let mut h = HistoryObserver::default();
    let rep = smooth(&mut grid(), &o, &mut h).unwrap();
    assert_eq!(rep.iter_classic, 3 + 5, "{rep:?}");
    assert!(rep.convex);
    let (plain, _) = run(StopRules::default(), 5);
    assert_ne!(
        h.history[0].f, plain[0].f,
        "the first iterate is the σ = 0.5 stage's"
    );
    for bad in [-0.1, 1.5, f64::NAN] {
        o.sigma_continuation = vec![bad];
        match smooth(&mut grid(), &o, &mut HistoryObserver::default()) {
            Err(unamalla_optim::OptimError::InvalidOption { name, .. }) => {
                assert_eq!(name, "sigma_continuation")
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
}
