//! Example 5.1 of the thesis ([Méndez 2023, §5.2.2], Fig 5.1): 3 blocks, 2 cuts, 17 curves.
//!
//! Assembles `A m = b`, prints the equations next to the ones printed in the thesis, solves
//! problem (5.10) with density d = 1 and prints `m1 .. m17`, the objective and the block sizes `M_k × N_k`.
//! Finally shows the error for a deliberately infeasible variant (pinned `m9 = 4`).
//!
//! Run: `cargo run -p unamalla-compat-ilp --example thesis_example_5_1`

use unamalla_compat_ilp::fixtures::thesis_example_5_1;
use unamalla_compat_ilp::{solve, CompatError, CompatSystem, SolveOptions};

/// An equation as printed in the thesis: text, `(curve id, coefficient)` terms, right-hand side.
type PrintedEquation = (&'static str, &'static [(usize, i64)], i64);

fn main() -> Result<(), CompatError> {
    let problem = thesis_example_5_1();
    println!(
        "Fig 5.1 topology: {} blocks, {} cuts, {} curves",
        problem.num_blocks(),
        problem.cuts.len(),
        problem.num_curves()
    );
    for b in &problem.blocks {
        let ids = |s: &[usize]| {
            s.iter()
                .map(|&j| format!("Q{}", problem.curves[j].id))
                .collect::<Vec<_>>()
                .join("+")
        };
        println!(
            "  block {}: b = {}, r = {}, t = {}, l = {}",
            b.id,
            ids(&b.sides[0]),
            ids(&b.sides[1]),
            ids(&b.sides[2]),
            ids(&b.sides[3])
        );
    }
    let system = CompatSystem::assemble(&problem)?;
    println!("\nCompatibility system A m = b (rows in the b,r,t,l order of (5.4)):");
    print!("{system}");

    // The 8 equations printed in the thesis, as (curve id, coefficient) lists and right-hand sides.
    let printed: [PrintedEquation; 8] = [
        ("m1 − m3 = 0", &[(1, 1), (3, -1)], 0),
        ("m2 − m4 = 0", &[(2, 1), (4, -1)], 0),
        ("m5 − m9 = 0", &[(5, 1), (9, -1)], 0),
        (
            "m6 + m7 + m8 − m10 − m11 − m12 = 0",
            &[(6, 1), (7, 1), (8, 1), (10, -1), (11, -1), (12, -1)],
            0,
        ),
        ("m14 − m16 − m17 = −1", &[(14, 1), (16, -1), (17, -1)], -1),
        ("m13 − m15 = 0", &[(13, 1), (15, -1)], 0),
        ("−m2 + m11 = 0", &[(2, -1), (11, 1)], 0),
        ("−m7 + m17 = 0", &[(7, -1), (17, 1)], 0),
    ];
    let a = system.matrix();
    let b = system.rhs();
    println!("\nAs printed in the thesis (Example 5.1), compared with the assembled rows:");
    for (row, (text, coefs, rhs)) in printed.iter().enumerate() {
        let mut thesis_row = vec![0i64; problem.num_curves()];
        for &(id, c) in coefs.iter() {
            thesis_row[id - 1] = c; // ids are 1..=17 at indices 0..=16
        }
        let negated: Vec<i64> = thesis_row.iter().map(|v| -v).collect();
        let verdict = if a[row] == thesis_row && b[row] == *rhs {
            "same coefficients and right-hand side"
        } else if a[row] == negated && b[row] == -rhs {
            "same equation multiplied by −1"
        } else {
            "DIFFERENT"
        };
        println!(
            "  {text:<36} vs {:<36} {verdict}",
            system.format_equation(row)
        );
    }

    let sol = solve(&problem, &SolveOptions::density(1))?;
    println!("\nProblem (5.10) with density d = 1:");
    let counts: Vec<String> = sol
        .counts
        .iter()
        .zip(&problem.curves)
        .map(|(m, c)| format!("m{} = {m}", c.id))
        .collect();
    for chunk in counts.chunks(6) {
        println!("  {}", chunk.join(", "));
    }
    println!("  objective Σ m_j = {}", sol.objective);
    for bs in &sol.block_sizes {
        println!("  block {}: {} × {}", bs.block, bs.m, bs.n);
    }
    println!("  solver path: {}", sol.path);
    for r in &sol.rejected {
        println!("  (rejected: {r})");
    }
    println!(
        "  verification: integral = {}, equations = {}, bounds = {}, pins = {}, optimality = {:?}",
        sol.verification.integral,
        sol.verification.equations_satisfied,
        sol.verification.bounds_satisfied,
        sol.verification.pins_satisfied,
        sol.verification.optimality
    );

    let mut bad = problem.clone();
    bad.curves[8].pinned = Some(4); // m9 = 4, while ℓ5 forces m5 ≥ 8 and m5 = m9
    println!("\nInfeasible variant (pin m9 = 4):");
    match solve(&bad, &SolveOptions::density(1)) {
        Err(e) => println!("  error: {e}"),
        Ok(s) => println!("  unexpectedly solved: {:?}", s.counts),
    }
    Ok(())
}
