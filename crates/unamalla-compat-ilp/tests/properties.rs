//! Property tests on random consistent decompositions: returned counts satisfy every equation, bound and
//! pin (checked here from the problem definition, not with the crate's own assembly), and are optimal —
//! compared with a brute-force enumeration on small cases.

use proptest::prelude::*;
mod common;
use common::build;
use unamalla_compat_ilp::fixtures::grid_decomposition;
use unamalla_compat_ilp::{solve, CompatError, CompatProblem, Method, Optimality, SolveOptions};

/// Lower bounds computed independently from the definition `max(2, d·⌈ℓ/ℓ_min⌉)`.
fn bounds(p: &CompatProblem, d: usize) -> Vec<i64> {
    let lmin = p
        .curves
        .iter()
        .map(|c| c.length)
        .fold(f64::INFINITY, f64::min);
    p.curves
        .iter()
        .map(|c| ((d as f64) * (c.length / lmin).ceil()).max(2.0) as i64)
        .collect()
}

/// Feasibility of integer counts, straight from the definition of (5.1)–(5.3) and the bounds.
fn feasible(p: &CompatProblem, lb: &[i64], m: &[i64]) -> bool {
    for b in &p.blocks {
        let sum = |s: &Vec<usize>| s.iter().map(|&j| m[j]).sum::<i64>();
        if sum(&b.sides[0]) - sum(&b.sides[2]) != b.sides[0].len() as i64 - b.sides[2].len() as i64
        {
            return false;
        }
        if sum(&b.sides[1]) - sum(&b.sides[3]) != b.sides[1].len() as i64 - b.sides[3].len() as i64
        {
            return false;
        }
    }
    for c in &p.cuts {
        if m[c.first] != m[c.second] {
            return false;
        }
    }
    p.curves.iter().enumerate().all(|(j, c)| match c.pinned {
        Some(pin) => m[j] == pin as i64,
        None => m[j] >= lb[j],
    })
}

/// Minimum of Σ m over the box `lb_j ≤ m_j ≤ lb_j + k` (pins fixed, cut copies enumerated together).
fn brute_force(p: &CompatProblem, lb: &[i64]) -> (Option<i64>, i64) {
    let n = p.curves.len();
    // classes: cut copies share a value
    let mut rep: Vec<usize> = (0..n).collect();
    for c in &p.cuts {
        rep[c.second] = c.first;
    }
    let classes: Vec<usize> = (0..n).filter(|&j| rep[j] == j).collect();
    let free: Vec<usize> = classes
        .iter()
        .copied()
        .filter(|&j| {
            p.curves[j].pinned.is_none()
                && p.curves
                    .iter()
                    .enumerate()
                    .all(|(i, c)| rep[i] != j || c.pinned.is_none())
        })
        .collect();
    let k: i64 = match free.len() {
        0..=4 => 15,
        5 => 9,
        6 => 6,
        7 => 4,
        _ => 3,
    };
    let mut m = vec![0i64; n];
    // fixed (pinned) classes take the pin of any pinned member
    for &j in &classes {
        if !free.contains(&j) {
            let pin = (0..n)
                .find(|&i| rep[i] == j && p.curves[i].pinned.is_some())
                .and_then(|i| p.curves[i].pinned)
                .unwrap_or(0) as i64;
            m[j] = pin;
        }
    }
    let base: Vec<i64> = free
        .iter()
        .map(|&j| {
            (0..n)
                .filter(|&i| rep[i] == j)
                .map(|i| lb[i])
                .max()
                .unwrap_or(2)
        })
        .collect();
    let mut offs = vec![0i64; free.len()];
    let mut best: Option<i64> = None;
    loop {
        for (t, &j) in free.iter().enumerate() {
            m[j] = base[t] + offs[t];
        }
        for i in 0..n {
            m[i] = m[rep[i]];
        }
        if feasible(p, lb, &m) {
            let obj: i64 = m.iter().sum();
            best = Some(best.map_or(obj, |b: i64| b.min(obj)));
        }
        // odometer
        let mut t = 0;
        loop {
            if t == free.len() {
                return (best, k);
            }
            offs[t] += 1;
            if offs[t] <= k {
                break;
            }
            offs[t] = 0;
            t += 1;
        }
    }
}

fn small_case() -> impl Strategy<Value = (CompatProblem, usize)> {
    (
        1usize..=2,
        prop::collection::vec(0usize..8, 0..=2),
        prop::collection::vec(prop::sample::select(vec![1.0, 1.5, 2.0, 2.5, 3.0]), 10),
        prop::collection::vec((0usize..10, 0usize..10), 0..=3),
        prop::collection::vec(prop::option::weighted(0.12, 2usize..=6), 10),
        1usize..=2,
    )
        .prop_map(|(nb, doubled, lengths, cuts, pins, d)| {
            (build(nb, &doubled, &lengths, &cuts, &pins), d)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn small_cases_match_brute_force((problem, d) in small_case()) {
        let lb = bounds(&problem, d);
        let (brute, k) = brute_force(&problem, &lb);
        for method in [Method::default(), Method::NetworkFlow] {
            let opts = SolveOptions::density(d).with_method(method);
            match solve(&problem, &opts) {
                Ok(sol) => {
                    let m: Vec<i64> = sol.counts.iter().map(|&v| v as i64).collect();
                    prop_assert!(feasible(&problem, &lb, &m), "infeasible counts {:?}", sol.counts);
                    prop_assert_eq!(sol.objective as i64, m.iter().sum::<i64>());
                    prop_assert!(sol.verification.passed());
                    if let Some(b) = brute {
                        prop_assert!(b >= sol.objective as i64, "brute force found {} < {}", b, sol.objective);
                    }
                    let in_box = m.iter().zip(&lb).enumerate().all(|(j, (&v, &l))| {
                        problem.curves[j].pinned.is_some() || v <= l + k
                    });
                    if in_box {
                        prop_assert_eq!(brute, Some(sol.objective as i64));
                    }
                }
                Err(CompatError::Infeasible(report)) => {
                    prop_assert!(brute.is_none(), "solver says infeasible, brute force found {:?}", brute);
                    prop_assert!(!report.conflict.is_empty());
                }
                Err(e) => prop_assert!(false, "unexpected error {e}"),
            }
        }
    }

    #[test]
    fn grid_decompositions_are_solved_optimally(rows in 1usize..=4, cols in 1usize..=4, seed in any::<u64>(), d in 1usize..=3) {
        let problem = grid_decomposition(rows, cols, seed);
        let a = solve(&problem, &SolveOptions::density(d)).unwrap();
        let b = solve(&problem, &SolveOptions::density(d).with_method(Method::NetworkFlow)).unwrap();
        let lb = bounds(&problem, d);
        for sol in [&a, &b] {
            let m: Vec<i64> = sol.counts.iter().map(|&v| v as i64).collect();
            prop_assert!(feasible(&problem, &lb, &m));
            let certified = matches!(sol.verification.optimality, Optimality::Certified { .. });
            prop_assert!(certified, "not certified: {:?}", sol.verification.optimality);
        }
        prop_assert_eq!(a.objective, b.objective);
        // block sizes from (5.5)/(5.6), recomputed here
        for (blk, size) in problem.blocks.iter().zip(&a.block_sizes) {
            let pts = |s: &Vec<usize>| s.iter().map(|&j| a.counts[j] - 1).sum::<usize>() + 1;
            prop_assert_eq!(size.m, pts(&blk.sides[0]));
            prop_assert_eq!(size.m, pts(&blk.sides[2]));
            prop_assert_eq!(size.n, pts(&blk.sides[1]));
            prop_assert_eq!(size.n, pts(&blk.sides[3]));
        }
    }
}
