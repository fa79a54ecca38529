//! `unamalla` — the command-line front end of the unamalla mesher.
//!
//! Subcommands:
//! * `unamalla tfi <region> --size MxN [--corners a,b,c,d | --auto-corners] -o out.vtk`
//! * `unamalla quality <mesh.vtk> [--json]`
//! * `unamalla mesh <region> [--decomposition file.json] [--strategy cuts|submap|auto]
//!   [--cells N | --density d | --cell-size h] [--boundary-density w] [--min-hole-area A]
//!   -o <outdir> [--json] [--quiet]`
//! * `unamalla eval <mesh> --functional NAME [--omega w] [--k k] [--raw] [--json]`
//! * `unamalla smooth <mesh> [--functional NAME] [--solver tn-tr|tn-ls|lbfgs|pointwise] [--sigma σ]
//!   [--lbfgs-memory m] [--pointwise-mode simultaneous|components] [--homotopy linear|t2|t3|sine]
//!   [--presmooth N] -o out`
//! * `unamalla simplify <region> --method NAME [--epsilon e] [--delta d] -o out.geojson [--svg f]`
//! * `unamalla decompose <region> [--from file.json] [--no-simplify] [--cells N] -o decomposition.json [--svg out.svg]`
//!   (decomposes the region `unamalla mesh` would: its default simplification first)
//! * `unamalla counts <problem.json> [--density d | --cell-size h] [-o counts.json]`
//! * `unamalla bspline <region> [--degree 1|2] [--net NxM] [--blocks] [--samples K] -o <outdir>`
//! * `unamalla hex <case|facedir> [--size m,n,p] [--perturb s | --nonconvex N] [--seed k]
//!   [--algorithm a|b] -o <outdir> [--json] [--quiet]`
//! * `unamalla pde <mesh> [--a .. --b .. --c .. --d ..] [--g const:V|sin:A]
//!   [--bc 1=parabolic:P,2=const:V,3=sin:P,4=..|all=..] [--manufactured sin-cosh|poly]
//!   [--solver sor|direct] [--omega w] -o <outdir> [--json]`
//! * `unamalla refine <mesh> --factor k [--factor-i ki] [--factor-j kj] -o out.vtk`
//!
//! Errors are reported as one line on stderr with a non-zero exit code (0 ok, 1 input error,
//! 2 usage error, 3 guarantee not met, 4 other — see [`reliability`]). Every run writes its
//! whole output set or nothing ([`unamalla_core::output`]): a directory output is staged beside
//! the target and renamed into place, single files are staged and renamed together, so a
//! failed run leaves the target as it was. Before success is reported the output is checked
//! independently ([`unamalla_core::verify`]).

// No `unwrap`/`expect` on paths user input can reach (tests may use them; docs/reliability.md).
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

use std::path::PathBuf;
use std::process::ExitCode;

mod bspline;
mod commands;
mod counts;
mod hex;
mod pde;
mod progress;
mod refine;
mod reliability;
mod report;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use unamalla_core::io::{self, VtkMesh};
use unamalla_core::mesh::quality::{quad_cell_metrics, QualityReport};
use unamalla_core::single_block::{tfi_region, Corners};

#[derive(Parser, Debug)]
#[command(
    name = "unamalla",
    version,
    about = "Structured and block-structured quad/hex meshes with convex cells",
    after_help = "Exit codes: 0 ok, 1 input error, 2 usage error (or a size above the memory limit, \
                  UNAMALLA_MAX_MEMORY, default 4G), 3 the guarantee (convex cells inside the region) is not met \
                  (or, with mesh --strict, a quality target is missed; the output is written), \
                  4 other (writing failed, internal error). With --json an error is also printed on \
                  stdout as one JSON object, {\"error\": {\"exit_code\", \"kind\", \"message\"}}."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// One structured grid on a roughly four-sided region by transfinite interpolation.
    Tfi {
        /// Region file (GeoJSON Polygon / MultiPolygon / Feature / FeatureCollection).
        region: PathBuf,
        /// Grid size in nodes, `MxN` (M along the bottom side, N along the left side).
        #[arg(long, value_parser = parse_size)]
        size: (usize, usize),
        /// Four corner indices into the outer ring as listed in the file (first point 0,
        /// closing duplicate not counted); the bottom side starts at the first one.
        #[arg(long, value_parser = parse_corners, conflicts_with = "auto_corners")]
        corners: Option<[usize; 4]>,
        /// Choose the four corners automatically (the default when --corners is absent).
        #[arg(long)]
        auto_corners: bool,
        /// For a MultiPolygon: which part (0-based); required when the file has several.
        #[arg(long)]
        part: Option<usize>,
        /// Output VTK legacy file (`.vtk`), with per-cell quality arrays.
        #[arg(short, long)]
        output: PathBuf,
        /// Print the quality report as JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Write the grid even if a cell is not convex or lies outside the region (exit code 3
        /// and a warning).
        #[arg(long)]
        allow_non_convex: bool,
    },
    /// The main job: a block-structured, singularity-free, all-convex quad mesh of a region.
    Mesh(commands::MeshArgs),
    /// Value and gradient norm of a functional on a mesh (VTK legacy file).
    Eval {
        /// Mesh file.
        mesh: PathBuf,
        /// Functional name (length, area, orthogonality, area-orthogonality, smoothness,
        /// k-smoothness, k-area, h-omega, ...).
        #[arg(long)]
        functional: String,
        /// ω of h-omega.
        #[arg(long)]
        omega: Option<f64>,
        /// k of the k-functionals.
        #[arg(long)]
        k: Option<f64>,
        /// Plain sum over all corner triangles, no normalization.
        #[arg(long)]
        raw: bool,
        /// Print JSON (the default output is JSON too; this flag is accepted for symmetry).
        #[arg(long)]
        json: bool,
    },
    /// Untangle and smooth a quad mesh (VTK legacy file) keeping every cell convex.
    Smooth {
        /// Mesh file.
        mesh: PathBuf,
        /// Functional / driver: ao-homega (default), homega, karea-length, ksmooth-area, karea,
        /// ksmooth, area-length (t-Area–Length), area-ortho (t-Area–Orthogonality, weight 0.5),
        /// ivanenko (Σ((ε − α)₊)², ε = 0.01ᾱ: untangling only, no smoothing).
        #[arg(long, default_value = "ao-homega")]
        functional: String,
        /// Solver: tn-tr, tn-ls, lbfgs, pointwise, ncg-fr.
        #[arg(long, default_value = "tn-tr")]
        solver: String,
        /// Weight σ in [0, 1]: of H_ω for ao-homega (default 0.1), of the adaptive functional
        /// for karea-length / ksmooth-area (default 0.5), of t-Area for area-length (default
        /// 0.5; area-ortho accepts only 0.5).
        #[arg(long)]
        sigma: Option<f64>,
        /// L-BFGS memory m, the number of stored pairs (UNAMALLA: 3 or 5; default 5).
        #[arg(long)]
        lbfgs_memory: Option<usize>,
        /// Pointwise Newton mode: simultaneous (2×2 system, default) or components.
        #[arg(long)]
        pointwise_mode: Option<String>,
        /// Homotopy path σ̃(t) towards the combination for karea-length / ksmooth-area: linear
        /// (default), t2, t3, sine.
        #[arg(long)]
        homotopy: Option<String>,
        /// Length pre-smoothing iterations ("Previous Smoothness"; default 0).
        #[arg(long, default_value_t = 0)]
        presmooth: usize,
        /// Output VTK legacy file.
        #[arg(short, long)]
        output: PathBuf,
        /// No progress line.
        #[arg(long)]
        quiet: bool,
        /// Write the mesh even if cells stay non-convex (warning, exit code 3).
        #[arg(long)]
        allow_non_convex: bool,
    },
    /// Simplify a region's contour.
    Simplify {
        /// Region file (GeoJSON).
        region: PathBuf,
        /// visvalingam, areas, radii, modified-areas (default), modified-radii, three-step, modified-three-step.
        #[arg(long, default_value = "modified-areas")]
        method: String,
        /// Threshold ε.
        #[arg(long)]
        epsilon: Option<f64>,
        /// MPP factor δ.
        #[arg(long)]
        delta: Option<f64>,
        /// Output GeoJSON.
        #[arg(short, long)]
        output: PathBuf,
        /// Overlay picture (original and simplified rings).
        #[arg(long)]
        svg: Option<PathBuf>,
        /// For a MultiPolygon: which part (0-based); required when the file has several.
        #[arg(long)]
        part: Option<usize>,
    },
    /// Decompose a region into admissible four-sided blocks.
    Decompose(commands::DecomposeArgs),
    /// Compatible point counts of a compatibility problem (JSON), with pinned counts honoured.
    Counts(counts::CountsArgs),
    /// B-spline parametrization (bilinear or biquadratic) of a region from a convex control net,
    /// with injectivity certificates and a dense det J sample (Abelló et al.).
    Bspline(bspline::BsplineArgs),
    /// Structured hexahedral mesh of a built-in region or six face grids, made convex
    /// (Algorithm A) with planar interior faces (Algorithm B) (Cortés Aguirre 2012).
    Hex(hex::HexArgs),
    /// Solve a·U_xx + 2b·U_xy + c·U_yy + d·U = g on a convex mesh (SOR or sparse LU); writes
    /// VTK point data `u`, a Geomview MESH surface and PNG/SVG plots (González Flores, RF12).
    Pde(pde::PdeArgs),
    /// Uniform refinement of a convex structured grid: every cell into k × k (González Flores,
    /// RF11).
    Refine(refine::RefineArgs),
    /// Quality report of a mesh file: VTK legacy (.vtk), VTK XML (.vtu, .vts, .vtm: every block)
    /// or Gmsh (.msh).
    Quality {
        /// Mesh file.
        mesh: PathBuf,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected MxN (e.g. 60x40), got '{s}'"))?;
    let m: usize = a.trim().parse().map_err(|_| format!("bad M in '{s}'"))?;
    let n: usize = b.trim().parse().map_err(|_| format!("bad N in '{s}'"))?;
    if m < 2 || n < 2 {
        return Err(format!("a grid needs at least 2x2 nodes, got {m}x{n}"));
    }
    Ok((m, n))
}

fn parse_corners(s: &str) -> Result<[usize; 4], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("corners must be four vertex indices like 0,12,25,40; got '{s}'"))?;
    <[usize; 4]>::try_from(v)
        .map_err(|v| format!("corners must be exactly four indices, got {}", v.len()))
}

fn print_report(report: &QualityReport, json: bool) {
    if json {
        println!("{}", report.to_json());
    } else {
        println!("{report}");
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Tfi {
            region,
            size: (m, n),
            corners,
            auto_corners: _,
            part,
            output,
            json,
            allow_non_convex,
        } => {
            unamalla_core::preflight::check_size(
                "--size",
                format!("{m}x{n}"),
                m as f64 * n as f64,
                "nodes",
                unamalla_core::preflight::COST_PER_TFI_NODE,
                reliability::limit()?,
            )?;
            let reg = reliability::read_one_region(&region, part)?;
            let corners = match corners {
                Some(c) => Corners::Input(c),
                None => Corners::Auto,
            };
            let grid = tfi_region(&reg, corners, m, n)?;
            let v = unamalla_core::verify::verify_quads(
                &grid,
                Some(&reg),
                &unamalla_core::verify::VerifyOptions::default(),
            );
            let not_met = reliability::guarantee(&v, allow_non_convex, "tfi")?;
            let arrays = quad_cell_metrics(&grid);
            let data: Vec<(&str, &[f64])> =
                arrays.iter().map(|(k, v)| (*k, v.as_slice())).collect();
            let write = || -> Result<()> {
                let mut files = unamalla_core::output::OutputFiles::new();
                let tmp = files.stage(&output)?;
                io::write_vtk_structured2(&tmp, &grid, &data)?;
                files.commit()?;
                Ok(())
            };
            write().context(reliability::WriteFailed(format!(
                "writing {}",
                output.display()
            )))?;
            let report = QualityReport::for_quads(&grid);
            print_report(&report, json);
            if !json {
                eprintln!("wrote {} ({}x{} nodes)", output.display(), m, n);
            }
            reliability::finish(not_met)?;
        }
        Command::Mesh(a) => commands::mesh(a)?,
        Command::Eval {
            mesh,
            functional,
            omega,
            k,
            raw,
            json: _,
        } => commands::eval(&mesh, &functional, omega, k, raw)?,
        Command::Smooth {
            mesh,
            functional,
            solver,
            sigma,
            lbfgs_memory,
            pointwise_mode,
            homotopy,
            presmooth,
            output,
            quiet,
            allow_non_convex,
        } => commands::smooth(
            &mesh,
            &commands::SmoothFlags {
                functional,
                solver,
                sigma,
                lbfgs_memory,
                pointwise_mode,
                homotopy,
                presmooth,
            },
            &output,
            quiet,
            allow_non_convex,
        )?,
        Command::Simplify {
            region,
            method,
            epsilon,
            delta,
            output,
            svg,
            part,
        } => commands::simplify(
            &region,
            part,
            &method,
            epsilon,
            delta,
            &output,
            svg.as_deref(),
        )?,
        Command::Decompose(args) => commands::decompose(args)?,
        Command::Counts(args) => counts::run(args)?,
        Command::Bspline(args) => bspline::run(args)?,
        Command::Hex(args) => hex::run(args)?,
        Command::Pde(args) => pde::run(args)?,
        Command::Refine(args) => refine::run(args)?,
        Command::Quality { mesh, json } => {
            let file = commands::read_any_mesh(&mesh)?;
            let report = match &file.mesh {
                VtkMesh::Structured2(g) => QualityReport::for_quads(g),
                VtkMesh::Quads(q) => QualityReport::for_quads(q),
                VtkMesh::Structured3(g) => QualityReport::for_hexes(g),
                VtkMesh::Hexes(h) => QualityReport::for_hexes(h),
            };
            if file.mesh.num_nodes() == 0 {
                bail!("{}: the mesh has no nodes", mesh.display());
            }
            print_report(&report, json);
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    // a panic is an internal error: one line, exit 4 (never a backtrace dump for users)
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!(
            "error: internal error (please report): {}{at}",
            msg.replace('\n', " ")
        );
    }));
    // `--json` anywhere: errors are also printed on stdout as one JSON object
    // (`{"error": {"exit_code", "kind", "message"}}`), so a script reading stdout gets JSON
    let json = std::env::args().any(|a| a == "--json");
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            let shows = matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            );
            if json && !shows {
                let text = e.render().to_string();
                let first = text
                    .lines()
                    .next()
                    .unwrap_or("")
                    .trim_start_matches("error: ");
                json_error(reliability::EXIT_USAGE, first);
                eprintln!("error: {first}");
                return ExitCode::from(reliability::EXIT_USAGE);
            }
            e.exit()
        }
    };
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(cli)));
    let result = match outcome {
        Ok(r) => r,
        Err(_) => {
            if json {
                json_error(reliability::EXIT_OTHER, "internal error (please report)");
            }
            return ExitCode::from(reliability::EXIT_OTHER);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is::<reliability::WrittenNotMet>() => ExitCode::from(reliability::EXIT_NOT_MET),
        Err(e) => {
            // One line: the context chain joined by ": ", skipping a cause whose text the
            // message already contains (library errors such as `IoError::Geometry` print
            // their source themselves), with any newline flattened.
            let mut msg = e.to_string();
            for cause in e.chain().skip(1) {
                let c = cause.to_string();
                if !msg.contains(&c) {
                    msg.push_str(": ");
                    msg.push_str(&c);
                }
            }
            let msg = reliability::clean_paths(&msg.replace('\n', " "));
            let code = reliability::exit_code(&e);
            if json {
                json_error(code, &msg);
            }
            eprintln!("error: {msg}");
            ExitCode::from(code)
        }
    }
}

/// Prints `{"error": {"exit_code": code, "kind": …, "message": message}}` on stdout (`--json`);
/// `kind` is `input`, `usage`, `guarantee` or `other` after the exit code.
fn json_error(code: u8, message: &str) {
    let kind = match code {
        reliability::EXIT_INPUT => "input",
        reliability::EXIT_USAGE => "usage",
        reliability::EXIT_NOT_MET => "guarantee",
        _ => "other",
    };
    println!(
        "{}",
        serde_json::json!({"error": {"exit_code": code, "kind": kind, "message": message}})
    );
}
