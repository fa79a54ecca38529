//! The bad-input catalogue (`tests/bad_inputs/cases.json` at the repository
//! root), checked at the library level: every case's reader returns the expected error
//! **variant** (matched on the enums, see [`variant`]), or — for inputs that are valid though
//! unusual ("ok", "ok:mesh") — is accepted and, for "ok:mesh", meshed by the default pipeline
//! with no non-convex cell. The CLI side is `crates/unamalla-cli/tests/bad_inputs.rs`.

use std::path::{Path, PathBuf};

use unamalla_core::compat_ilp::{self as ilp, CompatError, CompatProblem};
use unamalla_core::decompose::{DecomposeError, Decomposition};
use unamalla_core::io::{self, IoError, PartSelector};
use unamalla_core::mesh::{GeometryError, Region};
use unamalla_core::pipeline::Mesher;
use unamalla_core::CoreError;

fn catalogue_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad_inputs")
}

fn scratch() -> PathBuf {
    let d = std::env::temp_dir().join(format!("unamalla-core-bad-inputs-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The catalogue's name of an error variant: `<Enum>::<Variant>`, with region validation
/// errors (however wrapped) as `Geometry::<Variant>`. Variants the catalogue does not use are
/// named by their debug form so a mismatch message shows them.
fn variant(e: &CoreError) -> String {
    fn geometry(g: &GeometryError) -> &'static str {
        match g {
            GeometryError::TooFewPoints { .. } => "TooFewPoints",
            GeometryError::NonFinite { .. } => "NonFinite",
            GeometryError::CoordinateOutOfRange { .. } => "CoordinateOutOfRange",
            GeometryError::RepeatedPoint { .. } => "RepeatedPoint",
            GeometryError::ZeroArea { .. } => "ZeroArea",
            GeometryError::SelfIntersection { .. } => "SelfIntersection",
            GeometryError::RingsIntersect { .. } => "RingsIntersect",
            GeometryError::HoleOutside { .. } => "HoleOutside",
            GeometryError::NestedHole { .. } => "NestedHole",
            _ => "other",
        }
    }
    match e {
        CoreError::Geometry(g)
        | CoreError::Io(IoError::Geometry { source: g, .. })
        | CoreError::Io(IoError::InvalidRegion { source: g, .. }) => {
            format!("Geometry::{}", geometry(g))
        }
        CoreError::Io(io) => match io {
            IoError::Json { .. } => "Io::Json".into(),
            IoError::WrongGeometryType { .. } => "Io::WrongGeometryType".into(),
            IoError::RingTooShort { .. } => "Io::RingTooShort".into(),
            IoError::BadCoordinate { .. } => "Io::BadCoordinate".into(),
            IoError::Truncated { .. } => "Io::Truncated".into(),
            IoError::Malformed { .. } => "Io::Malformed".into(),
            IoError::Mesh { .. } => "Io::Mesh".into(),
            IoError::MalformedBinary { .. } => "Io::MalformedBinary".into(),
            other => format!("Io::other({other:?})"),
        },
        CoreError::Decompose(d) => match d {
            DecomposeError::CutCrossesBoundary { .. } => "Decompose::CutCrossesBoundary".into(),
            DecomposeError::Json { .. } => "Decompose::Json".into(),
            other => format!("Decompose::other({other:?})"),
        },
        CoreError::Counts(c) => match c {
            CompatError::Infeasible(_) => "Counts::Infeasible".into(),
            other => format!("Counts::other({other:?})"),
        },
        other => format!("other({other:?})"),
    }
}

/// A 10⁶-vertex ellipse (semi-axes 1000 and 700) as GeoJSON, closed.
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

struct Case {
    name: String,
    file: PathBuf,
    reader: String,
    expect: String,
    region: Option<PathBuf>,
    generated: bool,
}

fn cases(out: &Path) -> Vec<Case> {
    let dir = catalogue_dir();
    let text = std::fs::read_to_string(dir.join("cases.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let s = |k: &str| c[k].as_str().unwrap().to_string();
            let file = s("file");
            let file = if file.contains("{out}") {
                PathBuf::from(file.replace("{out}", out.to_str().unwrap()))
            } else {
                dir.join(file)
            };
            Case {
                name: s("name"),
                file,
                reader: s("reader"),
                expect: s("expect"),
                region: c["region"].as_str().map(|r| dir.join(r)),
                generated: c["generate"].is_string(),
            }
        })
        .collect()
}

/// Runs one case's reader; `Ok(Some(region))` when a region was read (so "ok:mesh" can mesh it).
fn run(case: &Case) -> Result<Option<Region>, CoreError> {
    let f = &case.file;
    match case.reader.as_str() {
        // what the CLI uses: repeated consecutive points are removed
        "region" => Ok(Some(
            io::read_region_geojson_cleaned(f, PartSelector::Largest)?.0,
        )),
        "region_strict" => Ok(Some(io::read_region_geojson(f, PartSelector::Largest)?)),
        "vtk" => io::read_vtk(f).map(|_| None).map_err(Into::into),
        "msh" => io::read_msh(f).map(|_| None).map_err(Into::into),
        "shapefile" => Ok(Some(io::read_region_shapefile(f, PartSelector::Largest)?)),
        "decomposition" => {
            let region =
                io::read_region_geojson(case.region.as_ref().unwrap(), PartSelector::Largest)?;
            let text = std::fs::read_to_string(f).unwrap();
            Decomposition::from_json(&text, &region)?;
            Ok(None)
        }
        "compat" => {
            let text = std::fs::read_to_string(f).unwrap();
            let problem: CompatProblem = serde_json::from_str(&text).unwrap();
            ilp::solve(&problem, &ilp::SolveOptions::density(1))?;
            Ok(None)
        }
        other => panic!("{}: unknown reader {other:?}", case.name),
    }
}

#[test]
fn every_catalogue_case_gives_its_variant() {
    let out = scratch();
    let all = cases(&out);
    assert!(all.len() >= 20, "the catalogue has {} cases", all.len());
    let mut failures = Vec::new();
    // generated cases (the 10⁶-vertex ring) have their own test below
    for case in all.iter().filter(|c| !c.generated) {
        let t = std::time::Instant::now();
        let got = run(case);
        let seconds = t.elapsed().as_secs_f64();
        let ok = match (&got, case.expect.as_str()) {
            (Ok(_), "ok") => true,
            (Ok(Some(region)), "ok:mesh") => {
                let r = Mesher::new().cells(300).mesh(region);
                match r {
                    Ok(m) => {
                        if m.report.non_convex_cells != 0 {
                            failures.push(format!(
                                "{}: {} non-convex cells",
                                case.name, m.report.non_convex_cells
                            ));
                        }
                        true
                    }
                    Err(e) => {
                        failures.push(format!("{}: meshing failed: {e}", case.name));
                        true
                    }
                }
            }
            (Err(e), want) => variant(e) == want,
            _ => false,
        };
        if !ok {
            let got = match &got {
                Ok(_) => "ok".to_string(),
                Err(e) => format!("{} ({e})", variant(e)),
            };
            failures.push(format!(
                "{}: expected {}, got {got}",
                case.name, case.expect
            ));
        }
        // the library answers every case promptly (generous bound for a loaded machine)
        assert!(seconds < 30.0, "{}: {seconds:.1} s", case.name);
    }
    let _ = std::fs::remove_dir_all(&out);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The catalogue's generated case: the 10⁶-vertex ring is a valid region with exactly 10⁶
/// vertices (the closing position is dropped) and the area of the inscribed polygon: for a
/// regular n-gon inscribed in an ellipse with semi-axes a, b (an affine image of the
/// circle's), area = (n/2)·a·b·sin(2π/n) = π·a·b·(1 − O(n⁻²)).
#[test]
fn million_vertex_ring_is_read_exactly() {
    let n = 1_000_000;
    let t = std::time::Instant::now();
    let region = io::parse_region_geojson(&ellipse_geojson(n), PartSelector::Largest).unwrap();
    assert!(t.elapsed().as_secs_f64() < 30.0, "{:?}", t.elapsed());
    assert_eq!(region.outer().len(), n);
    let (a, b) = (1000.0, 700.0);
    let exact = 0.5 * n as f64 * a * b * (std::f64::consts::TAU / n as f64).sin();
    assert!(
        (region.area() - exact).abs() < 1e-6 * exact,
        "{} vs {exact}",
        region.area()
    );
}
