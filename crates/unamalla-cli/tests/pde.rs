//! End-to-end tests of `unamalla pde` and `unamalla refine`.

mod common;
use common::{bin, fixture, stdout_ok, tmpdir, RunOk};

use std::path::Path;
use std::process::Output;

/// TFI grid of a bundled region; a folded grid (Texas at 61 × 61) is written with
/// `--allow-non-convex` and exit code 3 (a guarantee not met).
fn tfi(region: &str, size: &str, out: &Path) {
    let o = bin()
        .arg("tfi")
        .arg(fixture(region))
        .args(["--size", size, "--allow-non-convex", "-o"])
        .arg(out)
        .output()
        .unwrap();
    assert!(
        matches!(o.status.code(), Some(0 | 3)),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.exists());
}

fn json(out: &Output) -> serde_json::Value {
    serde_json::from_str(&stdout_ok(out)).unwrap()
}

#[test]
fn constant_data_give_the_constant_solution_and_every_output() {
    // g = 0, d = 0, U = 3 on all four sides: every row of the 9-point stencil sums to d = 0
    // (it annihilates constants), so U ≡ 3 solves the discrete system exactly.
    let dir = tmpdir("const");
    let grid = dir.join("co.vtk");
    tfi("colorado.geojson", "30x20", &grid);
    let out = dir.join("out");
    let o = bin()
        .arg("pde")
        .arg(&grid)
        .args(["--g", "const:0", "--bc", "all=const:3", "--json", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let v = json(&o);
    assert_eq!(v["unknowns"], 28 * 18);
    assert!((v["u_min"].as_f64().unwrap() - 3.0).abs() < 1e-9, "{v}");
    assert!((v["u_max"].as_f64().unwrap() - 3.0).abs() < 1e-9, "{v}");
    // VTK point data u, Geomview MESH with header `m n` (i fastest), PNG, SVG
    let vtk = std::fs::read_to_string(out.join("solution.vtk")).unwrap();
    assert!(
        vtk.contains("POINT_DATA 600\nSCALARS u double 1"),
        "no point array u"
    );
    let mesh = std::fs::read_to_string(out.join("solution.mesh")).unwrap();
    let mut lines = mesh.lines();
    assert_eq!(lines.next(), Some("MESH"));
    assert_eq!(
        lines
            .next()
            .map(|l| l.split_whitespace().collect::<Vec<_>>()),
        Some(vec!["30", "20"])
    );
    let png = std::fs::read(out.join("solution.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    assert!(std::fs::read_to_string(out.join("solution.svg"))
        .unwrap()
        .contains("<polygon"));
}

/// A polar grid of the quarter annulus 1 ≤ r ≤ 2, 0 ≤ θ ≤ π/2 as VTK legacy text.
fn annulus_vtk(m: usize, n: usize) -> String {
    let mut t = format!(
        "# vtk DataFile Version 3.0\nannulus\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS {m} {n} 1\nPOINTS {} double\n",
        m * n
    );
    for j in 0..n {
        for i in 0..m {
            let r = 1.0 + i as f64 / (m - 1) as f64;
            let th = std::f64::consts::FRAC_PI_2 * j as f64 / (n - 1) as f64;
            t.push_str(&format!("{:?} {:?} 0\n", r * th.cos(), r * th.sin()));
        }
    }
    t
}

#[test]
fn manufactured_error_shrinks_under_refinement_and_solvers_agree() {
    // SOR and the direct LU give the same discrete solution; refining by 2 (bilinear, so the
    // refined grid has kinks along the coarse lines) still reduces the error.
    let dir = tmpdir("man");
    let coarse = dir.join("c.vtk");
    std::fs::write(&coarse, annulus_vtk(17, 13)).unwrap();
    let fine = dir.join("f.vtk");
    let r = bin()
        .arg("refine")
        .arg(&coarse)
        .args(["--factor", "2", "-o"])
        .arg(&fine)
        .run_ok();
    assert!(String::from_utf8_lossy(&r.stdout).contains("17 × 13 → 33 × 25 nodes"));
    let run = |mesh: &Path, solver: &str, tag: &str| {
        json(
            &bin()
                .arg("pde")
                .arg(mesh)
                .args([
                    "--manufactured",
                    "sin-cosh",
                    "--solver",
                    solver,
                    "--json",
                    "-o",
                ])
                .arg(dir.join(tag))
                .output()
                .unwrap(),
        )
    };
    let s = run(&coarse, "sor", "s");
    let d = run(&coarse, "direct", "d");
    assert_eq!(d["iterations"], 0);
    let (es, ed) = (
        s["error_max"].as_f64().unwrap(),
        d["error_max"].as_f64().unwrap(),
    );
    assert!(es > 0.0 && (es - ed).abs() <= 1e-8, "{es} vs {ed}");
    let f = run(&fine, "direct", "f");
    let ef = f["error_max"].as_f64().unwrap();
    assert!(ef < 0.5 * es, "{ef} vs {es}");
}

#[test]
fn folded_meshes_are_refused_with_no_output() {
    // TFI of Texas at 61 × 61 folds (hundreds of non-convex cells)
    let dir = tmpdir("fold");
    let grid = dir.join("tx.vtk");
    tfi("texas.geojson", "61x61", &grid);
    let out = dir.join("out");
    let o = bin()
        .arg("pde")
        .arg(&grid)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("folded") && err.contains("non-convex"),
        "{err}"
    );
    assert!(!out.exists());
    let o = bin()
        .arg("refine")
        .arg(&grid)
        .arg("-o")
        .arg(dir.join("r.vtk"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("convex"));
    assert!(!dir.join("r.vtk").exists());
}

#[test]
fn general_quad_mesh_and_bad_arguments() {
    // a hand-written unstructured 3 × 3-node square, 4 cells: the centre node is the only
    // unknown; with g = 0 its 9-point equation on a uniform grid is the 5-point Laplacian
    // (A12 = 0), so U(centre) = mean of its four edge neighbours = 2.
    let dir = tmpdir("quads");
    let mut text = String::from(
        "# vtk DataFile Version 3.0\nhand\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 9 double\n",
    );
    for j in 0..3 {
        for i in 0..3 {
            text.push_str(&format!("{i} {j} 0\n"));
        }
    }
    text.push_str(
        "CELLS 4 20\n4 0 1 4 3\n4 1 2 5 4\n4 3 4 7 6\n4 4 5 8 7\nCELL_TYPES 4\n9\n9\n9\n9\n",
    );
    let q = dir.join("q.vtk");
    std::fs::write(&q, text).unwrap();
    let v = json(
        &bin()
            .arg("pde")
            .arg(&q)
            .args(["--bc", "all=const:2", "--json", "-o"])
            .arg(dir.join("o"))
            .output()
            .unwrap(),
    );
    assert_eq!(v["unknowns"], 1);
    assert!((v["u_max"].as_f64().unwrap() - 2.0).abs() < 1e-12);
    assert!(dir.join("o/solution.vtk").exists());
    assert!(!dir.join("o/solution.mesh").exists());

    for (args, msg) in [
        (vec!["--bc", "1=const:1"], "four sides"),
        (vec!["--a", "1", "--b", "2", "--c", "1"], "not elliptic"),
        (vec!["--g", "cos:1"], "unknown kind"),
        (vec!["--bc", "all=parabolic"], "KIND:VALUE"),
        (vec!["--solver", "cg"], "unknown solver"),
        (vec!["--omega", "2.5"], "(0, 2)"),
        (vec!["--manufactured", "exp"], "unknown solution"),
    ] {
        let out = dir.join("bad");
        let o = bin()
            .arg("pde")
            .arg(&q)
            .args(&args)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert!(!o.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(msg), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?}");
    }
}

#[test]
fn manufactured_solutions_work_in_map_units() {
    // The solution lives on the bounding box mapped into the unit square, and the 9-point
    // transformed stencil is invariant under x → o + L·x (the metric terms scale by L², the
    // source by 1/L²): the annulus grid and its copy at (500 km, 3000 km) scaled by 1000 give
    // the same discrete error, and neither overflows (cosh(3·10⁶) would).
    let dir = tmpdir("man-map");
    let unit = dir.join("u.vtk");
    std::fs::write(&unit, annulus_vtk(17, 13)).unwrap();
    let moved = dir.join("m.vtk");
    let text = annulus_vtk(17, 13)
        .lines()
        .map(|l| {
            let w: Vec<f64> = l
                .split_whitespace()
                .map_while(|t| t.parse::<f64>().ok())
                .collect();
            if w.len() == 3 && l.split_whitespace().count() == 3 {
                format!(
                    "{:?} {:?} 0",
                    500_000.0 + 1000.0 * w[0],
                    3_000_000.0 + 1000.0 * w[1]
                )
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n";
    std::fs::write(&moved, text).unwrap();
    let run = |mesh: &Path, tag: &str| {
        json(
            &bin()
                .arg("pde")
                .arg(mesh)
                .args([
                    "--manufactured",
                    "sin-cosh",
                    "--solver",
                    "direct",
                    "--json",
                    "-o",
                ])
                .arg(dir.join(tag))
                .output()
                .unwrap(),
        )
    };
    let (u, m) = (run(&unit, "u"), run(&moved, "m"));
    let (eu, em) = (
        u["error_max"].as_f64().unwrap(),
        m["error_max"].as_f64().unwrap(),
    );
    assert!(eu > 0.0 && eu < 0.05, "{u}");
    assert!((eu - em).abs() <= 1e-6 * eu, "{eu} vs {em}");
    // the frame: the annulus' box is [0, 2]², the moved one's [5e5, 5.02e5] × [3e6, 3.002e6]
    assert_eq!(u["manufactured_frame"]["scale"].as_f64(), Some(2.0));
    assert_eq!(m["manufactured_frame"]["scale"].as_f64(), Some(2000.0));
    let rel = m["error_max_relative"].as_f64().unwrap();
    assert!(rel > 0.0 && rel < 0.05, "{m}");
}
