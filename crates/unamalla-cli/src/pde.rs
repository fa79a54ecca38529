//! `unamalla pde`: solve `a·U_xx + 2b·U_xy + c·U_yy + d·U = g` on a mesh file (the PDE
//! application of [González Flores, §6.1.7, §A.4.5]; the references are listed in
//! `docs/references.md` of the repository) with [`unamalla_pde`], and write the solution as VTK
//! point data `u`, a Geomview `MESH` surface (structured grids) and PNG/SVG colour plots.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use unamalla_core::io::{self, VtkMesh};
use unamalla_core::mesh::quality::quad_cell_metrics;
use unamalla_core::mesh::{QuadMesh, StructuredGrid2};
use unamalla_core::render;
use unamalla_pde::manufactured::Manufactured;
use unamalla_pde::{
    solve_grid, solve_quads, Equation, Method, SideValue, Solution, SolveOptions, Source,
};

/// Arguments of `unamalla pde`.
#[derive(clap::Args, Debug)]
pub struct PdeArgs {
    /// Mesh file: VTK legacy `.vtk` (structured grid or quads), `.vts`/`.vtu`, UNAMALLA `.xy`
    /// / `.red`, or Geomview `.mesh`. Structured grids take Dirichlet data per side; a general
    /// quad mesh (e.g. the block mesh of `unamalla mesh`) one value for the whole boundary.
    pub mesh: PathBuf,
    /// Coefficient of U_xx.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub a: f64,
    /// Half the coefficient of U_xy (the equation has 2b·U_xy).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub b: f64,
    /// Coefficient of U_yy.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub c: f64,
    /// Coefficient of U.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub d: f64,
    /// Right-hand side: `const:V` or `sin:A` (A·sin(π x̂)·sin(π ŷ) over the bounding box).
    #[arg(long, default_value = "const:0", allow_hyphen_values = true)]
    pub g: String,
    /// Dirichlet data: comma-separated `SIDE=KIND:V` with SIDE 1..4 (bottom, right, top, left)
    /// or `all`, KIND `const`, `parabolic` or `sin` (V = peak value); unspecified sides are 0.
    /// Example: `1=parabolic:1,3=const:0.5`.
    #[arg(long, default_value = "all=const:0", allow_hyphen_values = true)]
    pub bc: String,
    /// Verify with a manufactured solution instead of --g/--bc: `sin-cosh` (U = sin(πx̂)cosh(ŷ))
    /// or `poly` (a cubic) in the coordinates x̂ = (x − x_min)/L, ŷ = (y − y_min)/L of the mesh's
    /// bounding box (L its larger side), so any map unit works; g = L U, U on the boundary; the
    /// error is printed, also relative to max |U|.
    #[arg(long)]
    pub manufactured: Option<String>,
    /// Linear solver: `sor` (automatic ω) or `direct` (sparse LU).
    #[arg(long, default_value = "sor")]
    pub solver: String,
    /// Fixed SOR relaxation factor in (0, 2) instead of the automatic one.
    #[arg(long)]
    pub omega: Option<f64>,
    /// SOR tolerance (largest correction of a sweep relative to max(1, max|U|)).
    #[arg(long, default_value_t = 1e-11)]
    pub tol: f64,
    /// SOR sweep limit.
    #[arg(long, default_value_t = 200_000)]
    pub max_iter: usize,
    /// Output directory: `solution.vtk` (point array `u`, cell quality), `solution.mesh`
    /// (Geomview, structured grids), `solution.png`, `solution.svg`.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// A mesh as read from a file.
pub enum InputMesh {
    /// A structured grid.
    Grid(StructuredGrid2),
    /// A conformal quad mesh.
    Quads(QuadMesh),
}

/// Reads a structured grid or a quad mesh, by extension.
pub fn read_input_mesh(path: &Path) -> Result<InputMesh> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let from_vtk = |m: VtkMesh| -> Result<InputMesh> {
        Ok(match m {
            VtkMesh::Structured2(g) => InputMesh::Grid(g),
            VtkMesh::Quads(q) => InputMesh::Quads(q),
            VtkMesh::Structured3(_) | VtkMesh::Hexes(_) => {
                bail!(
                    "{}: a 3D mesh; this command needs a planar quad mesh",
                    path.display()
                )
            }
        })
    };
    match ext.as_str() {
        "vtk" => from_vtk(io::read_vtk(path)?.mesh),
        "vts" | "vtu" => from_vtk(io::read_vtk_xml(path)?.mesh),
        "xy" => Ok(InputMesh::Grid(io::read_xy(path)?.grid)),
        "red" => Ok(InputMesh::Grid(io::read_red(path)?.grid)),
        "mesh" => Ok(InputMesh::Grid(
            io::read_geomview_mesh(path)?
                .grid()
                .with_context(|| format!("{}", path.display()))?,
        )),
        _ => bail!(
            "{}: unknown mesh format (expected .vtk, .vts, .vtu, .xy, .red or .mesh)",
            path.display()
        ),
    }
}

fn parse_number(s: &str, what: &str) -> Result<f64> {
    let v: f64 = s
        .trim()
        .parse()
        .with_context(|| format!("{what}: '{s}' is not a number"))?;
    if !v.is_finite() {
        bail!("{what}: '{s}' is not a finite number");
    }
    Ok(v)
}

fn parse_source(s: &str) -> Result<Source> {
    let (kind, v) = s
        .split_once(':')
        .with_context(|| format!("--g: expected KIND:VALUE (const:1, sin:2), got '{s}'"))?;
    let v = parse_number(v, "--g")?;
    Ok(match kind.trim() {
        "const" => Source::Constant(v),
        "sin" => Source::Sinusoidal { amplitude: v },
        k => crate::reliability::usage!("--g: unknown kind '{k}' (const, sin)"),
    })
}

fn parse_side_value(s: &str) -> Result<SideValue> {
    let (kind, v) = s.split_once(':').with_context(|| {
        format!("--bc: expected KIND:VALUE (const:0, parabolic:1, sin:1), got '{s}'")
    })?;
    let v = parse_number(v, "--bc")?;
    Ok(match kind.trim() {
        "const" => SideValue::Constant(v),
        "parabolic" => SideValue::Parabolic { peak: v },
        "sin" => SideValue::Sinusoidal { peak: v },
        k => crate::reliability::usage!("--bc: unknown kind '{k}' (const, parabolic, sin)"),
    })
}

/// Parses `--bc` into the four sides (bottom, right, top, left).
pub fn parse_bc(s: &str) -> Result<[SideValue; 4]> {
    let mut sides: [SideValue; 4] = std::array::from_fn(|_| SideValue::Constant(0.0));
    for item in s.split(',').filter(|t| !t.trim().is_empty()) {
        let (key, val) = item
            .split_once('=')
            .with_context(|| format!("--bc: expected SIDE=KIND:VALUE, got '{item}'"))?;
        let v = parse_side_value(val)?;
        match key.trim() {
            "all" => sides = std::array::from_fn(|_| v.clone()),
            k => {
                let i: usize = k
                    .parse()
                    .ok()
                    .filter(|i| (1..=4).contains(i))
                    .with_context(|| format!("--bc: side '{k}' must be 1, 2, 3, 4 or all"))?;
                sides[i - 1] = v;
            }
        }
    }
    Ok(sides)
}

/// Largest magnitude of a coefficient or data value: the 9-point stencil multiplies them by
/// each other and by squared mesh spacings, so beyond ~10¹⁵⁰ the products overflow f64 (10³⁰⁸).
pub const MAX_DATA_MAGNITUDE: f64 = 1e150;

/// Numeric overflow named before solving (instead of "SOR diverged" after it).
fn check_overflow(a: &PdeArgs) -> Result<()> {
    for (name, v) in [("--a", a.a), ("--b", a.b), ("--c", a.c), ("--d", a.d)] {
        if !v.is_finite() || v.abs() > MAX_DATA_MAGNITUDE {
            crate::reliability::usage!(
                "{name} {v}: numeric overflow — |value| above {MAX_DATA_MAGNITUDE:e} overflows the stencil products; rescale the equation"
            );
        }
    }
    for (name, text) in [("--g", &a.g), ("--bc", &a.bc)] {
        for tok in text.split([',', '=', ':']) {
            if let Ok(v) = tok.trim().parse::<f64>() {
                if !v.is_finite() || v.abs() > MAX_DATA_MAGNITUDE {
                    crate::reliability::usage!(
                        "{name} {text}: numeric overflow — the value {v:e} is above {MAX_DATA_MAGNITUDE:e} in magnitude and overflows f64 in the stencil; rescale the data"
                    );
                }
            }
        }
    }
    Ok(())
}

/// `unamalla pde`.
pub fn run(a: PdeArgs) -> Result<()> {
    let mesh = read_input_mesh(&a.mesh)?;
    let method = match a.solver.as_str() {
        "sor" => Method::Sor { omega: a.omega },
        "direct" => {
            if a.omega.is_some() {
                crate::reliability::usage!("--omega applies to --solver sor only");
            }
            Method::Direct
        }
        s => crate::reliability::usage!("--solver: unknown solver '{s}' (sor, direct)"),
    };
    let opts = SolveOptions::default()
        .method(method)
        .tol(a.tol)
        .max_iterations(a.max_iter);
    let nodes: Vec<_> = match &mesh {
        InputMesh::Grid(g) => unamalla_core::mesh::HasNodes::nodes(g).to_vec(),
        InputMesh::Quads(q) => unamalla_core::mesh::HasNodes::nodes(q).to_vec(),
    };
    let man = match &a.manufactured {
        // in the mesh's bounding box mapped into the unit square, so a map in kilometres
        // does not overflow cosh
        Some(name) => Some(
            Manufactured::by_name(name)
                .with_context(|| {
                    format!("--manufactured: unknown solution '{name}' (sin-cosh, poly)")
                })?
                .on_box(&nodes)
                .with_context(|| {
                    format!(
                        "--manufactured: {} has a bounding box of zero or non-finite size",
                        a.mesh.display()
                    )
                })?,
        ),
        None => None,
    };
    let eq = match &man {
        Some(m) => m.equation(a.a, a.b, a.c, a.d),
        None => Equation::new(a.a, a.b, a.c, a.d, parse_source(&a.g)?),
    };
    let sides = match &man {
        Some(m) => m.sides(),
        None => parse_bc(&a.bc)?,
    };
    check_overflow(&a)?;
    let sol: Solution = match &mesh {
        InputMesh::Grid(g) => solve_grid(g, &eq, &sides, &opts)?,
        InputMesh::Quads(q) => {
            let bc = match &man {
                Some(m) => m.boundary(),
                None => {
                    let uniform =
                        a.bc.split(',')
                            .filter(|t| !t.trim().is_empty())
                            .all(|t| t.split_once('=').is_some_and(|(k, _)| k.trim() == "all"));
                    if !uniform {
                        crate::reliability::usage!("--bc: {} is a general quad mesh without four sides; give `all=const:V`", a.mesh.display());
                    }
                    sides[0].clone()
                }
            };
            solve_quads(q, &eq, &bc, &opts)?
        }
    };

    if let Some(k) = sol.u.iter().position(|v| !v.is_finite()) {
        bail!(
            "numeric overflow: the solution is not finite at node {k} ({}); the data (--a … --d, --g, --bc) are too large for f64 — rescale the equation",
            sol.u[k]
        );
    }
    let out = unamalla_core::output::OutputDir::create(&a.output)?;
    let vtk = out.join("solution.vtk");
    let png = out.join("solution.png");
    let svg = out.join("solution.svg");
    let gm = out.join("solution.mesh");
    crate::commands::writing(&a.output, || {
        let point: Vec<(&str, &[f64])> = vec![("u", sol.u.as_slice())];
        match &mesh {
            InputMesh::Grid(g) => {
                let cells = quad_cell_metrics(g);
                let cd: Vec<(&str, &[f64])> =
                    cells.iter().map(|(k, v)| (*k, v.as_slice())).collect();
                io::write_vtk_structured2_with_point_data(&vtk, g, &cd, &point)?;
                io::write_geomview_mesh(&gm, g, Some(&sol.u))?;
                io::atomic_write(&png, |w| {
                    let bytes = render::field_png(g, &sol.u, None, 1200)
                        .map_err(|e| std::io::Error::other(e.to_string()))?;
                    w.write_all(&bytes)
                })?;
                let text = render::field_svg(g, &sol.u, None, 900.0)?;
                io::atomic_write(&svg, |w| w.write_all(text.as_bytes()))?;
            }
            InputMesh::Quads(q) => {
                let cells = quad_cell_metrics(q);
                let cd: Vec<(&str, &[f64])> =
                    cells.iter().map(|(k, v)| (*k, v.as_slice())).collect();
                io::write_vtk_quads_with_point_data(&vtk, q, &cd, &point)?;
                io::atomic_write(&png, |w| {
                    let bytes = render::field_png(q, &sol.u, None, 1200)
                        .map_err(|e| std::io::Error::other(e.to_string()))?;
                    w.write_all(&bytes)
                })?;
                let text = render::field_svg(q, &sol.u, None, 900.0)?;
                io::atomic_write(&svg, |w| w.write_all(text.as_bytes()))?;
            }
        }
        out.commit()?;
        Ok(())
    })?;

    let (umin, umax) = sol
        .u
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let err = man.as_ref().map(|m| m.error(&nodes, &sol.u));
    let method_name = sol.method.name();
    if a.json {
        let v = serde_json::json!({
            "unknowns": sol.unknowns,
            "method": method_name,
            "iterations": sol.iterations,
            "omega": sol.omega,
            "rho_jacobi": sol.rho_jacobi,
            "residual": sol.residual,
            "u_min": umin,
            "u_max": umax,
            "error_max": err.map(|e| e.max),
            "error_rms": err.map(|e| e.rms),
            "error_max_relative": err.map(|e| e.max / e.exact_max),
            "manufactured_frame": man.map(|m| {
                let (o, l) = m.frame();
                serde_json::json!({ "origin": [o.x, o.y], "scale": l })
            }),
            "seconds": sol.seconds,
        });
        println!("{v}");
    } else {
        print!(
            "{} unknowns, {method_name}: {} sweeps",
            sol.unknowns, sol.iterations
        );
        if let Some(w) = sol.omega {
            print!(", ω = {w:.4}");
        }
        println!(
            ", residual {:.2e}, {:.2} s; u in [{umin:.6}, {umax:.6}]",
            sol.residual, sol.seconds
        );
        if let (Some(e), Some(m)) = (err, &man) {
            let (o, l) = m.frame();
            println!(
                "manufactured {} on (x − {:.6}, y − {:.6})/{:.6}: max error {:.3e} ({:.3e} of max|U|), rms error {:.3e}",
                m.name,
                o.x,
                o.y,
                l,
                e.max,
                e.max / e.exact_max,
                e.rms
            );
        }
        eprintln!("wrote {}", a.output.display());
    }
    Ok(())
}
