//! The bad-input catalogue (`tests/bad_inputs/cases.json`, `docs/reliability.md`), run through the
//! `unamalla` binary: for every case with a CLI command, a failing case exits non-zero with
//! exactly one line on stderr (starting `error: `), no panic text, and leaves neither its
//! output file nor any temporary file in the scratch directory; an accepted case ("ok") exits
//! 0 and writes its output. The library side is `crates/unamalla-core/tests/bad_inputs.rs`.

mod common;
use common::{bin, tmpdir};

use std::path::{Path, PathBuf};

fn catalogue_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad_inputs")
}

/// A 10⁶-vertex ellipse as GeoJSON (the same ring as the core test generates).
fn ellipse_geojson(n: usize) -> String {
    let mut s = String::with_capacity(n * 44);
    s.push_str(r#"{"type": "Polygon", "coordinates": [["#);
    for k in 0..=n {
        let t = std::f64::consts::TAU * (k % n) as f64 / n as f64;
        if k > 0 {
            s.push(',');
        }
        s.push_str(&format!("[{},{}]", 1000.0 * t.cos(), 700.0 * t.sin()));
    }
    s.push_str("]]}\n");
    s
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Runs every case with a CLI command; `slow` selects the cases marked `slow_cli` instead.
fn run_catalogue(slow: bool) {
    let dir = catalogue_dir();
    let text = std::fs::read_to_string(dir.join("cases.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut failures = Vec::new();
    let mut ran = 0;
    for (k, c) in doc["cases"].as_array().unwrap().iter().enumerate() {
        let name = c["name"].as_str().unwrap();
        let Some(args) = c["cli"].as_array() else {
            continue;
        };
        if c["slow_cli"].as_bool().unwrap_or(false) != slow {
            continue;
        }
        let out = tmpdir(&format!("case-{k}"));
        let subst = |s: &str| {
            s.replace("{out}", out.to_str().unwrap())
                .replace("{dir}", dir.to_str().unwrap())
        };
        let file = subst(c["file"].as_str().unwrap());
        let file = if Path::new(&file).is_absolute() {
            PathBuf::from(file)
        } else {
            dir.join(file)
        };
        // inputs generated into the scratch directory are not outputs
        let mut inputs = Vec::new();
        if c["generate"].as_str() == Some("ellipse-1e6") {
            std::fs::write(&file, ellipse_geojson(1_000_000)).unwrap();
            inputs.push(file.file_name().unwrap().to_string_lossy().into_owned());
        }
        let args: Vec<String> = args
            .iter()
            .map(|a| subst(a.as_str().unwrap()).replace("{file}", file.to_str().unwrap()))
            .collect();
        let output = c["output"].as_str().map(|o| PathBuf::from(subst(o)));
        let r = bin().args(&args).current_dir(&out).output().unwrap();
        ran += 1;
        let stderr = String::from_utf8_lossy(&r.stderr);
        let lines: Vec<&str> = stderr.lines().collect();
        let mut fail = |msg: String| failures.push(format!("{name}: {msg}\n  stderr: {stderr}"));
        if stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") {
            fail("panic text on stderr".into());
        }
        match c["cli_expect"].as_str().unwrap() {
            "error" => {
                if r.status.success() {
                    fail("exit code 0, expected failure".into());
                }
                if lines.len() != 1 || !lines[0].starts_with("error: ") {
                    fail(format!(
                        "{} stderr line(s), expected one 'error: ' line",
                        lines.len()
                    ));
                }
                if let Some(o) = &output {
                    if o.exists() {
                        fail(format!("output {} was left", o.display()));
                    }
                }
                let left: Vec<String> = files_in(&out)
                    .into_iter()
                    .filter(|f| !inputs.contains(f))
                    .collect();
                if !left.is_empty() {
                    fail(format!("files left in the output directory: {left:?}"));
                }
            }
            "ok" => {
                if !r.status.success() {
                    fail(format!("exit code {:?}, expected success", r.status.code()));
                }
                if let Some(o) = &output {
                    if !o.exists() {
                        fail(format!("output {} missing", o.display()));
                    }
                }
                if lines.iter().any(|l| l.starts_with("error")) {
                    fail("an error line on success".into());
                }
            }
            other => fail(format!("unknown cli_expect {other:?}")),
        }
        let _ = std::fs::remove_dir_all(&out);
    }
    assert!(ran > 0, "no case ran");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_catalogue_case_fails_cleanly_or_succeeds() {
    run_catalogue(false);
}

/// The 10⁶-vertex ring through `unamalla simplify` (~40 s of CPU in a debug build, more on a
/// loaded machine): `cargo test -p unamalla-cli --test bad_inputs -- --ignored`.
#[test]
#[ignore]
fn slow_catalogue_cases() {
    run_catalogue(true);
}
