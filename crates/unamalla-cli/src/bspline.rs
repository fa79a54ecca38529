//! `unamalla bspline <region> --degree 1|2 --net NxM -o outdir`: B-spline parametrizations of a
//! region with injectivity certificates ([Abelló et al.]; crate `unamalla-bspline`).
//!
//! How a region becomes control nets:
//! * **default (one net)**: the region must be simply connected. Its outer ring is split at four
//!   corners (automatic, as `unamalla tfi --auto-corners`, or `--corners a,b,c,d`) into south,
//!   east, north and west sides; each side is resampled by arc length to `N` (south/north) or `M`
//!   (west/east) points, which are used directly as the control points of the quadratic
//!   boundary curves (as `BoundaryCurves::from_ring`). The interior control points minimize
//!   `½S_{ω,ε} + ½F_AO` from a TFI start; then the map of `--degree` is built and certified.
//!   The region's boundary polygon is the control polygon Ω'; the biquadratic map's image is
//!   bounded by the quadratic B-spline curves of that polygon.
//! * **`--blocks`**: the region is meshed by the block-structured pipeline (`unamalla mesh`,
//!   about `--cells` cells, default `N·M`), and every block's grid is used as a control net as it
//!   is (no further optimization; the pipeline's cells are convex), one map per block.
//!
//! Outputs (atomic writes): `report.json` (`min_det_j` sampled, `theorem1`/`theorem2` as
//! `true`/`false`/`"not applicable"`, `bernstein`, `certified`, `seconds`, details), and for
//! every map `net.vtk` (control net with per-cell `min_alpha_rel`), `isocurves.vtk`,
//! `isocurves.svg` and `jacobian.vtk` (det J on a 201 × 201 parameter grid); in block mode the
//! files are prefixed `block-K-`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use serde_json::{json, Value};
use unamalla_core::bspline::{
    certify_map, export, optimize_interior, BernsteinOutcome, BoundaryCurves, Certificates,
    ControlNet, Degree, Fairing, FitParameters, InteriorOptions, TensorMap,
};
use unamalla_core::bspline_maps::{block_maps, BlockMapOptions};
use unamalla_core::io;
use unamalla_core::pipeline::Mesher;
use unamalla_core::single_block::{resolve_corners, Corners};

/// Arguments of `unamalla bspline`.
#[derive(clap::Args, Debug)]
pub struct BsplineArgs {
    /// Region file (GeoJSON).
    pub region: PathBuf,
    /// Polynomial degree of the map: 1 (bilinear) or 2 (biquadratic).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub degree: u8,
    /// Control net size `NxM` (N control points along the south side, M along the west side;
    /// at least 3x3).
    #[arg(long, default_value = "18x18", value_parser = parse_net)]
    pub net: (usize, usize),
    /// Four corner indices into the outer ring as listed in the file (Q first, then
    /// counter-clockwise); default automatic.
    #[arg(long, value_parser = crate::parse_corners, conflicts_with = "blocks")]
    pub corners: Option<[usize; 4]>,
    /// Boundary curves by a least-squares fit of each side (quadratic, uniform knots, ends at
    /// the corners; `--net NxM` gives the control point counts) with `chord-length` or
    /// `centripetal` sample parameters, instead of using the resampled sides directly as
    /// control polygons. Ragged sides (e.g. texas) need it: the resampled control polygon
    /// self-intersects.
    #[arg(long, value_parser = ["chord-length", "centripetal"], conflicts_with = "blocks")]
    pub fit: Option<String>,
    /// With --fit: the weight λ of the fit's second-difference (fairing) penalty on every
    /// side, or `auto`: λ starts at 0 and goes up the ladder 1e-4, 3.2e-4, …, 1000 on the sides
    /// whose curves make the control polygon cross itself or a corner reflex, until it is
    /// valid (report.json `boundary_fit.fairing`: λ of south, east, north, west).
    #[arg(long, default_value = "auto", requires = "fit", value_parser = parse_fairing)]
    pub fairing: Fairing,
    /// One map per block of the pipeline's block-structured mesh instead of one net.
    #[arg(long)]
    pub blocks: bool,
    /// With --blocks: about this many cells (default N·M).
    #[arg(long, requires = "blocks")]
    pub cells: Option<usize>,
    /// Samples per direction of the dense det J sample (the paper used 10000).
    #[arg(long, default_value_t = 1000)]
    pub samples: usize,
    /// Maximum subdivision depth of the Bernstein-coefficient test.
    #[arg(long, default_value_t = 4)]
    pub subdivide: usize,
    /// ω of S_{ω,ε} (interior optimization).
    #[arg(long, default_value_t = 20.0)]
    pub omega: f64,
    /// ε of S_{ω,ε} and of the ε-convexity target.
    #[arg(long, default_value_t = 0.05)]
    pub eps: f64,
    /// Output directory.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print report.json on stdout.
    #[arg(long)]
    pub json: bool,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
}

fn parse_net(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected NxM (e.g. 18x18), got '{s}'"))?;
    let n: usize = a.trim().parse().map_err(|_| format!("bad N in '{s}'"))?;
    let m: usize = b.trim().parse().map_err(|_| format!("bad M in '{s}'"))?;
    if n < 3 || m < 3 {
        return Err(format!(
            "a control net needs at least 3x3 points, got {n}x{m}"
        ));
    }
    Ok((n, m))
}

fn parse_fairing(s: &str) -> Result<Fairing, String> {
    if s.eq_ignore_ascii_case("auto") {
        return Ok(Fairing::Auto);
    }
    match s.trim().parse::<f64>() {
        Ok(l) if l >= 0.0 && l.is_finite() => Ok(Fairing::Fixed(l)),
        _ => Err(format!("expected `auto` or a finite λ ≥ 0, got '{s}'")),
    }
}

fn write_with(
    path: &Path,
    f: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<()> {
    io::atomic_write(path, f).with_context(|| format!("writing {}", path.display()))
}

/// `true`/`false`/`"not applicable"`.
fn outcome(v: Option<bool>) -> Value {
    match v {
        Some(b) => Value::Bool(b),
        None => Value::String("not applicable".into()),
    }
}

fn bernstein_json(c: &Certificates) -> Value {
    match c.bernstein.outcome {
        BernsteinOutcome::Certified { lower_bound } => {
            json!({"outcome": "certified", "lower_bound": lower_bound})
        }
        BernsteinOutcome::Refuted { at, value } => {
            json!({"outcome": "refuted", "at": [at.0, at.1], "value": value})
        }
        BernsteinOutcome::Inconclusive { undecided } => {
            json!({"outcome": "inconclusive", "undecided_subpatches": undecided})
        }
    }
}

fn write_map_files(dir: &Path, prefix: &str, map: &TensorMap) -> Result<()> {
    let curves = export::isocurves(map, map.net().n().max(11), map.net().m().max(11), 200);
    write_with(&dir.join(format!("{prefix}net.vtk")), |w| {
        export::write_net_vtk(w, map.net())
    })?;
    write_with(&dir.join(format!("{prefix}isocurves.vtk")), |w| {
        export::write_isocurves_vtk(w, &curves)
    })?;
    let svg = export::svg(map, &curves, 1000.0);
    write_with(&dir.join(format!("{prefix}isocurves.svg")), |w| {
        w.write_all(svg.as_bytes())
    })?;
    write_with(&dir.join(format!("{prefix}jacobian.vtk")), |w| {
        export::write_jacobian_vtk(w, map, 201, 201)
    })
}

/// `unamalla bspline`.
pub fn run(a: BsplineArgs) -> Result<()> {
    let t0 = Instant::now();
    if !(2..=100_000).contains(&a.samples) {
        crate::reliability::usage!("--samples must be between 2 and 100000 per direction");
    }
    let degree = Degree::from_degree(a.degree as usize)?;
    let (n, m) = a.net;
    unamalla_core::preflight::check_size(
        "--net",
        format!("{n}x{m}"),
        n as f64 * m as f64,
        "control points",
        unamalla_core::preflight::COST_PER_BSPLINE_NET_POINT,
        crate::reliability::limit()?,
    )?;
    let region = crate::reliability::read_one_region(&a.region, None)?;
    let out = unamalla_core::output::OutputDir::create(&a.output)?;
    let name = a
        .region
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let report = if a.blocks {
        let cells = a.cells.unwrap_or(n * m);
        if !a.quiet {
            eprintln!("· meshing {name} into blocks (about {cells} cells)");
        }
        let result = Mesher::new().cells(cells).mesh(&region)?;
        if !a.quiet {
            eprintln!(
                "· {} blocks; building and certifying their maps",
                result.mesh.blocks().len()
            );
        }
        let opts = BlockMapOptions::default()
            .samples(a.samples)
            .subdivision(a.subdivide)
            .biquadratic(degree == Degree::Biquadratic);
        let maps = block_maps(&result.mesh, &opts)?;
        let mut blocks = Vec::new();
        let mut min_det = f64::INFINITY;
        let mut t1_all = true;
        let mut t2_all: Option<bool> = None;
        let mut certified_all = true;
        for bm in &maps {
            let (sample, cert) = match (&bm.biquadratic_certificates, degree) {
                (Some(c), Degree::Biquadratic) => (c.sample, Some(c)),
                _ => (bm.bilinear_sample, None),
            };
            min_det = min_det.min(sample.min);
            t1_all &= bm.theorem1.holds;
            let t2 = cert.and_then(|c| c.theorem2.as_ref().map(|t| t.holds));
            if degree == Degree::Biquadratic {
                t2_all = Some(t2_all.unwrap_or(true) && t2.unwrap_or(false));
                certified_all &= cert.is_some_and(|c| c.certified);
            } else {
                certified_all &= bm.theorem1.holds;
            }
            let g = &result.mesh.blocks()[bm.block];
            blocks.push(json!({
                "block": bm.block,
                "net": [g.m(), g.n()],
                "min_det_j": sample.min,
                "min_det_j_at": [sample.argmin.0, sample.argmin.1],
                "max_det_j": sample.max,
                "theorem1": bm.theorem1.holds,
                "theorem2": outcome(if degree == Degree::Biquadratic { t2 } else { None }),
                "bernstein": cert.map(bernstein_json),
                "certified": if degree == Degree::Biquadratic { cert.is_some_and(|c| c.certified) } else { bm.theorem1.holds },
            }));
        }
        let report = json!({
            "region": name,
            "mode": "blocks",
            "degree": a.degree,
            "blocks": blocks,
            "cells": result.report.cells,
            "samples": a.samples,
            "min_det_j": min_det,
            "theorem1": outcome(if degree == Degree::Bilinear { Some(t1_all) } else { None }),
            "net_convex": t1_all,
            "theorem2": outcome(t2_all),
            "certified": certified_all,
            "seconds": t0.elapsed().as_secs_f64(),
        });
        for (k, g) in result.mesh.blocks().iter().enumerate() {
            let net = ControlNet::from_grid(g);
            let map = if degree == Degree::Biquadratic && (g.m() < 3 || g.n() < 3) {
                TensorMap::new(Degree::Bilinear, net)?
            } else {
                TensorMap::new(degree, net)?
            };
            crate::commands::writing(&a.output, || {
                write_map_files(out.path(), &format!("block-{k}-"), &map)
            })?;
        }
        report
    } else {
        if !region.holes().is_empty() {
            bail!(
                "the region has {} hole(s); one control net needs a simply connected region (use --blocks)",
                region.holes().len()
            );
        }
        let corners = match a.corners {
            Some(c) => Corners::Input(c),
            None => Corners::Auto,
        };
        let c = resolve_corners(&region, &corners, n, m)?;
        let (boundary, fit_report) = match a.fit.as_deref() {
            None => (
                BoundaryCurves::from_ring(region.outer().points(), c, n, m)?,
                None,
            ),
            Some(kind) => {
                let kind = if kind == "centripetal" {
                    FitParameters::Centripetal
                } else {
                    FitParameters::ChordLength
                };
                let f =
                    BoundaryCurves::fit_ring(region.outer().points(), c, n, m, kind, a.fairing)?;
                (f.curves, Some((kind, f.residuals, f.fairing)))
            }
        };
        let mut net = ControlNet::from_boundary(&boundary)?;
        if !a.quiet {
            eprintln!("· {name}: {n}x{m} control net; optimizing the interior control points");
        }
        let iopts = InteriorOptions::default().omega(a.omega).eps(a.eps);
        let interior = optimize_interior(&mut net, &iopts)?;
        let map = TensorMap::new(degree, net)?;
        if !a.quiet {
            eprintln!(
                "· certificates and {}x{} det J samples",
                a.samples, a.samples
            );
        }
        let cert = certify_map(&map, a.samples, a.subdivide)?;
        let s = cert.sample;
        let report = json!({
            "region": name,
            "mode": "single",
            "degree": a.degree,
            "net": [n, m],
            "corners_ring_indices": c,
            "boundary_fit": fit_report.map(|(k, r, lambda)| json!({"parameters": k, "fairing": lambda, "south": r[0], "east": r[1], "north": r[2], "west": r[3]})),
            "samples": a.samples,
            "min_det_j": s.min,
            "min_det_j_at": [s.argmin.0, s.argmin.1],
            "max_det_j": s.max,
            "max_det_j_at": [s.argmax.0, s.argmax.1],
            "mean_det_j": s.mean,
            "min_det_j_over_mean": s.min_over_mean(),
            "nonpositive_samples": s.nonpositive,
            "theorem1": outcome(if degree == Degree::Bilinear { Some(cert.theorem1.holds) } else { None }),
            "net_convex": cert.theorem1.holds,
            "theorem2": outcome(cert.theorem2.as_ref().map(|t| t.holds)),
            "bernstein": bernstein_json(&cert),
            "certified": cert.certified,
            "interior": serde_json::to_value(&interior)?,
            "certificates": serde_json::to_value(&cert)?,
            "seconds": t0.elapsed().as_secs_f64(),
        });
        crate::commands::writing(&a.output, || write_map_files(out.path(), "", &map))?;
        report
    };
    let text = serde_json::to_string_pretty(&report)?;
    crate::commands::writing(&a.output, || {
        write_with(&out.join("report.json"), |w| w.write_all(text.as_bytes()))?;
        Ok(out.commit()?)
    })?;
    if a.json {
        println!("{text}");
    } else if !a.quiet {
        println!(
            "{}: degree {}, min det J {:.6e} (sampled {}x{}), theorem1 {}, theorem2 {}, certified {}, {:.2} s -> {}",
            name,
            a.degree,
            report["min_det_j"].as_f64().unwrap_or(f64::NAN),
            a.samples,
            a.samples,
            report["theorem1"],
            report["theorem2"],
            report["certified"],
            t0.elapsed().as_secs_f64(),
            a.output.display()
        );
    }
    Ok(())
}
