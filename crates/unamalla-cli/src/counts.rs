//! `unamalla counts`: solve the compatibility program (5.10) of a decomposition given as a
//! JSON [`CompatProblem`] (curves with lengths and optional pinned counts, blocks with four
//! sides, cut pairs; the serde form of `unamalla_compat_ilp::CompatProblem`), and print or
//! write the compatible point counts. An infeasible program (e.g. contradictory pins) is
//! reported as one error line naming the conflicting constraints ([Méndez 2023,
//! §5.2.1]; equalities plus lower bounds can have no solution).

use std::path::PathBuf;

use anyhow::{Context, Result};
use unamalla_core::compat_ilp::{self as ilp, CompatProblem};

/// Arguments of `unamalla counts`.
#[derive(clap::Args, Debug)]
pub struct CountsArgs {
    /// Compatibility problem (JSON: `curves`, `blocks`, `cuts`).
    problem: PathBuf,
    /// Density factor d of (5.9) (default 1).
    #[arg(long, conflicts_with = "cell_size")]
    density: Option<usize>,
    /// Target cell size h instead of a density factor.
    #[arg(long)]
    cell_size: Option<f64>,
    /// Write the solution (counts, block sizes, verification) as JSON here; otherwise it is
    /// printed on stdout.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Runs `unamalla counts`.
pub fn run(a: CountsArgs) -> Result<()> {
    let text = std::fs::read_to_string(&a.problem)
        .with_context(|| format!("reading {}", a.problem.display()))?;
    let problem: CompatProblem = serde_json::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{}:{}:{}: not a compatibility problem: {}",
            a.problem.display(),
            e.line(),
            e.column(),
            e
        )
    })?;
    let opts = match (a.density, a.cell_size) {
        (_, Some(h)) if !(h.is_finite() && h > 0.0) => {
            crate::reliability::usage!("--cell-size must be a positive number")
        }
        (_, Some(h)) => ilp::SolveOptions::cell_size(h),
        (Some(d), _) => ilp::SolveOptions::density(d),
        (None, None) => ilp::SolveOptions::density(1),
    };
    let sol = ilp::solve(&problem, &opts)
        .with_context(|| format!("{}: compatible counts", a.problem.display()))?;
    let json = serde_json::to_string_pretty(&serde_json::json!({
        "counts": problem.curves.iter().zip(&sol.counts)
            .map(|(c, m)| serde_json::json!({"curve": c.id, "count": m}))
            .collect::<Vec<_>>(),
        "objective": sol.objective,
        "block_sizes": sol.block_sizes,
        "path": sol.path.to_string(),
        "verified": sol.verification.passed(),
    }))?;
    match &a.output {
        Some(out) => {
            crate::commands::writing(out, || {
                let mut files = unamalla_core::output::OutputFiles::new();
                files.write(out, json.as_bytes())?;
                Ok(files.commit()?)
            })?;
            eprintln!(
                "{} curves, {} blocks, Σm = {} -> {}",
                problem.curves.len(),
                problem.blocks.len(),
                sol.objective,
                out.display()
            );
        }
        None => println!("{json}"),
    }
    Ok(())
}
