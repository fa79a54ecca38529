//! The target fit (`solve_fit`): hand-derived optima, exhaustive search on small random problems,
//! the MILP path on a non-network system and the comparison with the lower-bound solver (5.10).
//! Feasibility is checked here from the definition of (5.1)–(5.3), not with the crate's assembly.

mod common;
use common::build;
use proptest::prelude::*;
use unamalla_compat_ilp::fixtures::{grid_decomposition, thesis_example_5_1};
use unamalla_compat_ilp::{
    deviation_cost, solve, solve_fit, Block, CompatError, CompatProblem, Curve, CutPair,
    FitOptions, FitTargets, Optimality, SolveOptions, SolverPath,
};

/// `(n_b − 1)(n_l − 1)` summed over the blocks.
fn cells(p: &CompatProblem, m: &[usize]) -> usize {
    p.blocks
        .iter()
        .map(|b| {
            let pts = |s: &Vec<usize>| s.iter().map(|&j| m[j]).sum::<usize>() + 1 - s.len();
            (pts(&b.sides[0]) - 1) * (pts(&b.sides[3]) - 1)
        })
        .sum()
}

/// Feasibility of counts, straight from the definition: opposite sides carry the same number of
/// segments `Σ (m_j − 1)`, cut copies agree, `m ≥ lb`.
fn feasible(p: &CompatProblem, lb: &[usize], m: &[usize]) -> bool {
    let segs = |s: &Vec<usize>| s.iter().map(|&j| m[j] as i64 - 1).sum::<i64>();
    p.blocks
        .iter()
        .all(|b| segs(&b.sides[0]) == segs(&b.sides[2]) && segs(&b.sides[1]) == segs(&b.sides[3]))
        && p.cuts.iter().all(|c| m[c.first] == m[c.second])
        && m.iter().zip(lb).all(|(&v, &l)| v >= l.max(2))
}

/// `deviation_cost` from its definition: each unit step `k → k+1` between `n` and the minimiser
/// costs 1, 2 or 4 by the relative offset of its midpoint `|k + ½ − t| / t` (≤ ¼, ≤ ½, beyond).
fn cost_by_steps(n: usize, t: f64) -> u64 {
    let slope = |k: usize| {
        let r = (k as f64 + 0.5 - t).abs() / t;
        if r <= 0.25 {
            1
        } else if r <= 0.5 {
            2
        } else {
            4
        }
    };
    let up = |k: usize| k as f64 + 0.5 >= t; // the step k → k+1 moves away from t upward
    let mut c = 0;
    for k in n.. {
        if up(k) {
            break;
        }
        c += slope(k); // steps from n up towards t
    }
    for k in 0..n {
        if up(k) {
            c += slope(k); // steps from the minimiser up to n
        }
    }
    c
}

#[test]
fn deviation_cost_matches_its_definition() {
    for t10 in 10..400 {
        let t = t10 as f64 / 10.0 + 0.013;
        for n in 2..(3.0 * t) as usize + 4 {
            assert_eq!(
                deviation_cost(n, t),
                cost_by_steps(n, t),
                "n = {n}, t = {t}"
            );
        }
    }
    // convex on the integers
    for n in 3..60 {
        let t = 17.3;
        let d2 = deviation_cost(n + 1, t) as i64 - 2 * deviation_cost(n, t) as i64
            + deviation_cost(n - 1, t) as i64;
        assert!(d2 >= 0, "n = {n}");
    }
}

/// One tapered block (a trapezoid): bottom 10, top 5, sides 4, cell size 1.
fn tapered_block() -> CompatProblem {
    let curves = [10.0, 4.0, 5.0, 4.0]
        .iter()
        .enumerate()
        .map(|(j, &l)| Curve::new(j + 1, l))
        .collect();
    CompatProblem::new(
        curves,
        vec![Block::new(1, vec![0], vec![1], vec![2], vec![3])],
        vec![],
    )
}

#[test]
fn tapered_block_takes_the_hand_derived_optimum() {
    // t = ℓ + 1 = (11, 5, 6, 5); weights w = round(10·(ℓ_a + ℓ_b)/2): bottom/top 10·8/2 = 40,
    // right/left 10·15/2 = 75. m_r = m_l = 5 costs 0. m_b = m_t = m minimises c(m;11) + c(m;6):
    // marginals (c(m+1) − c(m)) for t = 11: −2 at m = 5..7 (midpoint offsets 5.5..3.5 ∈ (2.75, 5.5]),
    // −1 at m = 8..10; for t = 6: +1 at m = 6, 7 (offsets 0.5, 1.5 ≤ 1.5), +2 at m = 8 (2.5 ≤ 3).
    // Sum at m = 6: −2 + 1 = −1, m = 7: −1, m = 8: −1 + 2 = +1 ⇒ m = 8.
    // Cost 40·(c(8;11) + c(8;6)) = 40·(3 + 2) = 200.
    let p = tapered_block();
    let t = FitTargets::for_cell_size(&p, 1.0).unwrap();
    assert_eq!(t.weights, vec![40, 75, 40, 75]);
    let sol = solve_fit(&p, &t, &FitOptions::default()).unwrap();
    assert_eq!(sol.counts, vec![8, 5, 8, 5]);
    assert_eq!(sol.path, SolverPath::FitNetwork);
    assert_eq!(
        sol.verification.optimality,
        Optimality::FitCertified { cost: 200 }
    );
    assert_eq!(t.cost(&sol.counts), 200);
    // 7 × 4 = 28 cells for a trapezoid of area 30; (5.10) takes m_b = m_t = 11: 40 cells
    assert_eq!(cells(&p, &sol.counts), 28);
    let lb = solve(&p, &SolveOptions::cell_size(1.0)).unwrap();
    assert_eq!(lb.counts, vec![11, 5, 11, 5]);
    assert_eq!(cells(&p, &lb.counts), 40);
}

#[test]
fn a_minimum_is_enforced_and_moves_the_optimum() {
    // the same block with m_t ≥ 10: m = 10 costs 40·(c(10;11) + c(10;6)) = 40·(1 + (1+1+2+4)) = 360
    // (t = 6: steps 6, 7 cost 1, step 8 (offset 2.5 ≤ 3) 2, step 9 (3.5) 4)
    let p = tapered_block();
    let t = FitTargets::for_cell_size(&p, 1.0)
        .unwrap()
        .with_minimum(2, 10);
    let sol = solve_fit(&p, &t, &FitOptions::default()).unwrap();
    assert_eq!(sol.counts, vec![10, 5, 10, 5]);
    assert_eq!(
        sol.verification.optimality,
        Optimality::FitCertified { cost: 360 }
    );
}

/// One block whose bottom holds both copies of a cut (column coefficient 2: not a network matrix).
fn doubled_cut_block() -> CompatProblem {
    let curves = [3.0, 3.0, 2.0, 10.0, 2.0]
        .iter()
        .enumerate()
        .map(|(j, &l)| Curve::new(j + 1, l))
        .collect();
    CompatProblem::new(
        curves,
        vec![Block::new(1, vec![0, 1], vec![2], vec![3], vec![4])],
        vec![CutPair::new(0, 1)],
    )
}

#[test]
fn non_network_system_is_fitted_by_the_milp() {
    // m1 = m2 = a, m4 = 2a − 1 (bottom 2(a−1) segments = top m4 − 1), m3 = m5 = 3 (targets 3).
    // Targets (4, 4, 3, 11, 3), weights bottom/top 10·(2+2)/2 = 20. Cost/20 = 2 c(a;4) + c(2a−1;11):
    // a = 3: 2·1 + c(5;11) = 2 + 9 = 11; a = 4: 0 + c(7;11) = 5; a = 5: 2·1 + c(9;11) = 4;
    // a = 6: 2·3 + 0 = 6 ⇒ a = 5, cost 80.
    let p = doubled_cut_block();
    let t = FitTargets::for_cell_size(&p, 1.0).unwrap();
    let sol = solve_fit(&p, &t, &FitOptions::default()).unwrap();
    assert_eq!(sol.counts, vec![5, 5, 3, 9, 3]);
    assert!(matches!(sol.path, SolverPath::FitMilp(_)));
    assert!(matches!(
        sol.verification.optimality,
        Optimality::NotCertified { .. }
    ));
    assert_eq!(t.cost(&sol.counts), 80);
}

#[test]
fn infeasible_minimums_are_reported() {
    // m1 = m2 = a ⇒ m4 = 2a − 1 is odd: a pinned m4 = 4 has no solution
    let mut p = doubled_cut_block();
    p.curves[3].pinned = Some(4);
    let t = FitTargets::for_cell_size(&p, 1.0).unwrap();
    let err = solve_fit(&p, &t, &FitOptions::default()).unwrap_err();
    assert!(matches!(err, CompatError::Infeasible(_)), "{err}");
}

#[test]
fn bad_targets_are_typed_errors() {
    let p = tapered_block();
    assert!(matches!(
        FitTargets::for_cell_size(&p, 0.0),
        Err(CompatError::InvalidParameter(_))
    ));
    let mut t = FitTargets::for_cell_size(&p, 1.0).unwrap();
    t.targets[1] = f64::NAN;
    assert!(matches!(
        solve_fit(&p, &t, &FitOptions::default()),
        Err(CompatError::InvalidParameter(_))
    ));
    t.targets.pop();
    assert!(matches!(
        solve_fit(&p, &t, &FitOptions::default()),
        Err(CompatError::DimensionMismatch(_))
    ));
}

#[test]
fn thesis_example_fit_is_certified_and_never_worse_than_the_lower_bounds() {
    let p = thesis_example_5_1();
    for h in [0.05, 0.1, 0.2, 0.5] {
        let t = FitTargets::for_cell_size(&p, h).unwrap();
        let fit = solve_fit(&p, &t, &FitOptions::default()).unwrap();
        let lb = solve(&p, &SolveOptions::cell_size(h)).unwrap();
        assert!(matches!(
            fit.verification.optimality,
            Optimality::FitCertified { .. }
        ));
        assert!(feasible(&p, &[2; 17], &fit.counts));
        // the lower-bound counts are feasible for the fit, so the fit costs at most theirs
        assert!(t.cost(&fit.counts) <= t.cost(&lb.counts), "h = {h}");
    }
}

#[test]
fn grid_fits_are_certified_and_closer_to_the_area_than_the_lower_bounds() {
    // the lower-bound solver rounds every curve up and carries the largest bound of a sheet
    // across it; the fit stays near ℓ/h. Both are checked against the target cell count
    // Σ (target cells of the blocks); the fit must not be farther from it.
    for seed in 0..8 {
        let p = grid_decomposition(3, 4, seed);
        let h = 0.2;
        let t = FitTargets::for_cell_size(&p, h).unwrap();
        let fit = solve_fit(&p, &t, &FitOptions::default()).unwrap();
        assert!(matches!(
            fit.verification.optimality,
            Optimality::FitCertified { .. }
        ));
        let lb = solve(&p, &SolveOptions::cell_size(h)).unwrap();
        assert!(t.cost(&fit.counts) <= t.cost(&lb.counts));
        assert!(
            cells(&p, &fit.counts) <= cells(&p, &lb.counts),
            "seed {seed}: fit {} > lower-bound {} cells",
            cells(&p, &fit.counts),
            cells(&p, &lb.counts)
        );
    }
}

/// The minimum of the fit cost over every feasible assignment with counts in `2..=hi`
/// (cut copies enumerated as one value), or `None` when there is none.
fn exhaustive(p: &CompatProblem, t: &FitTargets, hi: usize) -> Option<u128> {
    let n = p.curves.len();
    let mut rep: Vec<usize> = (0..n).collect();
    for c in &p.cuts {
        rep[c.second] = c.first;
    }
    let free: Vec<usize> = (0..n).filter(|&j| rep[j] == j).collect();
    let mut vals = vec![2usize; free.len()];
    let mut best: Option<u128> = None;
    loop {
        let mut m = vec![0; n];
        for (i, &j) in free.iter().enumerate() {
            m[j] = vals[i];
        }
        for j in 0..n {
            m[j] = m[rep[j]];
        }
        if feasible(p, &t.minimums, &m) {
            let c = t.cost(&m);
            best = Some(best.map_or(c, |b| b.min(c)));
        }
        let mut i = 0;
        loop {
            if i == vals.len() {
                return best;
            }
            vals[i] += 1;
            if vals[i] <= hi {
                break;
            }
            vals[i] = 2;
            i += 1;
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn fit_is_optimal_against_exhaustive_search(
        nblocks in 1usize..=2,
        doubled in proptest::collection::vec(0usize..8, 0..2),
        lengths in proptest::collection::vec(0.3f64..4.0, 10),
        cut_picks in proptest::collection::vec((0usize..10, 0usize..10), 0..3),
        minimum in (0usize..10, 2usize..5),
    ) {
        let p = build(nblocks, &doubled, &lengths, &cut_picks, &[]);
        let classes = p.curves.len() - p.cuts.len();
        prop_assume!(classes <= 7);
        let hi = 8;
        let targets = FitTargets::for_cell_size(&p, 1.0)
            .unwrap()
            .with_minimum(minimum.0 % p.curves.len(), minimum.1);
        let best = exhaustive(&p, &targets, hi);
        match solve_fit(&p, &targets, &FitOptions::default()) {
            Ok(sol) => {
                prop_assert!(feasible(&p, &targets.minimums, &sol.counts));
                let cost = targets.cost(&sol.counts);
                if let Optimality::FitCertified { cost: c } = sol.verification.optimality {
                    prop_assert_eq!(c as u128, cost);
                }
                // the search covers counts ≤ hi only: the fit can only be cheaper or equal
                if let Some(b) = best {
                    prop_assert!(cost <= b, "fit {} > exhaustive {}", cost, b);
                    if sol.counts.iter().all(|&m| m <= hi) {
                        prop_assert_eq!(cost, b);
                    }
                }
                // never worse than the lower-bound solver's counts (feasible for the fit)
                if let Ok(lb) = solve(&p, &SolveOptions::cell_size(1.0)) {
                    if feasible(&p, &targets.minimums, &lb.counts) {
                        prop_assert!(cost <= targets.cost(&lb.counts));
                    }
                }
            }
            Err(CompatError::Infeasible(_)) => prop_assert!(best.is_none()),
            Err(e) => prop_assert!(false, "unexpected error {}", e),
        }
    }
}
