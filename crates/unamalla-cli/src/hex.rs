//! `unamalla hex`: a structured hexahedral mesh of a built-in region or of a directory of six
//! face grids, made convex by Algorithm A and (by default) given planar interior faces by
//! Algorithm B ([Cortés Aguirre 2012, §3.4, §4.2]; the references are listed in
//! `docs/references.md` of the repository). Writes `mesh.vts`, `mesh.vtu`, `report.json` and
//! `histograms.svg` into the output directory.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};
use unamalla_core::optim::drivers::CoplanarityOptions;
use unamalla_core::optim::{NullObserver, Observer, ProgressObserver};
use unamalla_hex::{
    read_face_dir, run_hex, write_outputs, HexAlgorithm, HexCase, HexRunOptions, HexScaling,
    Perturbation,
};

/// Arguments of `unamalla hex`.
#[derive(clap::Args, Debug)]
pub struct HexArgs {
    /// A built-in region (sphere, ellipsoid, box, pico, cosin, shell, parabs, elipsoideg,
    /// yacimiento, sydney) or a directory
    /// holding the six face grids i_min.txt … k_max.txt (built-in names take precedence:
    /// write `./sphere` for a directory called `sphere`).
    pub case: String,
    /// Nodes per direction `m,n,p` (built-in cases; default: the thesis's size).
    #[arg(long, value_parser = parse_size3)]
    pub size: Option<(usize, usize, usize)>,
    /// Perturbation amplitude s (each interior node moves up to s × its shortest edge);
    /// 0 for none. Default: the smallest amplitude giving the thesis's number of non-convex
    /// cells at the start (none for the box and for face directories).
    #[arg(long, allow_negative_numbers = true)]
    pub perturb: Option<f64>,
    /// Instead of an amplitude: perturb until at least this many cells are non-convex.
    #[arg(long, conflicts_with = "perturb")]
    pub nonconvex: Option<usize>,
    /// Seed of the perturbation.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// `a` (Algorithm A only) or `b` (A then B).
    #[arg(long, default_value = "b")]
    pub algorithm: String,
    /// Tetrahedron Jacobian scaling: parametric (default) or index.
    #[arg(long, default_value = "parametric")]
    pub scaling: String,
    /// Algorithm B schedule: `default` (μ₀ = 500, stop as soon as every interior face has
    /// |cos| ≤ 10⁻³) or `thesis` (μ₀ = 0.1, μ ← 0.1μ down to 10⁻¹², no planarity stop).
    #[arg(long, default_value = "default")]
    pub b_schedule: String,
    /// Algorithm B: first penalty parameter μ₀ (weight `C = 1/(2μ)`; default: the schedule's,
    /// 500 or 0.1; the thesis's Table 4.5 also uses 176–800).
    #[arg(long)]
    pub mu0: Option<f64>,
    /// Algorithm B: stop the μ continuation (`μ ← 0.1μ`) once `μ ≤ mu-min` (thesis 10⁻¹²).
    #[arg(long, default_value_t = 1e-12)]
    pub mu_min: f64,
    /// Algorithm B: solver iterations per μ step.
    #[arg(long, default_value_t = 50)]
    pub b_iters: usize,
    /// Algorithm A: solver iterations per ω step.
    #[arg(long, default_value_t = 100)]
    pub a_iters: usize,
    /// Algorithm A: ω₀ relative to the mean tetrahedron Jacobian.
    #[arg(long, default_value_t = 0.1)]
    pub omega0: f64,
    /// Output directory.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print report.json on stdout.
    #[arg(long)]
    pub json: bool,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    /// Write the grid even if cells stay non-convex (warning, exit code 3).
    #[arg(long)]
    pub allow_non_convex: bool,
}

fn parse_size3(s: &str) -> Result<(usize, usize, usize), String> {
    let v: Vec<usize> = s
        .split([',', 'x', 'X'])
        .map(|t| t.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected m,n,p (e.g. 20,20,20), got '{s}'"))?;
    let [m, n, p] = <[usize; 3]>::try_from(v)
        .map_err(|v| format!("expected three sizes m,n,p, got {}", v.len()))?;
    if m < 2 || n < 2 || p < 2 {
        return Err(format!(
            "a hex grid needs at least 2 nodes per direction, got {m},{n},{p}"
        ));
    }
    Ok((m, n, p))
}

/// Runs `unamalla hex`.
pub fn run(a: HexArgs) -> Result<()> {
    let algorithm = match a.algorithm.to_ascii_lowercase().as_str() {
        "a" => HexAlgorithm::A,
        "b" | "ab" => HexAlgorithm::AB,
        other => crate::reliability::usage!("--algorithm must be 'a' or 'b', got '{other}'"),
    };
    let scaling = match a.scaling.to_ascii_lowercase().as_str() {
        "parametric" => HexScaling::Parametric,
        "index" => HexScaling::Index,
        other => {
            crate::reliability::usage!("--scaling must be 'parametric' or 'index', got '{other}'")
        }
    };
    let mut coplanarity = match a.b_schedule.to_ascii_lowercase().as_str() {
        "default" => HexRunOptions::default().coplanarity,
        "thesis" => {
            CoplanarityOptions::thesis().solver(HexRunOptions::default().coplanarity.solver)
        }
        other => {
            crate::reliability::usage!("--b-schedule must be 'default' or 'thesis', got '{other}'")
        }
    };
    let mu0 = a.mu0.unwrap_or(coplanarity.mu0);
    for (name, v, lo) in [
        ("--mu0", mu0, false),
        ("--mu-min", a.mu_min, true),
        ("--omega0", a.omega0, false),
    ] {
        if !(v.is_finite() && (v > 0.0 || (lo && v == 0.0))) {
            bail!(
                "{name} must be a finite number > 0{}, got {v}",
                if lo { " (or 0)" } else { "" }
            );
        }
    }
    if a.mu_min >= mu0 {
        crate::reliability::usage!("--mu-min ({}) must be below --mu0 ({mu0})", a.mu_min);
    }
    if a.b_iters == 0 || a.a_iters == 0 {
        crate::reliability::usage!("--a-iters and --b-iters must be at least 1");
    }
    if let Some(s) = a.perturb {
        if !(s.is_finite() && s >= 0.0) {
            crate::reliability::usage!("--perturb must be a number ≥ 0, got {s}");
        }
    }
    let dir = PathBuf::from(&a.case);
    let builtin = a.case.parse::<HexCase>().ok();
    let (name, mut grid, default_perturb) = if builtin.is_none() && dir.is_dir() {
        if a.size.is_some() {
            crate::reliability::usage!(
                "--size applies to built-in cases; a face directory fixes the size"
            );
        }
        let region = read_face_dir(&dir)?;
        (a.case.clone(), region.tfi()?, Perturbation::None)
    } else {
        let case: HexCase = a.case.parse()?;
        let dims = a.size.unwrap_or_else(|| case.default_size());
        unamalla_core::preflight::check_size(
            "--size",
            format!("{},{},{}", dims.0, dims.1, dims.2),
            dims.0 as f64 * dims.1 as f64 * dims.2 as f64,
            "nodes",
            unamalla_core::preflight::COST_PER_HEX_NODE,
            crate::reliability::limit()?,
        )?;
        (
            case.name().to_string(),
            case.initial_grid(dims)?,
            case.default_perturbation(dims),
        )
    };
    let perturbation = match (a.perturb, a.nonconvex) {
        (Some(0.0), _) => Perturbation::None,
        (Some(s), _) => Perturbation::Amplitude(s),
        (None, Some(c)) => Perturbation::AtLeast { cells: c },
        (None, None) => default_perturb,
    };
    let (amp, nc0) = perturbation.apply(&mut grid, a.seed)?;
    let (m, n, p) = grid.dims();
    if !a.quiet {
        eprintln!(
            "{name} {m}x{n}x{p}: {} cells, perturbation {amp:.4} (seed {}) → {nc0} non-convex",
            grid.num_cells(),
            a.seed
        );
    }
    let mut opts = HexRunOptions::default()
        .algorithm(algorithm)
        .scaling(scaling);
    coplanarity.mu0 = mu0;
    coplanarity.mu_min = a.mu_min;
    opts.coplanarity = coplanarity;
    opts.coplanarity.solver.max_iter = a.b_iters;
    opts.omega.solver.max_iter = a.a_iters;
    opts.omega.omega0_rel = a.omega0;
    let mut progress = ProgressObserver::new(Duration::from_millis(200));
    let observer: &mut dyn Observer = if a.quiet {
        &mut NullObserver
    } else {
        &mut progress
    };
    let mut report = run_hex(&mut grid, &opts, observer)?;
    if !a.quiet {
        progress.finish();
    }
    report.case = name;
    report.perturbation = amp;
    report.seed = a.seed;
    let v = unamalla_core::verify::verify_hexes(&grid);
    let not_met = crate::reliability::guarantee(&v, a.allow_non_convex, "hex")?;
    let out = unamalla_core::output::OutputDir::create(&a.output)?;
    let files = crate::commands::writing(&a.output, || {
        let f = write_outputs(out.path(), &grid, &report)?;
        out.commit()?;
        Ok(f)
    })?;
    if a.json {
        println!("{}", report.to_json());
    } else {
        let s = &report.start;
        println!(
            "start:   non-convex {:>5}  non-hex interior {:>5}  max|cos| {:.3e}",
            s.non_convex_cells, s.non_hex_interior_cells, s.max_abs_cos
        );
        if let (Some(r), Some(st)) = (&report.after_a, &report.algorithm_a) {
            println!(
                "after A: non-convex {:>5}  non-hex interior {:>5}  max|cos| {:.3e}  {} it  {:.3} s  ({})",
                r.non_convex_cells, r.non_hex_interior_cells, r.max_abs_cos, st.iterations, st.seconds, st.status
            );
        }
        if let (Some(r), Some(st)) = (&report.after_b, &report.algorithm_b) {
            println!(
                "after B: non-convex {:>5}  non-hex interior {:>5}  max|cos| {:.3e}  {} it  {:.3} s  ({})",
                r.non_convex_cells, r.non_hex_interior_cells, r.max_abs_cos, st.iterations, st.seconds, st.status
            );
            println!(
                "         μ schedule: {} steps, μ₀ {:e} → {:e} (×0.1, ≤ {} iterations each; planarity stop {:?})",
                st.continuation_steps,
                report.options.coplanarity.mu0,
                st.mu.unwrap_or(f64::NAN),
                report.options.coplanarity.solver.max_iter,
                report.options.coplanarity.stop_cos
            );
        }
        println!(
            "final:   min tet volume {:.3e}  max {:.3e}  scaled Jacobian min {:.3} p5 {:.3}  total {} it {:.3} s",
            report.min_tet_volume,
            report.max_tet_volume,
            report.min_scaled_jacobian,
            report.p5_scaled_jacobian,
            report.iterations,
            report.seconds
        );
    }
    if !a.quiet {
        eprintln!(
            "wrote {}, {}, {}, {}",
            a.output
                .join(files.vts.file_name().unwrap_or_default())
                .display(),
            a.output
                .join(files.vtu.file_name().unwrap_or_default())
                .display(),
            a.output
                .join(files.report.file_name().unwrap_or_default())
                .display(),
            a.output
                .join(files.svg.file_name().unwrap_or_default())
                .display()
        );
    }
    crate::reliability::finish(not_met)
}
