//! Ring and hole defects, and unreadable paths.

use crate::harness::{bad, case, hostile, p, Case};

/// The cases of ring and hole defects.
pub(crate) fn cases(v: &mut Vec<Case>) {
    for (f, msg) in [
        ("hole-outside.geojson", "hole"),
        ("overlapping-holes.geojson", "hole"),
        ("nested-holes.geojson", "hole"),
        ("too-few-points.geojson", "point"),
        ("zero-area.geojson", "area"),
        ("touching.geojson", "touch"),
    ] {
        let name: &'static str = Box::leak(format!("mesh {f}").into());
        let msg: &'static [&'static str] = Box::leak(vec![msg].into());
        v.push(Case {
            name,
            args: vec![
                "mesh".into(),
                p(bad(f)),
                "-o".into(),
                "{out}".into(),
                "--quiet".into(),
            ],
            code: 1,
            msg,
            region: None,
            env: Vec::new(),
        });
    }
    v.push(case(
        "mesh hole crossing the outer ring",
        &["mesh", &p(hostile("hole-crossing.geojson")), "-o", "{out}"],
        1,
        &["hole"],
    ));
    v.push(case(
        "mesh missing file",
        &["mesh", "no-such-file.geojson", "-o", "{out}"],
        1,
        &["no-such-file.geojson"],
    ));
    v.push(case(
        "mesh a directory as region",
        &["mesh", ".", "-o", "{out}"],
        1,
        &[],
    ));
}
