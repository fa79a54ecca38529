//! `unamalla bspline`: one net on a four-sided region and one map per block, report.json
//! fields, output files, and bad input giving one error line without output.

mod common;
use common::{bin, fixture, report, tmpdir, RunOk};

use std::path::{Path, PathBuf};

/// A wavy four-sided region written as GeoJSON (clockwise on purpose: it is normalised).
fn wavy_region(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut ring = Vec::new();
    let k = 40;
    let w = |t: f64| 0.05 * (std::f64::consts::TAU * 3.0 * t).sin();
    for l in 0..k {
        let t = l as f64 / k as f64;
        ring.push((2.0 * t, -w(t)));
    }
    for l in 0..k {
        let t = l as f64 / k as f64;
        ring.push((2.0 + w(t), t));
    }
    for l in 0..k {
        let t = l as f64 / k as f64;
        ring.push((2.0 * (1.0 - t), 1.0 + w(t)));
    }
    for l in 0..k {
        let t = l as f64 / k as f64;
        ring.push((-w(t), 1.0 - t));
    }
    ring.push(ring[0]);
    ring.reverse();
    let coords: Vec<String> = ring.iter().map(|(x, y)| format!("[{x},{y}]")).collect();
    let path = dir.join("wavy.geojson");
    std::fs::write(
        &path,
        format!(
            r#"{{"type":"Polygon","coordinates":[[{}]]}}"#,
            coords.join(",")
        ),
    )
    .unwrap();
    path
}

#[test]
fn biquadratic_single_net_report_and_files() {
    let dir = tmpdir("single");
    let region = wavy_region(&dir);
    let out = dir.join("out");
    bin()
        .arg("bspline")
        .arg(&region)
        .args(["--degree", "2", "--net", "20x12", "--samples", "400", "-o"])
        .arg(&out)
        .run_ok();
    let v = report(&out);
    assert_eq!(v["degree"], 2);
    assert_eq!(v["net"], serde_json::json!([20, 12]));
    assert!(v["min_det_j"].as_f64().unwrap() > 0.0, "{v}");
    // biquadratic: Theorem 1 is the bilinear certificate, not applicable; Theorem 2 is decided
    assert_eq!(v["theorem1"], "not applicable");
    assert!(v["theorem2"].is_boolean());
    assert_eq!(v["net_convex"], true);
    assert!(v["seconds"].as_f64().unwrap() > 0.0);
    // the mean of det J approximates the area of the image (about 2 for this region)
    let mean = v["mean_det_j"].as_f64().unwrap();
    assert!((mean - 2.0).abs() < 0.1, "mean det J {mean}");
    for f in ["net.vtk", "isocurves.vtk", "isocurves.svg", "jacobian.vtk"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let iso = std::fs::read_to_string(out.join("isocurves.vtk")).unwrap();
    // one curve of constant ξ per control column (20) and of constant η per row (12)
    assert!(iso.contains("DATASET POLYDATA") && iso.contains("LINES 32 "));
    let jac = std::fs::read_to_string(out.join("jacobian.vtk")).unwrap();
    assert!(jac.contains("DIMENSIONS 201 201 1") && jac.contains("SCALARS det_j double 1"));
}

#[test]
fn bilinear_single_net_theorem1_holds() {
    let dir = tmpdir("bilinear");
    let region = wavy_region(&dir);
    let out = dir.join("out");
    let st = bin()
        .arg("bspline")
        .arg(&region)
        .args([
            "--degree",
            "1",
            "--net",
            "15x9",
            "--samples",
            "200",
            "--json",
            "-o",
        ])
        .arg(&out)
        .run_ok();
    let v: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    assert_eq!(v, report(&out));
    assert_eq!(v["theorem1"], true);
    assert_eq!(v["theorem2"], "not applicable");
    assert_eq!(v["certified"], true);
    assert!(v["min_det_j"].as_f64().unwrap() > 0.0);
}

#[test]
fn blocks_of_a_region_with_a_hole() {
    let dir = tmpdir("blocks");
    let out = dir.join("out");
    bin()
        .arg("bspline")
        .arg(fixture("kiwi-bird.geojson"))
        .args([
            "--blocks",
            "--cells",
            "1500",
            "--samples",
            "100",
            "--quiet",
            "-o",
        ])
        .arg(&out)
        .run_ok();
    let v = report(&out);
    assert_eq!(v["mode"], "blocks");
    let blocks = v["blocks"].as_array().unwrap();
    assert!(blocks.len() >= 2);
    for b in blocks {
        // the pipeline's blocks are convex: Theorem 1 holds for every block's bilinear map
        assert_eq!(b["theorem1"], true, "{b}");
        assert!(b["theorem2"].is_boolean());
    }
    assert_eq!(v["net_convex"], true);
    assert!(out.join("block-0-isocurves.vtk").is_file());
}

/// Texas as one biquadratic map: the resampled sides give a self-intersecting control polygon
/// (the Laguna Madre behind Padre Island is a slit on the east side); the least-squares fit
/// with automatic fairing gives a valid one, faired on the east side only, and a map with
/// det J > 0 (Bernstein certificate). The mean of det J over the unit square is the area of
/// the image, checked against the shoelace area of the region's ring.
#[test]
fn texas_biquadratic_with_a_faired_least_squares_boundary() {
    let dir = tmpdir("texas");
    let region = fixture("texas.geojson");
    let args = [
        "--degree",
        "2",
        "--net",
        "35x35",
        "--samples",
        "500",
        "--quiet",
    ];
    let out0 = dir.join("plain");
    let st = bin()
        .arg("bspline")
        .arg(&region)
        .args(args)
        .arg("-o")
        .arg(&out0)
        .output()
        .unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(err.contains("not simple"), "{err}");

    let out = dir.join("fit");
    bin()
        .arg("bspline")
        .arg(&region)
        .args(args)
        .args(["--fit", "chord-length", "-o"])
        .arg(&out)
        .run_ok();
    let v = report(&out);
    assert!(v["min_det_j"].as_f64().unwrap() > 0.0, "{v}");
    assert_eq!(v["bernstein"]["outcome"], "certified", "{v}");
    assert_eq!(v["nonpositive_samples"], 0);
    let fit = &v["boundary_fit"];
    let lambda: Vec<f64> = fit["fairing"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(lambda[1] > 0.0, "{fit}");
    assert!(lambda.iter().filter(|&&l| l == 0.0).count() >= 2, "{fit}");
    // the region's area by the shoelace formula on the file's ring
    let gj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&region).unwrap()).unwrap();
    let ring = gj["features"][0]["geometry"]["coordinates"][0]
        .as_array()
        .unwrap();
    let p: Vec<(f64, f64)> = ring
        .iter()
        .map(|c| (c[0].as_f64().unwrap(), c[1].as_f64().unwrap()))
        .collect();
    let area = p
        .windows(2)
        .map(|w| w[0].0 * w[1].1 - w[1].0 * w[0].1)
        .sum::<f64>()
        .abs()
        / 2.0;
    let mean = v["mean_det_j"].as_f64().unwrap();
    assert!(
        (mean / area - 1.0).abs() < 0.02,
        "mean det J {mean} vs area {area}"
    );
}

#[test]
fn bad_input_gives_one_error_line_and_no_files() {
    let dir = tmpdir("bad");
    let out = dir.join("out");
    // a region with a hole needs --blocks
    let st = bin()
        .arg("bspline")
        .arg(fixture("kiwi-bird.geojson"))
        .args(["--net", "10x10", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(err.contains("hole"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists());
    // degree 3 and a 2x5 net are rejected by the argument parser
    for args in [["--degree", "3"], ["--net", "2x5"]] {
        let st = bin()
            .arg("bspline")
            .arg(fixture("colorado.geojson"))
            .args(args)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert!(!st.status.success());
        assert!(!out.exists());
    }
}
