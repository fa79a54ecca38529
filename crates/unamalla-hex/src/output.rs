//! The output files of a run: the mesh as VTK (`mesh.vts`, `mesh.vtu`) with the per-cell
//! quality and cell class, `report.json`, and the histograms as an SVG plot.

use std::path::{Path, PathBuf};

use unamalla_mesh::hexgen::{classify_cells, CellClass};
use unamalla_mesh::svg::{Style, SvgCanvas};
use unamalla_mesh::{DVec2, HexMesh, StructuredGrid3};

use crate::{HexError, HexHistograms, HexRunReport};

/// An SVG with three bar charts of the histograms (App. B.6): tetrahedron volume sign,
/// interior-face planarity by `|cos|` decade (bars at or above the tolerance in red), and
/// edge lengths.
pub fn histograms_svg(h: &HexHistograms, title: &str) -> String {
    // world units: three panels of 10 × 6 side by side, y up
    let mut c = SvgCanvas::new(DVec2::new(0.0, -1.5), DVec2::new(33.0, 8.0), 990.0);
    c.text(DVec2::new(16.5, 7.5), title, 16.0, "#000000");
    let panel = |c: &mut SvgCanvas, x0: f64, name: &str, bars: &[(String, usize, &str)]| {
        let maxc = bars.iter().map(|b| b.1).max().unwrap_or(0).max(1) as f64;
        let w = 10.0 / bars.len().max(1) as f64;
        c.polyline(
            &[
                DVec2::new(x0, 6.0),
                DVec2::new(x0, 0.0),
                DVec2::new(x0 + 10.0, 0.0),
            ],
            &Style::stroke("#000000", 1.0),
        );
        c.text(DVec2::new(x0 + 5.0, 6.6), name, 13.0, "#000000");
        for (k, (label, count, color)) in bars.iter().enumerate() {
            let hgt = 5.5 * *count as f64 / maxc;
            let xl = x0 + k as f64 * w + 0.1 * w;
            let xr = x0 + (k + 1) as f64 * w - 0.1 * w;
            if *count > 0 {
                c.polygon(
                    &[
                        DVec2::new(xl, 0.0),
                        DVec2::new(xr, 0.0),
                        DVec2::new(xr, hgt),
                        DVec2::new(xl, hgt),
                    ],
                    &Style::fill(color),
                );
            }
            c.text(
                DVec2::new(0.5 * (xl + xr), hgt + 0.3),
                &count.to_string(),
                9.0,
                "#333333",
            );
            c.text(DVec2::new(0.5 * (xl + xr), -0.5), label, 9.0, "#333333");
        }
    };
    panel(
        &mut c,
        0.5,
        "tetrahedra: sign of V",
        &[
            ("V>0".into(), h.tets_positive, "#1f77b4"),
            ("V=0".into(), h.tets_zero, "#ff7f0e"),
            ("V<0".into(), h.tets_negative, "#d62728"),
        ],
    );
    let dec: Vec<(String, usize, &str)> = h
        .face_cos_decades
        .iter()
        .zip(&h.face_cos_labels)
        .enumerate()
        .map(|(k, (n, l))| (l.clone(), *n, if k >= 5 { "#d62728" } else { "#1f77b4" }))
        .collect();
    panel(&mut c, 11.5, "interior faces: |cos| decade", &dec);
    let el = &h.edge_lengths;
    let bars: Vec<(String, usize, &str)> = el
        .counts
        .iter()
        .enumerate()
        .map(|(k, n)| {
            let label = if k == 0 || k + 1 == el.counts.len() {
                format!("{:.3}", el.edges[k.min(el.edges.len() - 1)])
            } else {
                String::new()
            };
            (label, *n, "#2ca02c")
        })
        .collect();
    panel(&mut c, 22.5, "edge lengths", &bars);
    c.finish()
}

/// Files written by [`write_outputs`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HexOutputFiles {
    /// `mesh.vts` (structured grid with per-cell quality).
    pub vts: PathBuf,
    /// `mesh.vtu` (unstructured hexahedra with per-cell quality).
    pub vtu: PathBuf,
    /// `report.json`.
    pub report: PathBuf,
    /// `histograms.svg`.
    pub svg: PathBuf,
}

/// Writes `mesh.vts`, `mesh.vtu` (both with the per-cell Verdict metrics, `min_tet_det`,
/// `convex_10tet`, `max_face_cos` and the cell class 0 corner / 1 edge / 2 face /
/// 3 interior / 4 other), `report.json` and `histograms.svg` into `dir` (created if
/// missing). Every file is written atomically.
pub fn write_outputs(
    dir: &Path,
    grid: &StructuredGrid3,
    report: &HexRunReport,
) -> Result<HexOutputFiles, HexError> {
    std::fs::create_dir_all(dir).map_err(|e| HexError::FaceFile {
        path: dir.to_path_buf(),
        line: 0,
        reason: format!("cannot create the output directory: {e}"),
    })?;
    let mut cols = unamalla_mesh::quality::hex_cell_metrics(grid);
    let cls: Vec<f64> = classify_cells(grid)
        .iter()
        .map(|c| match c {
            CellClass::Corner => 0.0,
            CellClass::Edge => 1.0,
            CellClass::Face => 2.0,
            CellClass::Interior => 3.0,
            CellClass::Other(_) => 4.0,
        })
        .collect();
    cols.push(("cell_class", cls));
    let data: Vec<(&str, &[f64])> = cols.iter().map(|(k, v)| (*k, v.as_slice())).collect();
    let files = HexOutputFiles {
        vts: dir.join("mesh.vts"),
        vtu: dir.join("mesh.vtu"),
        report: dir.join("report.json"),
        svg: dir.join("histograms.svg"),
    };
    unamalla_io::write_vts3(&files.vts, grid, &data)?;
    unamalla_io::write_vtu_hexes(&files.vtu, &HexMesh::from_grid(grid), &data)?;
    let json = report.to_json();
    unamalla_io::atomic_write(&files.report, |w| w.write_all(json.as_bytes()))?;
    let title = format!(
        "{} {}x{}x{}: non-convex {}, non-hex interior {}, max |cos| {:.2e}",
        report.case,
        report.dims.0,
        report.dims.1,
        report.dims.2,
        report.non_convex_cells,
        report.non_hex_interior_cells,
        report.max_abs_cos
    );
    let svg = histograms_svg(&report.histograms, &title);
    unamalla_io::atomic_write(&files.svg, |w| w.write_all(svg.as_bytes()))?;
    Ok(files)
}
