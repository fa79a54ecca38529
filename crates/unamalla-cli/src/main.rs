//! `unamalla` — the command-line front end of the unamalla mesher.
//!
//! Subcommands:
//! * `unamalla tfi <region> --size MxN [--corners a,b,c,d | --auto-corners] -o out.vtk`
//! * `unamalla quality <mesh.vtk> [--json]`
//!
//! Errors are reported as one line on stderr with a non-zero exit code; output files are
//! written atomically, so a failed run never leaves a partial file.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use unamalla_core::io::{self, PartSelector, VtkMesh};
use unamalla_core::mesh::quality::{quad_cell_metrics, QualityReport};
use unamalla_core::single_block::{tfi_region, Corners};

#[derive(Parser, Debug)]
#[command(
    name = "unamalla",
    version,
    about = "Structured and block-structured quad/hex meshes with convex cells"
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
        /// For a MultiPolygon: which part (0-based); default the largest.
        #[arg(long)]
        part: Option<usize>,
        /// Output VTK legacy file (`.vtk`), with per-cell quality arrays.
        #[arg(short, long)]
        output: PathBuf,
        /// Print the quality report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Quality report of a mesh file (VTK legacy: structured grid or quad/hex unstructured grid).
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
        } => {
            let sel = part.map_or(PartSelector::Largest, PartSelector::Index);
            let (reg, removed) = io::read_region_geojson_cleaned(&region, sel)?;
            if removed > 0 {
                eprintln!("note: removed {removed} repeated point(s) from the region");
            }
            let corners = match corners {
                Some(c) => Corners::Input(c),
                None => Corners::Auto,
            };
            let grid = tfi_region(&reg, corners, m, n)?;
            let arrays = quad_cell_metrics(&grid);
            let data: Vec<(&str, &[f64])> =
                arrays.iter().map(|(k, v)| (*k, v.as_slice())).collect();
            io::write_vtk_structured2(&output, &grid, &data)
                .with_context(|| format!("writing {}", output.display()))?;
            let report = QualityReport::for_quads(&grid);
            print_report(&report, json);
            if !json {
                eprintln!("wrote {} ({}x{} nodes)", output.display(), m, n);
            }
        }
        Command::Quality { mesh, json } => {
            let file = io::read_vtk(&mesh)?;
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
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let mut msg = e.to_string();
            for cause in e.chain().skip(1) {
                msg.push_str(": ");
                msg.push_str(&cause.to_string());
            }
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}
