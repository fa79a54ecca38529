//! Solver formats and GIS input: named boundary patches through `unamalla mesh` to Gmsh, SU2,
//! OpenFOAM (and CGNS with `--features cgns`), checked by the formats' own tools through
//! `scripts/check_solver_formats.py`; lon/lat input meshed in km; `report.html` rendered by
//! headless Chromium; `quality` on every mesh format `mesh` writes.
//!
//! A check whose tool is missing prints "skipped: …" and passes; `bash
//! scripts/install_solver_tools.sh` installs them all (Debian `openfoam`, `cgns-convert`,
//! `chromium`; PyPI `gmsh`, `meshio`, `vtk`).

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use common::{bin, report, tmpdir, RunOk};
use unamalla_io::{read_msh, MshMesh};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The Puget Sound water region with `coast`, `open-sea` and `island` patches, meshed once.
fn puget() -> &'static Path {
    static OUT: OnceLock<PathBuf> = OnceLock::new();
    OUT.get_or_init(|| {
        let out = tmpdir("puget").join("out");
        let mut exports = "msh,su2,openfoam".to_string();
        if cfg!(feature = "cgns") {
            exports.push_str(",cgns");
        }
        bin()
            .arg("mesh")
            .arg(repo().join("fixtures/patches/puget-sound-patches.geojson"))
            .args(["--cells", "12000", "--quiet", "--export", &exports, "-o"])
            .arg(&out)
            .run_ok();
        out
    })
}

/// Edge counts per patch as our own reader sees `mesh.msh`.
fn msh_patch_counts(out: &Path) -> BTreeMap<String, usize> {
    let f = read_msh(out.join("mesh.msh")).unwrap();
    f.edge_groups
        .iter()
        .map(|g| (g.name.clone(), g.edges.len()))
        .collect()
}

/// Runs the checker on `out` for the given formats; `None` when Python is absent.
fn check(out: &Path, only: &str) -> Option<serde_json::Value> {
    let o = Command::new("python3")
        .arg(repo().join("scripts/check_solver_formats.py"))
        .arg(out)
        .args(["--only", only])
        .output()
        .ok()?;
    assert!(
        o.status.success(),
        "checker failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    Some(serde_json::from_slice(&o.stdout).unwrap())
}

fn skipped(v: &serde_json::Value) -> Option<&str> {
    v.get("skipped").and_then(|s| s.as_str())
}

#[test]
fn named_patches_are_in_mesh_msh_with_open_sea_on_the_box() {
    let out = puget();
    let counts = msh_patch_counts(out);
    let names: Vec<&str> = counts.keys().map(String::as_str).collect();
    assert_eq!(names, ["coast", "island", "open-sea"]);
    // open-sea edges lie on the clipping box: both nodes on one side of the mesh's bounding
    // box (the box edges are straight, so simplification keeps them)
    let f = read_msh(out.join("mesh.msh")).unwrap();
    let MshMesh::Quads(q) = &f.mesh else {
        panic!("quads expected")
    };
    use unamalla_core::mesh::HasNodes;
    let nodes = q.nodes();
    let (lo, hi) = nodes
        .iter()
        .fold((nodes[0], nodes[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    // distance of a point from the box's boundary
    let off_box = |p: unamalla_core::mesh::DVec2| {
        (p.x - lo.x)
            .abs()
            .min((p.x - hi.x).abs())
            .min((p.y - lo.y).abs())
            .min((p.y - hi.y).abs())
    };
    // the mesh boundary is within the simplification's Hausdorff distance of the input, so
    // every open-sea node lies within it of the box; the box sides are straight, so most lie
    // exactly on it
    let hausdorff = report(out)["hausdorff"].as_f64().unwrap();
    let sea = f.edge_group("open-sea").unwrap();
    assert!(!sea.edges.is_empty());
    let mut exact = 0;
    for &[a, b] in &sea.edges {
        let d = off_box(nodes[a]).max(off_box(nodes[b]));
        assert!(
            d <= hausdorff + 1e-9,
            "open-sea edge {a}-{b} is {d} from the box"
        );
        exact += usize::from(d < 1e-9 * (hi - lo).length());
    }
    assert!(
        exact * 10 >= sea.edges.len() * 9,
        "only {exact} of {} open-sea edges on the box",
        sea.edges.len()
    );
    // coast edges are away from the box, apart from the few where a coast meets it
    let coast = f.edge_group("coast").unwrap();
    let on = coast
        .edges
        .iter()
        .filter(|&&[a, b]| off_box(nodes[a]).max(off_box(nodes[b])) < 1e-9)
        .count();
    assert!(on * 100 <= coast.edges.len(), "{on} coast edges on the box");
    let r = report(out);
    let total: usize = counts.values().sum();
    assert!(total > 0 && r["cells"].as_u64().unwrap() > 3000);
}

#[test]
fn gmsh_lists_the_physical_curves_with_their_element_counts() {
    let out = puget();
    let Some(v) = check(out, "msh") else {
        println!("skipped: python3 not found");
        return;
    };
    if let Some(why) = skipped(&v["msh"]) {
        println!("skipped: {why}");
        return;
    }
    let ours = msh_patch_counts(out);
    let gmsh: BTreeMap<String, usize> =
        serde_json::from_value(v["msh"]["physical_curves"].clone()).unwrap();
    assert_eq!(gmsh, ours);
    let r = report(out);
    assert_eq!(v["msh"]["surfaces"], r["blocks"], "one surface per block");
    assert_eq!(v["msh"]["physical_surfaces"]["domain"], r["cells"]);
}

#[test]
fn meshio_reads_the_su2_markers() {
    let out = puget();
    let Some(v) = check(out, "su2") else {
        println!("skipped: python3 not found");
        return;
    };
    if let Some(why) = skipped(&v["su2"]) {
        println!("skipped: {why}");
        return;
    }
    let ours = msh_patch_counts(out);
    let markers: BTreeMap<String, usize> =
        serde_json::from_value(v["su2"]["markers"].clone()).unwrap();
    assert_eq!(markers, ours);
    assert_eq!(v["su2"]["cells"]["quad"], report(out)["cells"]);
}

#[test]
/// `checkMesh` on the extruded mesh: no failed check (it failed the boundary skewness test,
/// 4.14–4.98 > 4, while the triangle-block rule split a 36° coastal tip between two cells of
/// ≈ 18°; a sharp tip is now a block corner, one cell: max skewness 3.25).
fn openfoam_check_mesh_says_mesh_ok() {
    let out = puget();
    let Some(v) = check(out, "openfoam") else {
        println!("skipped: python3 not found");
        return;
    };
    let of = &v["openfoam"];
    if let Some(why) = skipped(of) {
        println!("skipped: {why}");
        return;
    }
    assert_eq!(of["fatal"], false, "{of}");
    assert_eq!(of["failed_checks"], 0, "{of}");
    assert_eq!(of["mesh_ok"], true, "{of}");
    assert_eq!(of["cells"], report(out)["cells"]);
    let ours = msh_patch_counts(out);
    for (name, n) in &ours {
        assert_eq!(
            of["patches"][name].as_u64(),
            Some(*n as u64),
            "patch {name}"
        );
    }
    assert_eq!(
        of["patches"]["frontAndBack"].as_u64(),
        report(out)["cells"].as_u64().map(|c| 2 * c)
    );
}

#[test]
fn cgnscheck_and_vtk_read_the_structured_zones() {
    if !cfg!(feature = "cgns") {
        println!(
            "skipped: built without --features cgns (cargo test -p unamalla-cli --features cgns)"
        );
        return;
    }
    let out = puget();
    let Some(v) = check(out, "cgns") else {
        println!("skipped: python3 not found");
        return;
    };
    let c = &v["cgns"];
    if let Some(why) = skipped(c) {
        println!("skipped: {why}");
        return;
    }
    assert_eq!(c["cgnscheck_exit"], 0, "{c}");
    assert_eq!(c["errors"].as_array().unwrap().len(), 0, "{c}");
    assert_eq!(c["warnings"].as_array().unwrap().len(), 0, "{c}");
    let r = report(out);
    if skipped(&c["vtk"]).is_none() {
        assert_eq!(c["vtk"]["structured_zones"], r["blocks"]);
        assert_eq!(c["vtk"]["cells"], r["cells"]);
    } else {
        println!("skipped (second reader): vtk not installed");
    }
}

#[test]
fn lonlat_geojson_meshes_in_km() {
    // Luxembourg in WGS84 lon/lat: meshed in a transverse Mercator in km, target cell size 2 km
    let dir = tmpdir("lux");
    let out = dir.join("out");
    let o = bin()
        .arg("mesh")
        .arg(repo().join("fixtures/gis/luxembourg.geojson"))
        .args(["--cell-size", "2", "--lonlat", "--export", "msh", "-o"])
        .arg(&out)
        .run_ok();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("WGS84 lon/lat"), "{stderr}");
    let f = read_msh(out.join("mesh.msh")).unwrap();
    let MshMesh::Quads(q) = &f.mesh else {
        panic!("quads expected")
    };
    use unamalla_core::mesh::{HasNodes, HasQuadCells};
    // the mesh spans the country in km: 0.568° of longitude at 49.8° ≈ 40.9 km,
    // 0.685° of latitude ≈ 76.2 km
    let nodes = q.nodes();
    let (lo, hi) = nodes
        .iter()
        .fold((nodes[0], nodes[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let d = hi - lo;
    assert!(
        (d.x - 40.9).abs() < 1.5 && (d.y - 76.2).abs() < 1.5,
        "extent {d} km"
    );
    // cells of the intended size: mean cell area ≈ (2 km)²
    let area: f64 = (0..q.num_quads())
        .map(|c| {
            let v = q.quad(c).map(|k| nodes[k]);
            0.5 * ((v[2] - v[0]).perp_dot(v[3] - v[1]))
        })
        .sum();
    let mean = area / q.num_quads() as f64;
    assert!(
        (mean.sqrt() - 2.0).abs() < 0.3,
        "mean cell size {} km",
        mean.sqrt()
    );
    // back-projected copy: every node in the country's lon/lat box
    let ll = read_msh(out.join("mesh-lonlat.msh")).unwrap();
    let MshMesh::Quads(llq) = &ll.mesh else {
        panic!("quads expected")
    };
    for p in llq.nodes() {
        assert!(
            p.x > 5.66 && p.x < 6.25 && p.y > 49.43 && p.y < 50.14,
            "{p}"
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn planar_looking_text_input_warns_and_crs_planar_silences() {
    let dir = tmpdir("warn");
    let region = dir.join("square.txt");
    std::fs::write(&region, "0 0\n10 0\n10 8\n0 8\n").unwrap();
    let run = |extra: &[&str]| {
        bin()
            .arg("mesh")
            .arg(&region)
            .args(["--cells", "200", "--export", "none", "--no-report", "-o"])
            .arg(dir.join("out"))
            .args(extra)
            .run_ok()
    };
    let warned = String::from_utf8_lossy(&run(&[]).stderr).into_owned();
    assert!(
        warned.contains("warning:") && warned.contains("--crs lonlat"),
        "{warned}"
    );
    let quiet = String::from_utf8_lossy(&run(&["--crs", "planar"]).stderr).into_owned();
    assert!(!quiet.contains("warning:"), "{quiet}");
    let bad = bin()
        .arg("mesh")
        .arg(&region)
        .args(["--crs", "EPSG:9999", "-o"])
        .arg(dir.join("out2"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown CRS"));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn quality_reads_every_mesh_format_mesh_writes() {
    let out = puget();
    let cells = report(out)["cells"].as_u64().unwrap();
    for f in ["mesh.vtu", "blocks.vtm", "mesh.msh"] {
        let o = bin().args(["quality", "--json"]).arg(out.join(f)).run_ok();
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let n = v["cells"].as_u64().or_else(|| v["num_cells"].as_u64());
        assert_eq!(n, Some(cells), "{f}: {v}");
    }
    bin()
        .args(["quality"])
        .arg(out.join("block-0.vts"))
        .run_ok();
}

#[test]
fn report_html_is_self_contained_and_renders_in_chromium() {
    let out = puget();
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    for needle in [
        "<svg id=\"mesh\"",
        "class=\"block\"",
        "aria-label=\"μ\"",
        "aria-label=\"scaled Jacobian\"",
        "<table id=\"blocks\"",
        "<td class=\"l\">open-sea</td>",
        "<table id=\"settings\"",
    ] {
        assert!(html.contains(needle), "report.html lacks {needle}");
    }
    assert!(!html.contains("src=\"http") && !html.contains("href=\"http"));
    let blocks = report(out)["blocks"].as_u64().unwrap() as usize;
    assert_eq!(html.matches("class=\"block\"").count(), blocks);
    let Some(chromium) = ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| {
            Command::new(c)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
    else {
        println!("skipped: headless Chromium not found (Debian package chromium)");
        return;
    };
    let url = format!(
        "file://{}",
        out.join("report.html").canonicalize().unwrap().display()
    );
    let profile = tmpdir("chromium-profile");
    let dom = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(["--dump-dom", &url])
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&dom.stdout);
    // the page's script ran to its end (zoom handlers installed) and the picture is there
    assert!(
        dom.contains("data-ready=\"yes\""),
        "script did not run: {}",
        &dom[..dom.len().min(300)]
    );
    assert!(dom.contains("<svg id=\"mesh\""));
    let shot = out.join("report.png");
    let s = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            "--window-size=1300,1400",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(&url)
        .output()
        .unwrap();
    assert!(s.status.success(), "{}", String::from_utf8_lossy(&s.stderr));
    let png = std::fs::read(&shot).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    assert!(
        png.len() > 20_000,
        "screenshot of {} bytes: blank page?",
        png.len()
    );
    std::fs::remove_dir_all(profile).ok();
}

#[test]
fn binary_mesh_vtu_is_read_by_meshio_and_vtk() {
    let out = puget();
    let vtu = out.join("mesh.vtu");
    let text = std::fs::read_to_string(&vtu).unwrap();
    assert!(
        text.contains("format=\"binary\""),
        "a mesh above the threshold is binary"
    );
    let cells = report(out)["cells"].as_u64().unwrap();
    let script = format!(
        "import meshio, vtk\nm = meshio.read({p:?})\nr = vtk.vtkXMLUnstructuredGridReader()\nr.SetFileName({p:?})\nr.Update()\nprint(len(m.cells_dict['quad']), r.GetOutput().GetNumberOfCells())",
        p = vtu.display().to_string()
    );
    let Ok(o) = Command::new("python3").args(["-c", &script]).output() else {
        println!("skipped: python3 not found");
        return;
    };
    if !o.status.success() {
        println!(
            "skipped: meshio or vtk not installed ({})",
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
        return;
    }
    assert_eq!(
        String::from_utf8_lossy(&o.stdout).trim(),
        format!("{cells} {cells}")
    );
}
