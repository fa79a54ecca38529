//! The subcommands built on the stage crates (`mesh`, `eval`, `smooth`, `simplify`,
//! `decompose`). Nothing is written before the whole computation has succeeded and passed its
//! check; the files of a run are staged and moved into place together
//! ([`unamalla_core::output`]).

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::reliability::{self, usage, PartArg, WriteFailed};
use anyhow::{bail, Context, Result};
use unamalla_core::contour::{self, HoleFilter, SimplifyOptions};
use unamalla_core::decompose::{self as dec, Decomposition};
use unamalla_core::io::{self, VtkMesh};
use unamalla_core::mesh::quality::quad_cell_metrics;
use unamalla_core::mesh::{HasNodes, QuadMesh, Region};
use unamalla_core::optim::{self, NullObserver, Observer, ProgressObserver, SmoothOptions};
use unamalla_core::output::{OutputDir, OutputFiles};
use unamalla_core::pipeline::{Mesher, Strategy};
use unamalla_core::OutputOptions;

/// Input and export options of `unamalla mesh` (see `docs/solvers-and-gis.md`): region formats,
/// feature selection, coordinate system, solver formats and the HTML report.
#[derive(clap::Args, Debug, Clone)]
pub struct SolverGisArgs {
    /// Coordinate system of the region: auto (GeoJSON in the lon/lat range without declared
    /// units, or a shapefile with a geographic .prj, is WGS84 lon/lat), lonlat, planar, or a
    /// proj string ("+proj=utm +zone=33 +datum=WGS84 +units=m"). Geographic input is meshed in
    /// a local transverse Mercator projection, lengths in km.
    #[arg(long, default_value = "auto")]
    pub crs: String,
    /// Select a feature by attribute, KEY=VALUE (GeoJSON properties, shapefile .dbf fields).
    #[arg(long)]
    pub feature: Option<String>,
    /// Solver formats to write besides the VTK files, comma-separated: msh, su2, openfoam, cgns
    /// (cgns needs a build with `--features cgns`), or none.
    #[arg(long, default_value = "msh,su2,openfoam")]
    pub export: String,
    /// Thickness of the one-cell OpenFOAM extrusion (default: the mean cell size).
    #[arg(long)]
    pub thickness: Option<f64>,
    /// With projected input: also write mesh-lonlat.msh with the nodes back-projected to
    /// longitude/latitude.
    #[arg(long)]
    pub lonlat: bool,
    /// Do not write report.html.
    #[arg(long)]
    pub no_report: bool,
}

/// The solver formats `--export` names.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Exports {
    msh: bool,
    su2: bool,
    openfoam: bool,
    cgns: bool,
}

fn parse_exports(s: &str) -> Result<Exports> {
    let mut e = Exports::default();
    for t in s.split(',').map(str::trim).filter(|t| !t.is_empty()) {
        match t {
            "msh" => e.msh = true,
            "su2" => e.su2 = true,
            "openfoam" | "foam" => e.openfoam = true,
            "cgns" if cfg!(feature = "cgns") => e.cgns = true,
            "cgns" => bail!(
                "--export cgns needs a build with the CGNS library: cargo build --features cgns"
            ),
            "none" => {}
            other => bail!("--export: unknown format {other:?} (msh, su2, openfoam, cgns, none)"),
        }
    }
    Ok(e)
}

/// Reads a region of any supported format (see [`io::input`]), printing the notes (unless
/// `quiet`) and any warning.
fn load_region(path: &Path, gis: &SolverGisArgs, quiet: bool) -> Result<io::LoadedRegion> {
    let opts = io::LoadOptions::default()
        .feature(gis.feature.clone())
        .crs(gis.crs.parse()?);
    let l = io::load_region(path, &opts)?;
    if !quiet {
        for n in &l.notes {
            eprintln!("note: {n}");
        }
        if l.removed_points > 0 {
            eprintln!(
                "note: removed {} repeated point(s) from the region",
                l.removed_points
            );
        }
    }
    if let Some(w) = &l.warning {
        eprintln!("warning: {w}");
    }
    Ok(l)
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    io::atomic_write(path, |w| w.write_all(text.as_bytes()))
        .with_context(|| format!("writing {}", path.display()))
}

/// Runs the write phase `f`; a failure is marked as a write failure (exit code 4) naming `target`.
pub fn writing<T>(target: &Path, f: impl FnOnce() -> Result<T>) -> Result<T> {
    f().context(WriteFailed(format!("writing {}", target.display())))
}

/// Arguments of `unamalla mesh` (the options of the subcommand).
#[derive(clap::Args, Debug)]
pub struct MeshArgs {
    /// Region file: GeoJSON, Shapefile (.shp), UNAMALLA .con or plain text rings.
    pub region: PathBuf,
    /// Use this decomposition file (made for the simplified region, or for the raw region
    /// together with --no-simplify) instead of the automatic one.
    #[arg(long)]
    pub decomposition: Option<PathBuf>,
    /// Decomposition strategy: cuts (default; Méndez 2023), submap (submapping, Ruiz-Gironés &
    /// Sarrate), or
    /// auto (submap when every angle is within 10° of a multiple of 90° and no vertex
    /// reclassification is needed, else cuts).
    #[arg(long, default_value = "cuts", value_parser = ["cuts", "submap", "auto"])]
    pub strategy: String,
    /// About this many cells (default 20000; at least 1).
    #[arg(long, conflicts_with_all = ["density", "cell_size"], allow_negative_numbers = true, value_parser = crate::reliability::positive_count)]
    pub cells: Option<usize>,
    /// The thesis's density factor d (at least 1).
    #[arg(long, conflicts_with = "cell_size", allow_negative_numbers = true, value_parser = crate::reliability::positive_count)]
    pub density: Option<usize>,
    /// Target cell size in region units.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::reliability::finite_number)]
    pub cell_size: Option<f64>,
    /// Boundary density w of (6.9) (1 = plain (6.8)).
    #[arg(long, default_value_t = 1.0)]
    pub boundary_density: f64,
    /// Drop holes smaller than this area (region units squared) up front (by default no hole is
    /// dropped by area; islands narrower than a cell are carved, see --carve-islands).
    #[arg(long)]
    pub min_hole_area: Option<f64>,
    /// Mesh the region as given, without contour simplification.
    #[arg(long)]
    pub no_simplify: bool,
    /// Remove boundary features whose modified-area measure is below this many squared
    /// target cell sizes (0 keeps every feature the simplification kept).
    #[arg(long, default_value_t = unamalla_core::pipeline::DEFAULT_FEATURE_FACTOR)]
    pub feature_factor: f64,
    /// Cut off spits and fill inlets behind a neck narrower than this many target cell
    /// sizes (and thinner than that on average); 0 keeps them. Each cut is listed in
    /// report.json's notes.
    #[arg(long, default_value_t = unamalla_core::pipeline::DEFAULT_NECK_FACTOR)]
    pub neck_factor: f64,
    /// Stop smoothing after this many seconds of wall-clock time (status "STOP by TIME
    /// LIMIT"). By default there is no limit: smoothing stops on convergence, so the mesh
    /// does not depend on the machine.
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// Sweeps of the shape pass after the smoothing at most: cells below the target μ
    /// (--shape-target) are improved one node at a time, the nodes on the region boundary
    /// sliding along it; 0 turns the pass off.
    #[arg(long, default_value_t = unamalla_core::optim::ShapeOptions::default().max_sweeps)]
    pub shape_sweeps: usize,
    /// The target μ of the shape pass: cells below it are raised where the guards allow.
    #[arg(long, default_value_t = unamalla_core::optim::ShapeOptions::default().target)]
    pub shape_target: f64,
    /// Keep the nodes on the region boundary where the transfinite interpolation put them
    /// (the shape pass moves interior nodes only).
    #[arg(long)]
    pub no_slide: bool,
    /// Never drop holes: every hole stays in the block layout (none is carved), and where the
    /// mesh fails next to a hole narrower than the cell size the run fails, naming the hole. By
    /// default islands narrower than a cell are carved and those too small to carve dropped,
    /// and a failure next to such a hole is meshed again without it (report.json
    /// "holes_dropped", with a warning).
    #[arg(long)]
    pub keep_narrow_holes: bool,
    /// Leave every hole narrower than this many cell sizes out of the block layout and carve
    /// it into the smoothed mesh (its cells removed, the nodes around it moved onto its
    /// contour; report.json "holes_carved"); islands too small to carve are dropped
    /// ("holes_dropped"). Default 1 (islands narrower than a cell); wider ones are carved too
    /// when bridging them with cuts fails or stays below --quality-target. Larger values suit
    /// seas with many islands a few cells across.
    #[arg(long, value_parser = crate::reliability::finite_number)]
    pub carve_islands: Option<f64>,
    /// Never carve: every hole stays in the block layout, and the holes the retries leave out
    /// stay out of the mesh.
    #[arg(long, conflicts_with = "carve_islands")]
    pub no_carve: bool,
    /// When the automatically chosen layout gives μ ≥ 0.8 on fewer than this share of the
    /// cells (percent), re-make the mesh from the next candidate layouts (at most two more
    /// runs) and keep the best; 0 turns the retry off. Each try is named in report.json's
    /// notes.
    #[arg(long, default_value_t = unamalla_core::pipeline::QUALITY_TARGET_PERCENT)]
    pub quality_target: f64,
    /// Exit with code 3 (after writing everything) when the mesh misses a quality target:
    /// μ ≥ 0.8 on fewer than 90 % of the cells, or (with --cells) a cell count more than 15 %
    /// off the request.
    #[arg(long)]
    pub strict: bool,
    /// Also write rectilinear.json: the rectilinear region R whose piecewise-bilinear image is
    /// the mesh (one lattice rectangle per block, the lattice position of every node, R's
    /// boundary rings), or the reason there is none (the development does not close around a
    /// hole, or overlaps itself).
    #[arg(long)]
    pub rectilinear: bool,
    /// For a MultiPolygon: `all` (the default: every part is meshed, into `part-K/`
    /// subdirectories with a summary `report.json`) or one part's 0-based index.
    #[arg(long, value_parser = crate::reliability::parse_part)]
    pub part: Option<PartArg>,
    /// Write the mesh even if it fails the independent check (non-convex cells, cells
    /// outside the region, area or holes off), with a warning and exit code 3.
    #[arg(long)]
    pub allow_non_convex: bool,
    /// Output directory (replaced as a whole: it must be new, empty or a previous output).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print report.json on stdout.
    #[arg(long)]
    pub json: bool,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    #[command(flatten)]
    pub gis: SolverGisArgs,
}

/// `unamalla mesh`. A GeoJSON MultiPolygon's parts are meshed one by one into `part-K/`
/// (with a summary `report.json` listing them) unless `--part N` picks one (or `--feature`
/// selects a feature); a single polygon writes its files into the output directory itself.
pub fn mesh(a: MeshArgs) -> Result<()> {
    let exports = parse_exports(&a.gis.export)?;
    if let Some(t) = a.gis.thickness {
        if !(t.is_finite() && t > 0.0) {
            usage!("--thickness must be a positive number");
        }
    }
    // option checks before any work
    if let Some(h) = a.cell_size {
        if !(h.is_finite() && h > 0.0) {
            usage!("--cell-size must be a positive number, got {h}");
        }
    }
    if !(a.boundary_density.is_finite() && a.boundary_density >= 1.0) {
        usage!("--boundary-density must be a number ≥ 1");
    }
    if !(a.feature_factor.is_finite() && a.feature_factor >= 0.0) {
        usage!("--feature-factor must be a number ≥ 0");
    }
    if !(a.neck_factor.is_finite() && a.neck_factor >= 0.0) {
        usage!("--neck-factor must be a number ≥ 0");
    }
    if !(a.shape_target > 0.0 && a.shape_target <= 1.0) {
        usage!(
            "--shape-target must be a number in (0, 1], got {}",
            a.shape_target
        );
    }
    if !matches!(a.strategy.as_str(), "cuts" | "submap" | "auto") {
        usage!(
            "--strategy must be cuts, submap or auto, got {}",
            a.strategy
        );
    }
    // GeoJSON parts (the general loader takes the largest part): every part, or --part N
    let is_geojson = a
        .region
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("geojson") || e.eq_ignore_ascii_case("json"));
    let parts: Vec<(Option<usize>, io::LoadedRegion)> =
        match (is_geojson && a.gis.feature.is_none(), a.part) {
            (true, part) => {
                let parts = reliability::read_region_parts(&a.region, part, true)?;
                if parts.len() == 1 && part.is_none() {
                    vec![(None, load_region(&a.region, &a.gis, a.quiet)?)]
                } else {
                    let multi = parts.len() > 1;
                    parts
                        .into_iter()
                        .map(|(k, region)| {
                            let loaded = io::LoadedRegion {
                                region,
                                names: Default::default(),
                                projection: None,
                                removed_points: 0,
                                notes: Vec::new(),
                                warning: None,
                            };
                            (multi.then_some(k), loaded)
                        })
                        .collect()
                }
            }
            (false, Some(_)) => usage!("--part applies to GeoJSON files without --feature"),
            (false, None) => vec![(None, load_region(&a.region, &a.gis, a.quiet)?)],
        };
    if a.gis.lonlat && parts.iter().any(|(_, l)| l.projection.is_none()) {
        usage!("--lonlat needs geographic input (or --crs lonlat / a proj string)");
    }
    let out = OutputDir::create(&a.output)?;
    let stem = a
        .region
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let multi = parts.len() > 1;
    let mut summaries = Vec::new();
    let mut not_met = Vec::new();
    for (k, loaded) in &parts {
        let (dir, name) = match k {
            Some(k) => (out.join(format!("part-{k}")), format!("{stem} part {k}")),
            None => (out.path().to_path_buf(), stem.clone()),
        };
        let (report, warn) = mesh_part(&a, exports, loaded, &name, &dir, multi)?;
        if let Some(w) = warn {
            not_met.push(w);
        }
        summaries.push(report);
    }
    if multi {
        let cells: u64 = summaries
            .iter()
            .map(|r| r["cells"].as_u64().unwrap_or(0))
            .sum();
        let summary = serde_json::json!({
            "region": stem,
            "parts": summaries.len(),
            "cells": cells,
            "part_reports": summaries,
        });
        let text = serde_json::to_string_pretty(&summary)?;
        writing(&a.output, || write_text(&out.join("report.json"), &text))?;
        if a.json {
            println!("{text}");
        }
    }
    writing(&a.output, || Ok(out.commit()?))?;
    reliability::finish((!not_met.is_empty()).then(|| not_met.join("; ")))
}

/// Meshes one region into `dir` (inside the staging directory); returns the report as JSON and
/// the warning when the guarantee is not met (`--allow-non-convex`).
fn mesh_part(
    a: &MeshArgs,
    exports: Exports,
    loaded: &io::LoadedRegion,
    name: &str,
    dir: &Path,
    multi: bool,
) -> Result<(serde_json::Value, Option<String>)> {
    let region = loaded.region.clone();
    let mut mesher = Mesher::new();
    mesher = match (a.cells, a.density, a.cell_size) {
        (_, _, Some(h)) => mesher.cell_size(h),
        (_, Some(d), _) => mesher.density(d),
        (Some(n), _, _) => mesher.cells(n),
        _ => mesher,
    };
    mesher = mesher.boundary_density(a.boundary_density);
    mesher = mesher
        .feature_factor(a.feature_factor)
        .neck_factor(a.neck_factor);
    if let Some(t) = a.time_limit {
        if !(t.is_finite() && t >= 0.0) {
            bail!("--time-limit must be a number of seconds ≥ 0");
        }
    }
    mesher = mesher.time_limit(a.time_limit);
    mesher = mesher.shape((a.shape_sweeps > 0).then(|| {
        unamalla_core::optim::ShapeOptions::default()
            .with_target(a.shape_target)
            .with_max_sweeps(a.shape_sweeps)
            .with_slide(!a.no_slide)
    }));
    mesher = mesher.strategy(match a.strategy.as_str() {
        "submap" => Strategy::Submap,
        "auto" => Strategy::Auto,
        _ => Strategy::Cuts,
    });
    mesher = mesher.allow_non_convex(a.allow_non_convex);
    if !(a.quality_target.is_finite() && (0.0..=100.0).contains(&a.quality_target)) {
        bail!("--quality-target must be a percentage between 0 and 100");
    }
    mesher = mesher
        .quality_target(a.quality_target)
        .drop_narrow_holes(!a.keep_narrow_holes)
        .carve_dropped_holes(!a.no_carve);
    if let Some(w) = a.carve_islands {
        mesher = mesher.carve_islands(w);
    }
    let mut sopts = SimplifyOptions::default();
    if let Some(area) = a.min_hole_area {
        sopts.holes = HoleFilter::MinArea(area);
    }
    mesher = mesher.simplify((!a.no_simplify).then_some(sopts));
    if let Some(f) = &a.decomposition {
        // a saved decomposition fits the region without small features; one made by hand for
        // the simplified region (`unamalla simplify`) fits that one
        let prepared = mesher.prepare_region(&region)?;
        let (d, _) = read_decomposition(
            f,
            ("the meshed region", &prepared.mesh_region),
            ("the simplified region", &prepared.simplified),
        )?;
        mesher = mesher.decomposition(d);
    }
    let progress = (!a.quiet).then(crate::progress::Progress::for_stderr);
    if let Some(p) = &progress {
        let p = p.clone();
        mesher = mesher.on_progress(move |stage, msg| p.stage(stage, msg));
    }
    let result = match &progress {
        Some(p) => mesher.mesh_observed(&region, &mut p.observer()),
        None => mesher.mesh_observed(&region, &mut NullObserver),
    };
    if let Some(p) = &progress {
        p.finish();
    }
    let result = result.with_context(|| format!("{name}: nothing written"))?;
    // dropping holes changes the domain: said on stderr even with --quiet
    if !result.report.holes_dropped.is_empty() && a.min_hole_area.is_none() {
        eprintln!(
            "warning: {name}: {} hole(s) at the cell scale were dropped (report.json \"holes_dropped\", the notes say why); --keep-narrow-holes fails instead, a smaller --cell-size keeps them",
            result.report.holes_dropped.len()
        );
    }
    let mut report = result.report.clone();
    report.region = name.to_string();
    let mut not_met = reliability::guarantee(&report.verification, true, name)?;
    if a.strict {
        let missed = reliability::strict_targets(&report, a.cells);
        if !missed.is_empty() {
            let msg = format!("{name}: --strict: {}", missed.join("; "));
            not_met = Some(match not_met {
                Some(m) => format!("{m}; {msg}"),
                None => msg,
            });
        }
    }

    // everything computed: now write (into the staging directory)
    let mut result = result;
    result.report = report;
    let report = &result.report;
    let json = unamalla_core::write::report_json(report)?;
    let groups = if loaded.names.is_empty() {
        io::msh::boundary_edge_groups(result.mesh.global())
    } else {
        io::named_edge_groups(result.mesh.global(), &region, &loaded.names)?
    };
    // the extrusion's default thickness: the mean cell size of the input region
    let cell_size = (region.area() / report.cells.max(1) as f64).sqrt();
    let opts = OutputOptions::default()
        .formats(exports.msh, exports.su2, exports.openfoam, exports.cgns)
        .thickness(Some(a.gis.thickness.unwrap_or(cell_size)))
        .patches(&region, &loaded.names)
        .lonlat(if a.gis.lonlat {
            loaded.projection.as_ref()
        } else {
            None
        })
        .rectilinear(a.rectilinear);
    writing(&a.output, || {
        result.write_files(dir, &opts)?;
        if !a.gis.no_report {
            let settings = crate::report::Settings::of_run(a, loaded, &groups);
            let html = crate::report::report_html(&result, report, &settings);
            write_text(&dir.join("report.html"), &html)?;
        }
        Ok(())
    })?;
    if a.json && !multi {
        println!("{json}");
    } else if !a.quiet {
        println!(
            "{}: {} cells, {} blocks, non-convex {}, interior singularities {}, mu>=0.8 {:.1} %, min scaled Jacobian {:.3}, area change {:.3} %, {:.2} s -> {}",
            report.region,
            report.cells,
            report.blocks,
            report.non_convex_cells,
            report.interior_singularities,
            report.mu_ge_0_8_percent,
            report.min_scaled_jacobian,
            report.area_change_percent,
            report.seconds,
            a.output.display()
        );
    }
    Ok((serde_json::to_value(report)?, not_met))
}

/// Reads a mesh file of any format `unamalla mesh` writes: VTK legacy (`.vtk`), VTK XML
/// (`.vtu`, `.vts`; `.vtm`: the blocks it lists merged into one quad mesh) or Gmsh (`.msh`).
pub fn read_any_mesh(path: &Path) -> Result<io::VtkFile> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    Ok(match ext.as_str() {
        "vtu" | "vts" => io::read_vtk_xml(path)?,
        "vtm" => {
            let dir = path.parent().unwrap_or(Path::new("."));
            let mut nodes = Vec::new();
            let mut cells = Vec::new();
            for e in io::read_vtm(path)? {
                let f = io::read_vtk_xml(dir.join(&e.file))?;
                let q = match f.mesh {
                    VtkMesh::Structured2(g) => QuadMesh::from_grid(&g),
                    VtkMesh::Quads(q) => q,
                    _ => bail!("{}: block {} is not a quad mesh", path.display(), e.name),
                };
                let off = nodes.len();
                nodes.extend_from_slice(q.nodes());
                cells.extend(q.cells().iter().map(|c| c.map(|v| v + off)));
            }
            bare_file(VtkMesh::Quads(QuadMesh::new(nodes, cells)?))
        }
        "msh" => {
            let f = io::read_msh(path)?;
            bare_file(match f.mesh {
                io::MshMesh::Quads(q) => VtkMesh::Quads(q),
                io::MshMesh::Hexes(h) => VtkMesh::Hexes(h),
            })
        }
        _ => io::read_vtk(path)?,
    })
}

fn bare_file(mesh: VtkMesh) -> io::VtkFile {
    io::VtkFile {
        title: String::new(),
        mesh,
        cell_data: Vec::new(),
        point_data: Vec::new(),
    }
}

fn read_quad_mesh(path: &Path) -> Result<QuadMesh> {
    let file = io::read_vtk(path)?;
    Ok(match file.mesh {
        VtkMesh::Structured2(g) => QuadMesh::from_grid(&g),
        VtkMesh::Quads(q) => q,
        VtkMesh::Structured3(_) | VtkMesh::Hexes(_) => {
            bail!(
                "{}: a hexahedral mesh; this command takes a quad mesh",
                path.display()
            )
        }
    })
}

/// `unamalla eval`.
pub fn eval(path: &Path, name: &str, omega: Option<f64>, k: Option<f64>, raw: bool) -> Result<()> {
    let mesh = read_quad_mesh(path)?;
    let spec = unamalla_core::functionals::FunctionalSpec::from_name(name, omega, k)?;
    let r = unamalla_core::functionals::evaluate(&mesh, &spec, raw)?;
    println!(
        "{}",
        serde_json::json!({ "value": r.value, "gradient_norm": r.gradient_norm })
    );
    Ok(())
}

/// `unamalla smooth`.
/// The options of `unamalla smooth` besides the files.
#[derive(Debug, Clone, Default)]
pub struct SmoothFlags {
    /// `--functional`.
    pub functional: String,
    /// `--solver`.
    pub solver: String,
    /// `--sigma` (the functional's default if `None`).
    pub sigma: Option<f64>,
    /// `--lbfgs-memory`.
    pub lbfgs_memory: Option<usize>,
    /// `--pointwise-mode`.
    pub pointwise_mode: Option<String>,
    /// `--homotopy`.
    pub homotopy: Option<String>,
    /// `--presmooth`.
    pub presmooth: usize,
}

impl SmoothFlags {
    /// The library options these flags select (typed errors for unknown names and bad values).
    pub fn options(&self) -> Result<SmoothOptions> {
        let mut functional: optim::SmoothFunctional = self.functional.parse()?;
        if let Some(s) = self.sigma {
            functional = functional.with_sigma(s)?;
        }
        let mut opts = SmoothOptions::default()
            .functional(functional)
            .presmooth(self.presmooth);
        opts.solver.solver = self.solver.parse::<optim::solver::Solver>()?;
        if let Some(m) = self.lbfgs_memory {
            opts.solver.lbfgs_memory = m;
        }
        if let Some(p) = &self.pointwise_mode {
            opts.solver.pointwise_mode = p.parse()?;
        }
        if let Some(h) = &self.homotopy {
            opts.schedule = h.parse()?;
        }
        opts.solver.validate()?;
        Ok(opts)
    }
}

pub fn smooth(
    path: &Path,
    flags: &SmoothFlags,
    out: &Path,
    quiet: bool,
    allow_non_convex: bool,
) -> Result<()> {
    let mut mesh = read_quad_mesh(path)?;
    unamalla_core::preflight::check_size(
        "the mesh",
        path.display(),
        unamalla_core::mesh::HasNodes::num_nodes(&mesh) as f64,
        "nodes",
        unamalla_core::preflight::COST_PER_SMOOTH_NODE,
        reliability::limit()?,
    )?;
    let opts = flags.options()?;
    let mut progress = ProgressObserver::new(Duration::from_millis(200));
    let mut null = NullObserver;
    let observer: &mut dyn Observer = if quiet { &mut null } else { &mut progress };
    let report = optim::smooth(&mut mesh, &opts, observer)?;
    let v = unamalla_core::verify::verify_quads(
        &mesh,
        None,
        &unamalla_core::verify::VerifyOptions::default(),
    );
    let not_met = reliability::guarantee(&v, allow_non_convex, "smooth")?;
    let arrays = quad_cell_metrics(&mesh);
    let data: Vec<(&str, &[f64])> = arrays.iter().map(|(k, v)| (*k, v.as_slice())).collect();
    writing(out, || {
        let mut files = OutputFiles::new();
        let tmp = files.stage(out)?;
        io::write_vtk_quads(&tmp, &mesh, &data)?;
        Ok(files.commit()?)
    })?;
    eprintln!(
        "{}: Alfamin/mean {:.4}, Inocon {} (was {}), F {:.6e}",
        report.status,
        report.alfamin / report.alpha_bar,
        report.inocon,
        report.initial_inocon,
        report.f
    );
    reliability::finish(not_met)
}

/// `unamalla simplify`.
pub fn simplify(
    path: &Path,
    part: Option<usize>,
    method: &str,
    epsilon: Option<f64>,
    delta: Option<f64>,
    out: &Path,
    svg: Option<&Path>,
) -> Result<()> {
    let region = reliability::read_one_region(path, part)?;
    let opts = SimplifyOptions::default()
        .method(method.parse()?)
        .epsilon(epsilon)
        .delta(delta);
    let r = contour::simplify_region(&region, &opts)?;
    let overlay = svg.map(|_| contour::overlay_svg(&region, &r.region));
    writing(out, || {
        let mut files = OutputFiles::new();
        files.write(out, io::region_to_geojson(&r.region).as_bytes())?;
        if let (Some(p), Some(text)) = (svg, overlay) {
            files.write(p, text.as_bytes())?;
        }
        Ok(files.commit()?)
    })?;
    eprintln!(
        "{} -> {} vertices, area change {:.4} %, Hausdorff {:.4}",
        r.vertices_before,
        r.vertices_after,
        100.0 * r.relative_area_change,
        r.hausdorff
    );
    Ok(())
}

/// Reads decomposition file `path` and validates it against region `first`, or, if it does
/// not fit that one and `second` is a different region, against `second` (then the flag is
/// `true`); the error names both regions (their labels) and why the file fits neither.
fn read_decomposition(
    path: &Path,
    first: (&str, &Region),
    second: (&str, &Region),
) -> Result<(Decomposition, bool)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    match Decomposition::from_json(&text, first.1) {
        Ok(d) => Ok((d, false)),
        Err(e1) if first.1 == second.1 => Err(e1.into()),
        Err(e1) => match Decomposition::from_json(&text, second.1) {
            Ok(d) => Ok((d, true)),
            Err(e2) => bail!(
                "{}: fits neither {} ({e1}) nor {} ({e2})",
                path.display(),
                first.0,
                second.0
            ),
        },
    }
}

/// Arguments of `unamalla decompose`.
#[derive(clap::Args, Debug)]
pub struct DecomposeArgs {
    /// Region file (GeoJSON).
    pub region: PathBuf,
    /// Start from (or validate) this decomposition file.
    #[arg(long)]
    pub from: Option<PathBuf>,
    /// Output decomposition JSON.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Picture of the decomposition.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Decompose the region as read. By default it is first simplified exactly as
    /// `unamalla mesh` does (contour simplification, then removal of boundary features below
    /// the cell size of `--cells`), so the file fits `unamalla mesh --decomposition`.
    #[arg(long)]
    pub no_simplify: bool,
    /// Cell count the feature removal is sized for, as `unamalla mesh --cells` (at least 1).
    #[arg(long, default_value_t = 20_000, allow_negative_numbers = true, value_parser = reliability::positive_count)]
    pub cells: usize,
    /// For a MultiPolygon: which part (0-based); required when the file has several.
    #[arg(long)]
    pub part: Option<usize>,
}

/// `unamalla decompose`: the automatic decomposition (or a file's, validated) of the region
/// `unamalla mesh` would decompose — the mesher's default simplification and feature removal
/// for about `cells` cells ([`Mesher::prepare_region`]) — or of the region as read with
/// `no_simplify`. A `from` file that does not fit the simplified region is tried on the region
/// as read (a file made by hand for the original rings).
pub fn decompose(a: DecomposeArgs) -> Result<()> {
    let raw = reliability::read_one_region(&a.region, a.part)?;
    let region = if a.no_simplify {
        unamalla_core::preflight::check_unsimplified(&raw)?;
        raw.clone()
    } else {
        Mesher::new()
            .cells(a.cells)
            .prepare_region(&raw)?
            .mesh_region
    };
    let vertices = |r: &Region| r.rings().map(|p| p.len()).sum::<usize>();
    let raw_vertices = vertices(&raw);
    let (d, region) = match &a.from {
        Some(f) => {
            let (d, fits_raw) = read_decomposition(
                f,
                ("the simplified region", &region),
                ("the region as read", &raw),
            )?;
            (d, if fits_raw { raw } else { region })
        }
        None => (
            dec::decompose(&region, &dec::DecomposeOptions::default())?,
            region,
        ),
    };
    writing(&a.output, || {
        let mut files = OutputFiles::new();
        files.write(&a.output, d.to_json().as_bytes())?;
        if let Some(p) = &a.svg {
            files.write(p, d.to_svg(&region).as_bytes())?;
        }
        Ok(files.commit()?)
    })?;
    let tol = dec::Tolerances::default();
    let admissible = (0..d.blocks.len())
        .filter(|&b| d.block_admissible(b, &tol))
        .count();
    // the notes only on success: a failure is one `error:` line
    eprintln!("region: {raw_vertices} → {} vertices", vertices(&region));
    eprintln!(
        "{} blocks, {} cuts, {admissible} admissible",
        d.blocks.len(),
        d.cuts.len()
    );
    Ok(())
}

#[cfg(test)]
mod smooth_flag_tests;
