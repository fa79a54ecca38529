//! End-to-end tests of the `unamalla` binary: the documented commands work, bad input gives
//! one clear error line, a non-zero exit code and no output file.

mod common;
use common::{bin, fixture, report, tmpdir, RunOk};

use std::path::Path;

#[test]
fn tfi_on_colorado_then_quality_json() {
    let dir = tmpdir("tfi");
    let out = dir.join("co.vtk");
    let st = bin()
        .args(["tfi"])
        .arg(fixture("colorado.geojson"))
        .args(["--auto-corners", "--size", "60x40", "-o"])
        .arg(&out)
        .run_ok();
    let text = String::from_utf8_lossy(&st.stdout);
    assert!(text.contains("non-convex cells: 0"), "{text}");

    let q = bin().arg("quality").arg(&out).arg("--json").run_ok();
    let v: serde_json::Value = serde_json::from_slice(&q.stdout).unwrap();
    // 60 × 40 nodes → 59 × 39 cells
    assert_eq!(v["num_cells"], 59 * 39);
    assert_eq!(v["num_nodes"], 60 * 40);
    assert_eq!(v["non_convex_cells"], 0);
    // Colorado is nearly a rectangle: every cell is close to one
    let mu_min = v["metrics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == "mu")
        .unwrap()["min"]
        .as_f64()
        .unwrap();
    assert!(mu_min > 0.9, "min mu {mu_min}");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn explicit_corners_are_file_indices() {
    let dir = tmpdir("corners");
    let out = dir.join("sq.vtk");
    let region = dir.join("sq.geojson");
    // clockwise square in the file, corners listed in file order starting at (0,0)
    std::fs::write(
        &region,
        r#"{"type":"Polygon","coordinates":[[[0,0],[0,2],[1,2],[2,2],[2,0],[0,0]]]}"#,
    )
    .unwrap();
    bin()
        .arg("tfi")
        .arg(&region)
        .args(["--corners", "0,4,3,1", "--size", "3x3", "-o"])
        .arg(&out)
        .run_ok();
    let q = bin()
        .arg("quality")
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&q.stdout).unwrap();
    assert_eq!(v["num_cells"], 4);
    // a square split into 2 × 2 squares: every mu is exactly 1 (up to rounding)
    let mu = v["metrics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == "mu")
        .unwrap()
        .clone();
    assert!((mu["min"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    std::fs::remove_dir_all(dir).ok();
}

fn assert_clean_failure(args: &[&str], out: &Path) {
    let st = bin().args(args).output().unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(
        err.trim().lines().count(),
        1,
        "expected one error line, got: {err}"
    );
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "a failed run left {}", out.display());
}

#[test]
fn bad_regions_fail_cleanly_without_output() {
    let dir = tmpdir("bad");
    let out = dir.join("never.vtk");
    let o = out.to_str().unwrap();
    let cases = [
        (
            "bowtie.geojson",
            r#"{"type":"Polygon","coordinates":[[[0,0],[2,2],[2,0],[0,2],[0,0]]]}"#,
        ),
        (
            "hole-outside.geojson",
            r#"{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,1],[0,0]],[[5,5],[6,5],[6,6],[5,5]]]}"#,
        ),
        (
            "broken.geojson",
            r#"{"type":"Polygon","coordinates":[[[0,0],[1,0]"#,
        ),
        (
            "line.geojson",
            r#"{"type":"LineString","coordinates":[[0,0],[1,0]]}"#,
        ),
    ];
    for (name, text) in cases {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        assert_clean_failure(
            &["tfi", p.to_str().unwrap(), "--size", "5x5", "-o", o],
            &out,
        );
    }
    // a region with a hole is not four-sided
    assert_clean_failure(
        &[
            "tfi",
            fixture("horse.geojson").to_str().unwrap(),
            "--size",
            "5x5",
            "-o",
            o,
        ],
        &out,
    );
    assert_clean_failure(
        &["quality", dir.join("missing.vtk").to_str().unwrap()],
        &out,
    );
    // a quality target that is not a percentage
    for bad in ["150", "-1", "NaN"] {
        assert_clean_failure(
            &[
                "mesh",
                fixture("horse.geojson").to_str().unwrap(),
                &format!("--quality-target={bad}"),
                "-o",
                o,
            ],
            &out,
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn mesh_writes_every_output_and_report_fields() {
    let dir = tmpdir("mesh");
    let out = dir.join("kiwi");
    let st = bin()
        .arg("mesh")
        .arg(fixture("kiwi-bird.geojson"))
        .args(["--cells", "2000", "--quiet", "--json", "-o"])
        .arg(&out)
        .run_ok();
    let v: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    for key in [
        "region",
        "cells",
        "nodes",
        "blocks",
        "non_convex_cells",
        "interior_singularities",
        "mu_ge_0_8_percent",
        "mu_bands",
        "min_scaled_jacobian",
        "p5_scaled_jacobian",
        "min_alpha_over_mean",
        "area_change_percent",
        "hausdorff",
        "holes_dropped",
        "holes_carved",
        "seconds",
        "stage_seconds",
    ] {
        assert!(v.get(key).is_some(), "report.json lacks {key}");
    }
    assert_eq!(v["region"], "kiwi-bird");
    assert_eq!(v["non_convex_cells"], 0);
    assert_eq!(v["interior_singularities"], 0);
    let blocks = v["blocks"].as_u64().unwrap() as usize;
    let mut files = vec![
        "mesh.vtu".to_string(),
        "mesh.msh".into(),
        "blocks.vtm".into(),
        "decomposition.json".into(),
        "decomposition.svg".into(),
        "report.json".into(),
        "mesh.svg".into(),
        "mesh.png".into(),
    ];
    files.extend((0..blocks).map(|k| format!("block-{k}.vts")));
    for f in files {
        assert!(out.join(&f).is_file(), "missing {f}");
    }
    // report.json on disk is what --json printed
    let disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(disk, v);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn mesh_of_a_bad_region_writes_nothing() {
    let dir = tmpdir("meshbad");
    let out = dir.join("out");
    let region = dir.join("hole-outside.geojson");
    std::fs::write(
        &region,
        r#"{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,1],[0,0]],[[5,5],[6,5],[6,6],[5,5]]]}"#,
    )
    .unwrap();
    assert_clean_failure(
        &[
            "mesh",
            region.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        &out,
    );
    let bowtie = dir.join("bowtie.geojson");
    std::fs::write(
        &bowtie,
        r#"{"type":"Polygon","coordinates":[[[0,0],[2,2],[2,0],[0,2],[0,0]]]}"#,
    )
    .unwrap();
    assert_clean_failure(
        &[
            "mesh",
            bowtie.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        &out,
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn eval_raw_length_on_a_hand_written_grid() {
    // 3 × 3 nodes on the unit grid [0,2]²: four unit-square cells, each with four corner
    // triangles of l = 1 + 1 = 2, so the raw length is 4 · 4 · 2 = 32; the centre node is the
    // only free node and by symmetry the gradient there vanishes.
    let dir = tmpdir("eval");
    let f = dir.join("g.vtk");
    std::fs::write(
        &f,
        "# vtk DataFile Version 3.0\ngrid\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 3 3 1\nPOINTS 9 double\n\
         0 0 0 1 0 0 2 0 0\n0 1 0 1 1 0 2 1 0\n0 2 0 1 2 0 2 2 0\n",
    )
    .unwrap();
    let st = bin()
        .arg("eval")
        .arg(&f)
        .args(["--functional", "length", "--raw"])
        .run_ok();
    let v: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    assert!((v["value"].as_f64().unwrap() - 32.0).abs() < 1e-12, "{v}");
    assert!(v["gradient_norm"].as_f64().unwrap().abs() < 1e-12, "{v}");
    std::fs::remove_dir_all(dir).ok();
}

/// `unamalla decompose` decomposes the region `unamalla mesh` would (the mesher's default
/// simplification: maryland 260 → 99 vertices, every block admissible — the decompose crate's
/// fixture test checks the same blocks), writes a file that `--from` validates, and with
/// `--no-simplify` decomposes the rings as read; a file for the rings as read is also accepted
/// by `--from` without `--no-simplify` (it does not fit the simplified region).
#[test]
fn decompose_writes_the_meshers_decomposition() {
    let dir = tmpdir("decompose");
    let (json, svg) = (dir.join("d.json"), dir.join("d.svg"));
    let st = bin()
        .arg("decompose")
        .arg(fixture("maryland.geojson"))
        .arg("-o")
        .arg(&json)
        .arg("--svg")
        .arg(&svg)
        .run_ok();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(err.contains("region: 260 → 99 vertices"), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let blocks = v["blocks"].as_array().unwrap().len();
    let cuts = v["cuts"].as_array().unwrap().len();
    // a simply connected region: the block graph is a tree
    assert_eq!(cuts, blocks - 1);
    assert!(
        err.contains(&format!(
            "{blocks} blocks, {cuts} cuts, {blocks} admissible"
        )),
        "{err}"
    );
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    // the saved file validates against the same region
    let again = dir.join("again.json");
    bin()
        .arg("decompose")
        .arg(fixture("maryland.geojson"))
        .arg("--from")
        .arg(&json)
        .arg("-o")
        .arg(&again)
        .run_ok();
    assert_eq!(
        serde_json::from_slice::<serde_json::Value>(&std::fs::read(&again).unwrap()).unwrap()
            ["blocks"],
        v["blocks"]
    );
    // the rings as read: every block vertex of the file lies on the raw region, which has
    // 260 vertices, so the blocks' rings hold more than the 99 simplified ones
    let raw = dir.join("raw.json");
    bin()
        .arg("decompose")
        .arg(fixture("maryland.geojson"))
        .arg("--no-simplify")
        .arg("-o")
        .arg(&raw)
        .run_ok();
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&raw).unwrap()).unwrap();
    let vertices = |v: &serde_json::Value| -> usize {
        v["blocks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["ring"].as_array().unwrap().len())
            .sum()
    };
    assert!(vertices(&r) > vertices(&v) && vertices(&r) >= 260);
    bin()
        .arg("decompose")
        .arg(fixture("maryland.geojson"))
        .arg("--from")
        .arg(&raw)
        .arg("-o")
        .arg(dir.join("raw-again.json"))
        .run_ok();
    // a file for another region fits neither: one error line naming both, no output
    let other = dir.join("colorado.json");
    bin()
        .arg("decompose")
        .arg(fixture("colorado.geojson"))
        .arg("-o")
        .arg(&other)
        .run_ok();
    let never = dir.join("never.json");
    let (region, other, never_s) = (
        fixture("maryland.geojson"),
        other.to_string_lossy().into_owned(),
        never.to_string_lossy().into_owned(),
    );
    let region = region.to_string_lossy();
    let args = ["decompose", &region, "--from", &other, "-o", &never_s];
    assert_clean_failure(&args, &never);
    let st = bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("fits neither the simplified region")
            && err.contains("nor the region as read"),
        "{err}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// `--json`: an error is one JSON object on stdout (besides the line on stderr) whose exit code
/// and kind match the process's: a missing file is an input error (1), a bad value a usage
/// error (2, from clap's own parser too).
#[test]
fn errors_are_json_with_json() {
    let dir = tmpdir("json-errors");
    let cases: [(&[&str], u8, &str); 3] = [
        (&["mesh", "/nonexistent/region.geojson"], 1, "input"),
        (&["mesh", "kiwi", "--cells", "abc"], 2, "usage"),
        (&["mesh", "kiwi", "--shape-target", "1.5"], 2, "usage"),
    ];
    for (args, code, kind) in cases {
        let mut cmd = bin();
        for a in args {
            if *a == "kiwi" {
                cmd.arg(fixture("kiwi-bird.geojson"));
            } else {
                cmd.arg(a);
            }
        }
        let out = cmd
            .arg("-o")
            .arg(dir.join("out"))
            .arg("--json")
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(code as i32), "{args:?}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{args:?}: stdout is not JSON ({e}): {:?}", out.stdout));
        assert_eq!(v["error"]["exit_code"], code, "{v}");
        assert_eq!(v["error"]["kind"], kind, "{v}");
        assert!(v["error"]["message"]
            .as_str()
            .is_some_and(|m| !m.is_empty()));
        // the stderr line stays
        assert!(String::from_utf8_lossy(&out.stderr).starts_with("error: "));
        assert!(!dir.join("out").exists());
    }
    std::fs::remove_dir_all(dir).ok();
}

/// `--strict`: a mesh that misses a target is written and the run exits 3 naming the target.
/// A comb of ten 1 × 3 teeth on a 21 × 1 bar (every feature kept) needs at least one block per
/// tooth and bar segment, each with at least one cell, so `--cells 5` misses the count target
/// by construction; without `--strict` the same run succeeds (it also checks that a mesh with
/// no interior node — one cell per block — is written, not refused as "nothing to smooth").
#[test]
fn strict_exits_3_on_a_missed_target_after_writing() {
    let dir = tmpdir("strict");
    let mut ring = vec![[0.0, 0.0], [21.0, 0.0], [21.0, 1.0]];
    for k in (0..10).rev() {
        let x0 = 2.0 * k as f64 + 1.0;
        ring.extend([[x0 + 1.0, 1.0], [x0 + 1.0, 4.0], [x0, 4.0], [x0, 1.0]]);
    }
    ring.extend([[0.0, 1.0], [0.0, 0.0]]);
    let comb = dir.join("comb.geojson");
    std::fs::write(
        &comb,
        serde_json::json!({"type": "Polygon", "coordinates": [ring]}).to_string(),
    )
    .unwrap();
    let run = |strict: bool, out: &Path| {
        let mut c = bin();
        c.arg("mesh").arg(&comb).args([
            "--cells",
            "5",
            "--no-simplify",
            "--feature-factor",
            "0",
            "--neck-factor",
            "0",
            "--quiet",
            "--export",
            "none",
            "--no-report",
            "-o",
        ]);
        c.arg(out);
        if strict {
            c.arg("--strict");
        }
        c.output().unwrap()
    };
    let plain = run(false, &dir.join("plain"));
    assert!(
        plain.status.success(),
        "{}",
        String::from_utf8_lossy(&plain.stderr)
    );
    let rep = report(&dir.join("plain"));
    assert!(rep["cells"].as_u64().unwrap() >= 20, "{}", rep["cells"]);
    let strict = run(true, &dir.join("strict"));
    assert_eq!(strict.status.code(), Some(3));
    let err = String::from_utf8_lossy(&strict.stderr);
    assert!(
        err.contains("--strict") && err.contains("off the requested 5"),
        "{err}"
    );
    assert!(dir.join("strict").join("mesh.vtu").exists());
    std::fs::remove_dir_all(dir).ok();
}

/// `--carve-islands` / `--no-carve`: a 200 × 200 square sea with one octagonal islet of
/// circumradius 2 (width 2 · 2 · cos 22.5° ≈ 3.7, area 8√2 ≈ 11.3) at 1,600 cells (h = 5): the
/// islet is narrower than a cell and at least a quarter of one in area, so by default it is
/// carved (report.json "holes_carved" = [0]); `--no-carve` keeps it in the block layout (nothing
/// carved); both flags together are refused.
#[test]
fn islets_are_carved_by_default_and_not_with_no_carve() {
    let dir = tmpdir("carve");
    let ring = |pts: Vec<(f64, f64)>| {
        let mut v: Vec<[f64; 2]> = pts.into_iter().map(|(x, y)| [x, y]).collect();
        v.push(v[0]);
        v
    };
    let outer = ring(vec![(0.0, 0.0), (200.0, 0.0), (200.0, 200.0), (0.0, 200.0)]);
    let islet = ring(
        (0..8)
            .rev()
            .map(|k| {
                let t = std::f64::consts::PI * (0.125 + k as f64 / 4.0);
                (100.0 + 2.0 * t.cos(), 100.0 + 2.0 * t.sin())
            })
            .collect(),
    );
    let geo = serde_json::json!({
        "type": "Feature",
        "properties": {},
        "geometry": {"type": "Polygon", "coordinates": [outer, islet]}
    });
    let input = dir.join("sea.geojson");
    std::fs::write(&input, geo.to_string()).unwrap();
    let run = |extra: &[&str], out: &str| {
        let out = dir.join(out);
        bin()
            .arg("mesh")
            .arg(&input)
            .args([
                "--crs", "planar", "--cells", "1600", "--quiet", "--export", "none", "-o",
            ])
            .arg(&out)
            .args(extra)
            .run_ok();
        report(&out)
    };
    let carved = run(&[], "default");
    assert_eq!(carved["holes_carved"], serde_json::json!([0]));
    assert_eq!(carved["holes_dropped"], serde_json::json!([]));
    assert_eq!(carved["non_convex_cells"], 0);
    let kept = run(&["--no-carve"], "no-carve");
    assert_eq!(kept["holes_carved"], serde_json::json!([]));
    let both = bin()
        .arg("mesh")
        .arg(&input)
        .args(["--carve-islands", "2", "--no-carve", "-o"])
        .arg(dir.join("both"))
        .output()
        .unwrap();
    assert!(!both.status.success());
    assert!(!dir.join("both").exists());
    std::fs::remove_dir_all(dir).ok();
}
