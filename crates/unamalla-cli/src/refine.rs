//! `unamalla refine`: uniform refinement of a convex structured grid ([González Flores, §6.1.7,
//! RF11; §A.4 *Refinement Control Panel*]) by bilinear interpolation inside every cell
//! ([`StructuredGrid2::refined`](unamalla_core::mesh::StructuredGrid2::refined)): a factor `k`
//! inserts `k − 1` lines between consecutive grid lines, so `m × n` nodes become
//! `((m−1)k+1) × ((n−1)k+1)` and every cell is split into `k × k` convex cells.

use std::path::PathBuf;

use anyhow::{bail, Result};
use unamalla_core::io;
use unamalla_core::mesh::quality::{alpha_stats, quad_cell_metrics};

use crate::pde::{read_input_mesh, InputMesh};

/// Arguments of `unamalla refine`.
#[derive(clap::Args, Debug)]
pub struct RefineArgs {
    /// Structured grid file (`.vtk`, `.vts`, `.xy`, `.red`, `.mesh`).
    pub mesh: PathBuf,
    /// Every cell becomes `k × k` cells (k ≥ 1).
    #[arg(long, default_value_t = 2)]
    pub factor: usize,
    /// Different factor along i (the bottom side), overriding --factor there.
    #[arg(long)]
    pub factor_i: Option<usize>,
    /// Different factor along j (the left side), overriding --factor there.
    #[arg(long)]
    pub factor_j: Option<usize>,
    /// Output file: `.vtk` (with per-cell quality), `.vts`, `.xy` or `.red`.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `unamalla refine`.
pub fn run(a: RefineArgs) -> Result<()> {
    let grid = match read_input_mesh(&a.mesh)? {
        InputMesh::Grid(g) => g,
        InputMesh::Quads(_) => bail!(
            "{}: refinement needs a structured grid (a quad mesh without global i/j lines)",
            a.mesh.display()
        ),
    };
    let (ki, kj) = (
        a.factor_i.unwrap_or(a.factor),
        a.factor_j.unwrap_or(a.factor),
    );
    if ki == 0 || kj == 0 {
        bail!("the refinement factors must be at least 1, got {ki} × {kj}");
    }
    // RF11: the input must be convex (bilinear refinement of a folded cell stays folded)
    let st = alpha_stats(&grid);
    if st.non_convex_cells > 0 {
        bail!(
            "{}: the grid has {} non-convex cell(s) (min α = {:.3e}); refinement needs a convex grid — untangle it first (`unamalla smooth`)",
            a.mesh.display(),
            st.non_convex_cells,
            st.min
        );
    }
    let ext = a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if !matches!(ext.as_str(), "vtk" | "vts" | "xy" | "red") {
        bail!(
            "{}: unknown output format (expected .vtk, .vts, .xy or .red)",
            a.output.display()
        );
    }
    let fine_nodes =
        ((grid.m() - 1) as f64 * ki as f64 + 1.0) * ((grid.n() - 1) as f64 * kj as f64 + 1.0);
    unamalla_core::preflight::check_size(
        "--factor",
        format!("{ki}x{kj}"),
        fine_nodes,
        "nodes",
        unamalla_core::preflight::COST_PER_TFI_NODE,
        crate::reliability::limit()?,
    )?;
    let fine = grid.refined(ki - 1, kj - 1)?;
    let cells = quad_cell_metrics(&fine);
    let cd: Vec<(&str, &[f64])> = cells.iter().map(|(k, v)| (*k, v.as_slice())).collect();
    let name = a
        .output
        .file_name()
        .and_then(|s| s.to_str())
        .unwrap_or("refined");
    crate::commands::writing(&a.output, || {
        let mut files = unamalla_core::output::OutputFiles::new();
        let tmp = files.stage(&a.output)?;
        match ext.as_str() {
            "vtk" => io::write_vtk_structured2(&tmp, &fine, &cd)?,
            "vts" => io::write_vts2(&tmp, &fine, &cd)?,
            "xy" => io::write_xy(&tmp, &fine, name)?,
            _ => io::write_red(&tmp, &fine, name)?,
        }
        Ok(files.commit()?)
    })?;
    println!(
        "{} × {} → {} × {} nodes ({} cells, {} non-convex)",
        grid.m(),
        grid.n(),
        fine.m(),
        fine.n(),
        fine.num_cells(),
        alpha_stats(&fine).non_convex_cells
    );
    Ok(())
}
