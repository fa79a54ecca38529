//! End-to-end tests of `unamalla hex` (Cortés Aguirre 2012): the built-in box through Algorithms A
//! and B, a perturbed sphere through Algorithm A, a directory of six face grids, and bad input.

mod common;
use common::{bin, report, tmpdir, RunOk};

#[test]
fn box_case_with_algorithm_b_has_planar_interior_faces_and_all_outputs() {
    let dir = tmpdir("box");
    bin()
        .args(["hex", "box", "--algorithm", "b", "--quiet", "-o"])
        .arg(&dir)
        .run_ok();
    let v = report(&dir);
    // 5³ nodes → 4³ = 64 cells, (5−3)³ = 8 interior cells
    assert_eq!(v["cells"], 64);
    assert_eq!(v["interior_cells"], 8);
    assert_eq!(v["non_convex_cells"], 0);
    assert_eq!(v["non_hex_interior_cells"], 0);
    assert!(v["max_abs_cos"].as_f64().unwrap() < 1e-2);
    // the harmonic convex start has non-planar interior cells (the motivating example)
    assert_eq!(v["after_a"]["non_hex_interior_cells"], 8);
    for key in [
        "min_scaled_jacobian",
        "iterations",
        "seconds",
        "min_tet_volume",
    ] {
        assert!(v[key].is_number(), "{key}");
    }
    assert!(v["min_tet_volume"].as_f64().unwrap() > 0.0);
    // 5³: appendix A, 45 degrees of freedom
    assert_eq!(v["counting"]["dof"], 45);
    let vts = std::fs::read_to_string(dir.join("mesh.vts")).unwrap();
    assert!(vts.contains("WholeExtent=\"0 4 0 4 0 4\"") && vts.contains("Name=\"max_face_cos\""));
    let vtu = std::fs::read_to_string(dir.join("mesh.vtu")).unwrap();
    assert!(vtu.contains("NumberOfCells=\"64\"") && vtu.contains("Name=\"cell_class\""));
    let svg = std::fs::read_to_string(dir.join("histograms.svg")).unwrap();
    assert!(svg.starts_with("<svg"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn perturbed_sphere_becomes_convex_with_algorithm_a() {
    let dir = tmpdir("sphere");
    let st = bin()
        .args([
            "hex",
            "sphere",
            "--size",
            "10,10,10",
            "--nonconvex",
            "10",
            "--seed",
            "3",
            "--algorithm",
            "a",
            "--json",
            "--quiet",
            "-o",
        ])
        .arg(&dir)
        .run_ok();
    // --json prints the same report that is written
    let printed: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    let v = report(&dir);
    assert_eq!(printed, v);
    assert!(v["start"]["non_convex_cells"].as_u64().unwrap() >= 10);
    assert_eq!(v["non_convex_cells"], 0);
    assert!(v["after_b"].is_null());
    assert_eq!(v["seed"], 3);
    assert_eq!(v["cells"], 729);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_directory_of_face_grids_is_meshed() {
    // the unit cube's six faces, 4 × 4 × 4 nodes; the TFI start is the uniform grid
    let dir = tmpdir("faces");
    let faces = dir.join("faces");
    std::fs::create_dir_all(&faces).unwrap();
    let n = 4usize;
    let at = |i: usize, j: usize, k: usize| {
        let t = |a: usize| a as f64 / (n - 1) as f64;
        format!("{} {} {}\n", t(i), t(j), t(k))
    };
    let write = |name: &str, f: &dyn Fn(usize, usize) -> String| {
        let mut s = format!("# {name}\n{n} {n}\n");
        for y in 0..n {
            for x in 0..n {
                s.push_str(&f(x, y));
            }
        }
        std::fs::write(faces.join(format!("{name}.txt")), s).unwrap();
    };
    write("i_min", &|j, k| at(0, j, k));
    write("i_max", &|j, k| at(n - 1, j, k));
    write("j_min", &|i, k| at(i, 0, k));
    write("j_max", &|i, k| at(i, n - 1, k));
    write("k_min", &|i, j| at(i, j, 0));
    write("k_max", &|i, j| at(i, j, n - 1));
    let out = dir.join("out");
    bin()
        .args(["hex"])
        .arg(&faces)
        .args(["--quiet", "-o"])
        .arg(&out)
        .run_ok();
    let v = report(&out);
    assert_eq!(v["cells"], 27);
    assert_eq!(v["start"]["non_convex_cells"], 0);
    assert_eq!(v["non_hex_interior_cells"], 0);

    // a moved edge point: one clear error naming both faces, no output
    let bad = std::fs::read_to_string(faces.join("k_max.txt")).unwrap();
    let bad = bad.replacen("0 0 1\n", "0 0 1.5\n", 1);
    std::fs::write(faces.join("k_max.txt"), bad).unwrap();
    let out2 = dir.join("out2");
    let st = bin()
        .args(["hex"])
        .arg(&faces)
        .args(["--quiet", "-o"])
        .arg(&out2)
        .output()
        .unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("k_max (M6, top)") && err.contains("disagree"),
        "{err}"
    );
    assert!(!out2.exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_arguments_are_one_line_errors() {
    let dir = tmpdir("bad");
    for args in [
        vec!["hex", "nosuchcase"],
        vec!["hex", "box", "--size", "5,5"],
        vec!["hex", "box", "--algorithm", "c"],
        vec!["hex", "box", "--perturb=-1"],
    ] {
        let st = bin()
            .args(&args)
            .arg("-o")
            .arg(dir.join("o"))
            .output()
            .unwrap();
        assert!(!st.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&st.stderr);
        assert!(err.trim_end().lines().count() <= 3, "{args:?}: {err}");
        assert!(!dir.join("o").join("report.json").exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn mu_schedule_options_reach_the_report_and_bad_values_are_rejected() {
    let dir = tmpdir("box_mu");
    bin()
        .args([
            "hex",
            "box",
            "--b-schedule",
            "thesis",
            "--mu0",
            "500",
            "--mu-min",
            "1e-6",
            "--b-iters",
            "20",
            "--quiet",
            "-o",
        ])
        .arg(&dir)
        .run_ok();
    let v = report(&dir);
    let c = &v["options"]["coplanarity"];
    assert_eq!(c["mu0"].as_f64(), Some(500.0));
    assert_eq!(c["mu_min"].as_f64(), Some(1e-6));
    assert_eq!(c["solver"]["max_iter"], 20);
    // the thesis schedule has no planarity stop
    assert!(c["stop_cos"].is_null());
    // μ = 500, 50, …, 5e-6 > 1e-6: 9 steps (the last μ is 5·10⁻⁶ up to rounding)
    assert_eq!(v["algorithm_b"]["continuation_steps"], 9);
    assert_eq!(v["non_hex_interior_cells"], 0);
    std::fs::remove_dir_all(&dir).ok();
    for bad in [
        vec!["--mu0", "0"],
        vec!["--mu0", "nan"],
        vec!["--mu0", "1e-3", "--mu-min", "1e-2"],
        vec!["--b-iters", "0"],
        vec!["--b-schedule", "fast"],
    ] {
        let dir = tmpdir("box_mu_bad");
        let out = bin()
            .args(["hex", "box", "--quiet", "-o"])
            .arg(&dir)
            .args(&bad)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{bad:?} was accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--mu") || err.contains("iters") || err.contains("--b-schedule"),
            "{bad:?}: {err}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
