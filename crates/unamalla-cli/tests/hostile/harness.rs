//! The harness of the catalogue: fixture paths, the [`Case`] table entry, the independent mesh
//! checks and the runner.

use std::path::{Path, PathBuf};
use std::process::Output;

use unamalla_core::io::{self, PartSelector, VtkMesh};
use unamalla_core::mesh::QuadMesh;
use unamalla_core::verify::{verify_quads, VerifyOptions};

use crate::common::{self, tmpdir};

/// The binary under test; `HOSTILE_BIN` runs the catalogue against another build (the
/// "before" column of docs/reliability.md: `HOSTILE_BIN=… HOSTILE_REPORT=1 cargo test -p
/// unamalla-cli --test hostile fast_catalogue -- --nocapture` prints one line per case
/// instead of asserting).
pub(crate) fn bin() -> std::process::Command {
    match std::env::var_os("HOSTILE_BIN") {
        Some(b) => std::process::Command::new(b),
        None => common::bin(),
    }
}

pub(crate) fn hostile(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/hostile")
        .join(name)
}

pub(crate) fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/bad_inputs")
        .join(name)
}

pub(crate) fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// What a case expects.
pub(crate) struct Case {
    pub(crate) name: &'static str,
    pub(crate) args: Vec<String>,
    /// Expected exit code.
    pub(crate) code: i32,
    /// Substrings stderr must contain (lower-cased comparison).
    pub(crate) msg: &'static [&'static str],
    /// For code 0: the input region to check a `mesh` output against (`None`: no mesh check).
    pub(crate) region: Option<PathBuf>,
    pub(crate) env: Vec<(&'static str, &'static str)>,
}

pub(crate) fn case(
    name: &'static str,
    args: &[&str],
    code: i32,
    msg: &'static [&'static str],
) -> Case {
    Case {
        name,
        args: args.iter().map(|s| s.to_string()).collect(),
        code,
        msg,
        region: None,
        env: Vec::new(),
    }
}

pub(crate) fn p(path: PathBuf) -> String {
    path.to_string_lossy().into_owned()
}

/// `python3 quadcheck.py file` as JSON, or `None` when python3/meshio/the tool is missing.
pub(crate) fn quadcheck(file: &Path) -> Option<serde_json::Value> {
    let tool = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/tools/quadcheck.py");
    if !tool.exists() {
        eprintln!("note: {} missing; quadcheck skipped", tool.display());
        return None;
    }
    let o = std::process::Command::new("python3")
        .arg(&tool)
        .arg(file)
        .output()
        .ok()?;
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        if err.contains("No module named") {
            eprintln!("note: python3 without meshio; quadcheck skipped");
            return None;
        }
        panic!("quadcheck failed on {}: {err}", file.display());
    }
    serde_json::from_slice(&o.stdout).ok()
}

/// How far outside the **input** region a cell centroid may lie when the run simplified it, in
/// mean cell sizes `h = √(A_mesh / cells)`: the feature removal closes bays, inlets and slits
/// narrower than about two cells (by design, `DEFAULT_FEATURE_FACTOR`), and the cells covering
/// such a feature have their centroids inside it, within `h` of the input boundary (the 10⁻³
/// slit: 10 centroids outside, all within 5·10⁻⁴ of it). A misplaced cell — bridging a bay
/// wider than that, or outside the region altogether — is further out. The pipeline itself
/// checks every centroid strictly against the meshed (simplified) region; without
/// simplification the input region is the meshed one and the check here is strict.
const SIMPLIFIED_OUTSIDE_CELLS: f64 = 1.0;

/// Distance from `p` to the nearest ring of `r`.
fn distance_to_rings(r: &unamalla_core::mesh::Region, p: unamalla_core::mesh::DVec2) -> f64 {
    let mut d = f64::INFINITY;
    for ring in r.rings() {
        let pts = ring.points();
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            let ab = b - a;
            let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
            d = d.min((a + t * ab - p).length());
        }
    }
    d
}

/// The independent checks of an accepted mesh directory against the input region `region`
/// (every `mesh.vtu` below `dir`, i.e. one per MultiPolygon part); `strict`: the run did not
/// simplify, so no centroid may lie outside.
pub(crate) fn check_mesh_dir(dir: &Path, region: &Path, strict: bool) -> Result<(), String> {
    let mut vtus = Vec::new();
    if dir.join("mesh.vtu").exists() {
        vtus.push((dir.join("mesh.vtu"), 0usize));
    }
    for n in names(dir) {
        if let Some(k) = n.strip_prefix("part-") {
            vtus.push((dir.join(&n).join("mesh.vtu"), k.parse().unwrap()));
        }
    }
    if vtus.is_empty() {
        return Err(format!("{}: no mesh.vtu", dir.display()));
    }
    for (vtu, part) in vtus {
        let file = io::read_vtk_xml(&vtu).map_err(|e| e.to_string())?;
        let mesh = match file.mesh {
            VtkMesh::Quads(q) => q,
            VtkMesh::Structured2(g) => QuadMesh::from_grid(&g),
            _ => return Err("not a quad mesh".into()),
        };
        let (r, _) = io::read_region_geojson_cleaned(region, PartSelector::Index(part))
            .map_err(|e| e.to_string())?;
        let v = verify_quads(&mesh, Some(&r), &VerifyOptions::default());
        if v.non_convex_cells > 0 || v.centroids_outside.is_none() {
            return Err(format!("{}: {v}", vtu.display()));
        }
        if v.centroids_outside != Some(0) {
            if strict {
                return Err(format!("{}: {v}", vtu.display()));
            }
            use unamalla_core::mesh::geometry::Location;
            use unamalla_core::mesh::HasQuadCells;
            let h = (v.mesh_area.unwrap_or(0.0) / v.cells.max(1) as f64).sqrt();
            for c in 0..mesh.num_quads() {
                let q = mesh.quad_points(c);
                let centroid = (q[0] + q[1] + q[2] + q[3]) * 0.25;
                if r.locate(centroid) == Location::Outside {
                    let d = distance_to_rings(&r, centroid);
                    if d > SIMPLIFIED_OUTSIDE_CELLS * h {
                        return Err(format!(
                            "{}: cell {c}'s centroid {centroid} is {d:.3e} outside the input region (> {SIMPLIFIED_OUTSIDE_CELLS} × the cell size {h:.3e}); {v}",
                            vtu.display()
                        ));
                    }
                }
            }
        }
        if let Some(q) = quadcheck(&vtu) {
            if q["non_convex_cells"] != 0 || q["duplicate_nodes"] != 0 {
                return Err(format!("{}: quadcheck {q}", vtu.display()));
            }
        }
        // the set is consistent: blocks.vtm lists exactly the block files present
        let d = vtu.parent().unwrap();
        let vtm = std::fs::read_to_string(d.join("blocks.vtm")).map_err(|e| e.to_string())?;
        for f in names(d).iter().filter(|f| f.starts_with("block-")) {
            if !vtm.contains(f.as_str()) {
                return Err(format!("{f} not listed in blocks.vtm"));
            }
        }
    }
    Ok(())
}

/// Runs `cmd` to completion, or kills it after `limit`.
fn output_within(
    mut cmd: std::process::Command,
    limit: std::time::Duration,
) -> Result<Output, String> {
    use std::io::Read;
    let mut child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    // drain the pipes on threads so a chatty child cannot block
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = so.read_to_end(&mut v);
        v
    });
    let t_err = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = se.read_to_end(&mut v);
        v
    });
    let t0 = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("did not terminate within {} s", limit.as_secs()));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    Ok(Output {
        status,
        stdout: t_out.join().unwrap(),
        stderr: t_err.join().unwrap(),
    })
}

fn run_case(c: &Case, scratch: &Path) -> Result<Output, String> {
    let out = scratch.join("out");
    let mut args: Vec<String> = c
        .args
        .iter()
        .map(|a| a.replace("{out}", out.to_str().unwrap()))
        .collect();
    // the fixtures' small coordinates lie in the lon/lat range: mesh them as planar (the
    // loader's `--crs auto` would project them to km and the check against the file's
    // coordinates would not apply)
    // (an older build under HOSTILE_BIN has no --crs and meshes planar anyway)
    if args.first().is_some_and(|a| a == "mesh")
        && !args.iter().any(|a| a == "--crs")
        && std::env::var_os("HOSTILE_BIN").is_none()
    {
        args.extend(["--crs".to_string(), "planar".to_string()]);
    }
    let mut cmd = bin();
    cmd.args(&args).current_dir(scratch);
    for (k, v) in &c.env {
        cmd.env(k, v);
    }
    // a run that does not end within the bound is a failure (the hang cases)
    let o = output_within(cmd, std::time::Duration::from_secs(600))
        .map_err(|e| format!("{}: {e}", c.name))?;
    let stderr = String::from_utf8_lossy(&o.stderr).to_string();
    let code = o.status.code();
    let mut errs = Vec::new();
    if code != Some(c.code) {
        errs.push(format!("exit {code:?}, expected {}", c.code));
    }
    if stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") || code.is_none() {
        errs.push("panic/abort".to_string());
    }
    let low = stderr.to_lowercase();
    for m in c.msg {
        if !low.contains(&m.to_lowercase()) {
            errs.push(format!("stderr lacks '{m}'"));
        }
    }
    // no temporary files anywhere in the scratch directory
    let leftovers: Vec<String> = names(scratch)
        .into_iter()
        .filter(|n| n.contains(".unamalla-tmp-") || n.contains(".unamalla-old-"))
        .collect();
    if !leftovers.is_empty() {
        errs.push(format!("temporary files left: {leftovers:?}"));
    }
    if c.code != 0 && c.code != 3 && out.exists() {
        errs.push(format!("failed run left {}", out.display()));
    }
    if c.code == 0 {
        if let Some(r) = &c.region {
            let strict = c.args.iter().any(|a| a == "--no-simplify");
            if let Err(e) = check_mesh_dir(&out, r, strict) {
                errs.push(format!("independent check: {e}"));
            }
        }
    }
    if errs.is_empty() {
        Ok(o)
    } else {
        Err(format!(
            "{}: {} — stderr: {stderr}",
            c.name,
            errs.join("; ")
        ))
    }
}

pub(crate) fn run_all(cases: Vec<Case>, tag: &str) -> usize {
    let report = std::env::var_os("HOSTILE_REPORT").is_some();
    let mut failures = Vec::new();
    for (k, c) in cases.iter().enumerate() {
        let scratch = tmpdir(&format!("{tag}-{k}"));
        let t = std::time::Instant::now();
        let r = run_case(c, &scratch);
        if report {
            let (code, line) = match &r {
                Ok(o) => (
                    o.status.code(),
                    String::from_utf8_lossy(&o.stderr)
                        .lines()
                        .next()
                        .unwrap_or("")
                        .to_string(),
                ),
                Err(e) => (None, e.clone()),
            };
            println!(
                "REPORT\t{}\t{:?}\t{}",
                c.name,
                code,
                line.replace('\t', " ")
            );
        }
        if let Err(e) = r {
            failures.push(e);
        }
        eprintln!("{:>3} {:<48} {:.2} s", k, c.name, t.elapsed().as_secs_f64());
        let _ = std::fs::remove_dir_all(&scratch);
    }
    if !report {
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
    cases.len()
}

pub(crate) fn mesh_ok(name: &'static str, region: PathBuf, extra: &[&str]) -> Case {
    let mut args = vec!["mesh".to_string(), p(region.clone())];
    args.extend(extra.iter().map(|s| s.to_string()));
    args.extend(["-o", "{out}", "--quiet"].iter().map(|s| s.to_string()));
    Case {
        name,
        args,
        code: 0,
        msg: &[],
        region: Some(region),
        env: Vec::new(),
    }
}
