//! Output of maps: isoparametric curves (lines of constant ξ and constant η, as in the bottom
//! panels of the paper's Figs 8–11), the control net and the Jacobian field.
//!
//! This module formats; it does not touch the file system. Every writer takes a
//! `&mut dyn Write`, so callers pass the writer of `unamalla_io::atomic_write` (as the CLI and
//! `unamalla-core` do) and a failed run never leaves a partial file.
//!
//! * [`isocurves`]: `k_xi` curves `ξ = a/(k_xi−1)` and `k_eta` curves `η = b/(k_eta−1)`, each a
//!   polyline of `samples` points.
//! * [`write_isocurves_vtk`]: VTK legacy `POLYDATA` with one `LINES` cell per curve and a cell
//!   array `family` (0 = constant ξ, 1 = constant η).
//! * [`write_jacobian_vtk`]: VTK legacy `STRUCTURED_GRID` of the image points `x(ξ_a, η_b)` of an
//!   equispaced parameter grid with the point arrays `det_j`, `xi`, `eta`.
//! * [`write_net_vtk`]: the control net as a `STRUCTURED_GRID` with the cell array
//!   `min_alpha_rel` (`min α/ᾱ` of the four diagonal triangles, Definition 2).
//! * [`svg`]: a picture with the boundary control polygon, the control net, the control points
//!   and the isoparametric curves.

use std::io::{self, Write};

use glam::DVec2;
use unamalla_mesh::svg::{Style, SvgCanvas};

use crate::map::TensorMap;
use crate::net::ControlNet;
use crate::sample::det_j_grid;

/// Isoparametric curves of a map.
#[derive(Debug, Clone, PartialEq)]
pub struct IsoCurves {
    /// Curves of constant ξ (running in η), in increasing ξ.
    pub const_xi: Vec<Vec<DVec2>>,
    /// Curves of constant η (running in ξ), in increasing η.
    pub const_eta: Vec<Vec<DVec2>>,
}

/// `k_xi` curves of constant ξ and `k_eta` of constant η (each `≥ 2`), `samples ≥ 2` points per
/// curve.
pub fn isocurves(map: &TensorMap, k_xi: usize, k_eta: usize, samples: usize) -> IsoCurves {
    let (kx, ky, s) = (k_xi.max(2), k_eta.max(2), samples.max(2));
    let t = |l: usize, c: usize| l as f64 / (c - 1) as f64;
    IsoCurves {
        const_xi: (0..kx)
            .map(|a| (0..s).map(|l| map.eval(t(a, kx), t(l, s))).collect())
            .collect(),
        const_eta: (0..ky)
            .map(|b| (0..s).map(|l| map.eval(t(l, s), t(b, ky))).collect())
            .collect(),
    }
}

fn points3(w: &mut dyn Write, pts: &[DVec2]) -> io::Result<()> {
    writeln!(w, "POINTS {} double", pts.len())?;
    for p in pts {
        writeln!(w, "{} {} 0", p.x, p.y)?;
    }
    Ok(())
}

/// Writes the curves as VTK legacy `POLYDATA` (module docs).
pub fn write_isocurves_vtk(w: &mut dyn Write, curves: &IsoCurves) -> io::Result<()> {
    let all: Vec<&Vec<DVec2>> = curves.const_xi.iter().chain(&curves.const_eta).collect();
    let pts: Vec<DVec2> = all.iter().flat_map(|c| c.iter().copied()).collect();
    writeln!(w, "# vtk DataFile Version 3.0")?;
    writeln!(w, "isoparametric curves, written by unamalla-bspline")?;
    writeln!(w, "ASCII")?;
    writeln!(w, "DATASET POLYDATA")?;
    points3(w, &pts)?;
    let size: usize = all.iter().map(|c| c.len() + 1).sum();
    writeln!(w, "LINES {} {}", all.len(), size)?;
    let mut off = 0;
    for c in &all {
        write!(w, "{}", c.len())?;
        for k in 0..c.len() {
            write!(w, " {}", off + k)?;
        }
        writeln!(w)?;
        off += c.len();
    }
    writeln!(w, "CELL_DATA {}", all.len())?;
    writeln!(w, "SCALARS family int 1")?;
    writeln!(w, "LOOKUP_TABLE default")?;
    for _ in &curves.const_xi {
        writeln!(w, "0")?;
    }
    for _ in &curves.const_eta {
        writeln!(w, "1")?;
    }
    Ok(())
}

/// Writes `det J` on an `n_xi × n_eta` parameter grid as a VTK legacy `STRUCTURED_GRID` of the
/// image points with point arrays `det_j`, `xi`, `eta` (module docs).
pub fn write_jacobian_vtk(
    w: &mut dyn Write,
    map: &TensorMap,
    n_xi: usize,
    n_eta: usize,
) -> io::Result<()> {
    let (nx, ny) = (n_xi.max(2), n_eta.max(2));
    let dj = det_j_grid(map, nx, ny);
    writeln!(w, "# vtk DataFile Version 3.0")?;
    writeln!(w, "Jacobian field, written by unamalla-bspline")?;
    writeln!(w, "ASCII")?;
    writeln!(w, "DATASET STRUCTURED_GRID")?;
    writeln!(w, "DIMENSIONS {nx} {ny} 1")?;
    let mut pts = Vec::with_capacity(nx * ny);
    for b in 0..ny {
        for a in 0..nx {
            pts.push(map.eval(a as f64 / (nx - 1) as f64, b as f64 / (ny - 1) as f64));
        }
    }
    points3(w, &pts)?;
    writeln!(w, "POINT_DATA {}", nx * ny)?;
    writeln!(w, "SCALARS det_j double 1")?;
    writeln!(w, "LOOKUP_TABLE default")?;
    for v in &dj {
        writeln!(w, "{v}")?;
    }
    for (name, along_xi) in [("xi", true), ("eta", false)] {
        writeln!(w, "SCALARS {name} double 1")?;
        writeln!(w, "LOOKUP_TABLE default")?;
        for b in 0..ny {
            for a in 0..nx {
                let t = if along_xi {
                    a as f64 / (nx - 1) as f64
                } else {
                    b as f64 / (ny - 1) as f64
                };
                writeln!(w, "{t}")?;
            }
        }
    }
    Ok(())
}

/// Writes the control net as a VTK legacy `STRUCTURED_GRID` with the cell array
/// `min_alpha_rel` (module docs).
pub fn write_net_vtk(w: &mut dyn Write, net: &ControlNet) -> io::Result<()> {
    let (n, m) = (net.n(), net.m());
    writeln!(w, "# vtk DataFile Version 3.0")?;
    writeln!(w, "control net, written by unamalla-bspline")?;
    writeln!(w, "ASCII")?;
    writeln!(w, "DATASET STRUCTURED_GRID")?;
    writeln!(w, "DIMENSIONS {n} {m} 1")?;
    points3(w, net.points())?;
    let ab = net.alpha_bar();
    writeln!(w, "CELL_DATA {}", (n - 1) * (m - 1))?;
    writeln!(w, "SCALARS min_alpha_rel double 1")?;
    writeln!(w, "LOOKUP_TABLE default")?;
    for j in 0..m - 1 {
        for i in 0..n - 1 {
            let t = net.cell_triangles(i, j);
            let mn = t.iter().fold(f64::INFINITY, |a, &b| a.min(b));
            writeln!(w, "{}", mn / ab)?;
        }
    }
    Ok(())
}

/// An SVG picture `width_px` wide: boundary control polygon (grey fill), control net (light
/// grey), isoparametric curves (blue: constant ξ, red: constant η) and control points (dots).
pub fn svg(map: &TensorMap, curves: &IsoCurves, width_px: f64) -> String {
    let net = map.net();
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in net
        .points()
        .iter()
        .chain(curves.const_xi.iter().flatten())
        .chain(curves.const_eta.iter().flatten())
    {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let mut c = SvgCanvas::new(lo, hi, width_px);
    let mut fill = Style::fill("#eeeeee");
    fill.fill_opacity = 1.0;
    c.polygon(&net.boundary_polygon(), &fill);
    let thin = Style::stroke("#bbbbbb", 0.6);
    for j in 0..net.m() {
        let row: Vec<DVec2> = (0..net.n()).map(|i| net.get(i, j)).collect();
        c.polyline(&row, &thin);
    }
    for i in 0..net.n() {
        let col: Vec<DVec2> = (0..net.m()).map(|j| net.get(i, j)).collect();
        c.polyline(&col, &thin);
    }
    let blue = Style::stroke("#1f77b4", 0.9);
    let red = Style::stroke("#d62728", 0.9);
    for l in &curves.const_xi {
        c.polyline(l, &blue);
    }
    for l in &curves.const_eta {
        c.polyline(l, &red);
    }
    let dot = Style::fill("#333333");
    for p in net.points() {
        c.circle(*p, 1.4, &dot);
    }
    c.finish()
}
