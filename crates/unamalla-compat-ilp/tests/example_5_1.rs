//! Example 5.1 of the thesis [Méndez 2023, §5.2.2]: equations, d = 1 solution, block sizes, and
//! hand-derived variants (d = 2, cell size, pins). Expected values come from the thesis or are derived
//! by hand in the comments (the block sizes by (5.5)/(5.6)), never from this crate's output.

use std::collections::BTreeMap;

use unamalla_compat_ilp::fixtures::thesis_example_5_1;
use unamalla_compat_ilp::{
    block_sizes, solve, CompatSystem, LowerBounds, Method, Optimality, SolveOptions, SolverPath,
};

/// The thesis' d = 1 counts m1..m17 ([Méndez 2023, Example 5.1]).
const THESIS_M: [usize; 17] = [6, 6, 6, 6, 8, 6, 6, 6, 8, 8, 6, 4, 8, 8, 8, 3, 6];

/// The 8 printed equations as (curve id → coefficient, rhs).
fn printed() -> Vec<(BTreeMap<usize, i64>, i64)> {
    let eq = |plus: &[usize], minus: &[usize], rhs: i64| {
        let mut m = BTreeMap::new();
        for &p in plus {
            m.insert(p, 1);
        }
        for &q in minus {
            m.insert(q, -1);
        }
        (m, rhs)
    };
    vec![
        eq(&[1], &[3], 0),
        eq(&[2], &[4], 0),
        eq(&[5], &[9], 0),
        eq(&[6, 7, 8], &[10, 11, 12], 0),
        eq(&[14], &[16, 17], -1),
        eq(&[13], &[15], 0),
        eq(&[11], &[2], 0),
        eq(&[17], &[7], 0),
    ]
}

#[test]
fn assembled_rows_are_the_printed_equations() {
    let p = thesis_example_5_1();
    assert_eq!(p.num_blocks(), 3);
    assert_eq!(p.cuts.len(), 2);
    assert_eq!(p.num_curves(), 17);
    let sys = CompatSystem::assemble(&p).unwrap();
    assert_eq!(sys.equations.len(), 2 * 3 + 2);
    let a = sys.matrix();
    let b = sys.rhs();
    for (row, (coefs, rhs)) in printed().into_iter().enumerate() {
        let ours: BTreeMap<usize, i64> = a[row]
            .iter()
            .enumerate()
            .filter(|(_, &v)| v != 0)
            .map(|(j, &v)| (p.curves[j].id, v))
            .collect();
        let neg: BTreeMap<usize, i64> = coefs.iter().map(|(&k, &v)| (k, -v)).collect();
        assert!(
            (ours == coefs && b[row] == rhs) || (ours == neg && b[row] == -rhs),
            "row {row}: {ours:?} = {} vs printed {coefs:?} = {rhs}",
            b[row]
        );
    }
}

#[test]
fn printed_text_of_block_rows_matches_the_thesis() {
    let sys = CompatSystem::assemble(&thesis_example_5_1()).unwrap();
    let expected = [
        "m1 − m3 = 0",
        "m2 − m4 = 0",
        "m5 − m9 = 0",
        "m6 + m7 + m8 − m10 − m11 − m12 = 0",
        "m14 − m16 − m17 = −1",
        "m13 − m15 = 0",
    ];
    for (row, e) in expected.iter().enumerate() {
        assert_eq!(&sys.format_equation(row), e);
    }
    // cut rows: the thesis prints −m2 + m11 = 0 and −m7 + m17 = 0; we print ι first
    assert_eq!(sys.format_equation(6), "m11 − m2 = 0");
    assert_eq!(sys.format_equation(7), "m17 − m7 = 0");
}

#[test]
fn thesis_counts_satisfy_the_system_and_give_the_block_sizes() {
    let p = thesis_example_5_1();
    let sys = CompatSystem::assemble(&p).unwrap();
    assert!(sys.is_satisfied(&THESIS_M));
    // (5.5)/(5.6) by hand: block1 M = 6, N = 6; block2 M = m5 = 8, N = 6+6+6 − 3 + 1 = 16;
    // block3 M = m14 = 8, N = m13 = 8.
    let sizes = block_sizes(&p, &THESIS_M).unwrap();
    let got: Vec<(usize, usize, usize)> = sizes.iter().map(|s| (s.block, s.m, s.n)).collect();
    assert_eq!(got, vec![(1, 6, 6), (2, 8, 16), (3, 8, 8)]);
}

#[test]
fn d1_reproduces_the_thesis_solution() {
    let p = thesis_example_5_1();
    for method in [Method::default(), Method::NetworkFlow] {
        let sol = solve(&p, &SolveOptions::density(1).with_method(method)).unwrap();
        assert_eq!(sol.counts, THESIS_M.to_vec(), "{method:?}");
        // 4·6 + (8+6+6+6+8+8+6+4) + (8+8+8+3+6) = 24 + 52 + 33
        assert_eq!(sol.objective, 109);
        assert_eq!(sol.objective as usize, THESIS_M.iter().sum::<usize>());
        let got: Vec<(usize, usize)> = sol.block_sizes.iter().map(|s| (s.m, s.n)).collect();
        assert_eq!(got, vec![(6, 6), (8, 16), (8, 8)]);
        assert!(sol.verification.passed());
        assert_eq!(
            sol.verification.optimality,
            Optimality::Certified { dual_bound: 109 }
        );
    }
}

#[test]
fn default_method_uses_microlp_directly() {
    let sol = solve(&thesis_example_5_1(), &SolveOptions::density(1)).unwrap();
    // microlp may be rejected by verification (then a fallback is recorded); either way the path is named
    if sol.rejected.is_empty() {
        assert_eq!(
            sol.path,
            SolverPath::DirectMilp(unamalla_compat_ilp::MilpBackend::Microlp)
        );
    }
}

#[test]
fn d2_doubles_the_bounds() {
    // L_j = 2 m_j (j ≠ 16), L16 = 2. All curves but Q16 at their bound is feasible with
    // m16 = m14 − m17 + 1 = 16 − 12 + 1 = 5, and every other feasible point costs more
    // (raising m17 = m7 by one lowers m16 by one but raises m7 and a left curve of block 2).
    let p = thesis_example_5_1();
    let sol = solve(&p, &SolveOptions::density(2)).unwrap();
    let mut expected: Vec<usize> = THESIS_M.iter().map(|m| 2 * m).collect();
    expected[15] = 5;
    assert_eq!(sol.counts, expected);
    assert_eq!(sol.objective, 2 * (109 - 3) + 5);
}

#[test]
fn cell_size_mode() {
    // h = 1: L_j = ⌈ℓ_j⌉ + 1 = m_j + 1 (ℓ_j = m_j − ½), L16 = ⌈1⌉ + 1 = 2;
    // m16 = (8+1) − (6+1) + 1 = 3; objective = (109 − 3 + 16) + 3 = 125.
    let p = thesis_example_5_1();
    let sol = solve(&p, &SolveOptions::cell_size(1.0)).unwrap();
    let mut expected: Vec<usize> = THESIS_M.iter().map(|m| m + 1).collect();
    expected[15] = 3;
    assert_eq!(sol.counts, expected);
    assert_eq!(sol.objective, 125);
    assert_eq!(
        LowerBounds::CellSize(1.0).compute(&p).unwrap()[15],
        2,
        "shortest curve"
    );
}

#[test]
fn pinned_count_moves_the_optimum() {
    // Pin m12 = 5: block 2's left side grows by one, so its right side must too: either m6 or m8 + 1
    // (+2 in total) or m7 = m17 + 1 with m16 − 1 (+1 +1 +1 −1 = +2). Optimum 109 + 2 = 111.
    let mut p = thesis_example_5_1();
    p.curves[11].pinned = Some(5);
    let sol = solve(&p, &SolveOptions::density(1)).unwrap();
    assert_eq!(sol.counts[11], 5);
    assert_eq!(sol.objective, 111);
    assert!(sol.verification.passed());
}

#[cfg(feature = "cbc")]
#[test]
fn d1_with_cbc() {
    let opts =
        SolveOptions::density(1).with_method(Method::Milp(unamalla_compat_ilp::MilpBackend::Cbc));
    let sol = solve(&thesis_example_5_1(), &opts).unwrap();
    assert_eq!(sol.counts, THESIS_M.to_vec());
    assert_eq!(sol.objective, 109);
}
