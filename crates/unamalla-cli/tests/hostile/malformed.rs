//! Malformed files, across the region readers of every subcommand.

use crate::harness::{bad, hostile, p, Case};

/// The cases of malformed files, across the region readers of every subcommand.
pub(crate) fn cases(v: &mut Vec<Case>) {
    for (sub, extra) in [
        ("mesh", vec!["--cells", "200"]),
        ("tfi", vec!["--size", "10x10"]),
        ("decompose", vec![]),
        ("simplify", vec![]),
        ("bspline", vec!["--net", "5x5"]),
    ] {
        for (file, msg) in [
            (bad("malformed-json.geojson"), "malformed-json.geojson"),
            (bad("empty.geojson"), "empty.geojson"),
            (hostile("garbage.bin"), "garbage.bin"),
            (hostile("point.geojson"), "point"),
            (hostile("bow-tie.geojson"), "intersect"),
            (bad("nan.geojson"), "nan.geojson"),
        ] {
            let name: &'static str =
                Box::leak(format!("{sub} {}", file.file_name().unwrap().to_string_lossy()).into());
            let msg: &'static [&'static str] = Box::leak(vec![&*Box::leak(msg.into())].into());
            let mut args = vec![sub.to_string(), p(file)];
            args.extend(extra.iter().map(|s| s.to_string()));
            args.extend(["-o".to_string(), "{out}".to_string()]);
            v.push(Case {
                name,
                args,
                code: 1,
                msg,
                region: None,
                env: Vec::new(),
            });
        }
    }
}
