//! Nonsense options and huge sizes (usage: exit 2, the option named).

use crate::common::fixture;
use crate::harness::{case, hostile, p, Case};

/// The cases of nonsense options (usage: exit 2, the option named).
pub(crate) fn cases(v: &mut Vec<Case>) {
    let sq = p(hostile("square.geojson"));
    let tx = p(fixture("texas.geojson"));
    let co = p(fixture("colorado.geojson"));
    for (name, args, msg) in [
        ("mesh --cells -5", vec!["--cells", "-5"], "--cells"),
        ("mesh --cells 0", vec!["--cells", "0"], "--cells"),
        ("mesh --cells abc", vec!["--cells", "abc"], "--cells"),
        (
            "mesh --cell-size -1",
            vec!["--cell-size", "-1"],
            "--cell-size",
        ),
        (
            "mesh --cell-size nan",
            vec!["--cell-size", "nan"],
            "--cell-size",
        ),
        ("mesh --density 0", vec!["--density", "0"], "--density"),
        (
            "mesh --boundary-density 0.5",
            vec!["--boundary-density", "0.5"],
            "--boundary-density",
        ),
        (
            "mesh --strategy foo",
            vec!["--strategy", "foo"],
            "--strategy",
        ),
        ("mesh --part x", vec!["--part", "x"], "--part"),
        (
            "mesh --cells 1e9",
            vec!["--cells", "1000000000"],
            "--cells 1000000000",
        ),
        (
            "mesh --cell-size 1e-9 (huge count)",
            vec!["--cell-size", "1e-9"],
            "memory limit",
        ),
    ] {
        let mut a = vec!["mesh".to_string(), tx.clone()];
        a.extend(args.iter().map(|s| s.to_string()));
        a.extend(["-o".to_string(), "{out}".to_string()]);
        let msg: &'static [&'static str] = Box::leak(vec![msg].into());
        v.push(Case {
            name,
            args: a,
            code: 2,
            msg,
            region: None,
            env: Vec::new(),
        });
    }
    v.push(Case {
        env: vec![("UNAMALLA_MAX_MEMORY", "1M")],
        ..case(
            "mesh under UNAMALLA_MAX_MEMORY=1M",
            &["mesh", &tx, "-o", "{out}"],
            2,
            &["memory limit of 1.0 MiB"],
        )
    });
    v.push(Case {
        env: vec![("UNAMALLA_MAX_MEMORY", "lots")],
        ..case(
            "UNAMALLA_MAX_MEMORY=lots",
            &["mesh", &tx, "-o", "{out}"],
            2,
            &["UNAMALLA_MAX_MEMORY=lots"],
        )
    });
    v.push(case(
        "tfi --size 1x5",
        &["tfi", &sq, "--size", "1x5", "-o", "{out}"],
        2,
        &["--size", "2x2"],
    ));
    v.push(case(
        "tfi --size 100000x100000",
        &["tfi", &sq, "--size", "100000x100000", "-o", "{out}"],
        2,
        &["--size 100000x100000", "memory limit"],
    ));
    v.push(case(
        "tfi --corners 0,1,2",
        &[
            "tfi",
            &sq,
            "--size",
            "5x5",
            "--corners",
            "0,1,2",
            "-o",
            "{out}",
        ],
        2,
        &["--corners"],
    ));
    v.push(case(
        "tfi --corners 0,0,0,0",
        &[
            "tfi",
            &sq,
            "--size",
            "5x5",
            "--corners",
            "0,0,0,0",
            "-o",
            "{out}",
        ],
        1,
        &["corner"],
    ));
    v.push(case(
        "tfi Texas 61x61 folds: guarantee not met",
        &["tfi", &tx, "--size", "61x61", "-o", "{out}"],
        3,
        &["not convex", "--allow-non-convex"],
    ));
    v.push(case(
        "tfi Texas 61x61 --allow-non-convex: written, exit 3",
        &[
            "tfi",
            &tx,
            "--size",
            "61x61",
            "--allow-non-convex",
            "-o",
            "{out}",
        ],
        3,
        &["WARNING", "NOT met"],
    ));
    v.push(case(
        "tfi colorado ok",
        &["tfi", &co, "--size", "20x12", "-o", "{out}"],
        0,
        &[],
    ));
    v.push(case(
        "hex --size 1e6^3",
        &[
            "hex",
            "sphere",
            "--size",
            "1000000,1000000,1000000",
            "-o",
            "{out}",
        ],
        2,
        &["--size 1000000,1000000,1000000", "memory limit"],
    ));
    v.push(case(
        "hex --size 1,2,3",
        &["hex", "sphere", "--size", "1,2,3", "-o", "{out}"],
        2,
        &["--size"],
    ));
    v.push(case(
        "hex --algorithm z",
        &["hex", "box", "--algorithm", "z", "-o", "{out}"],
        2,
        &["--algorithm"],
    ));
    v.push(case(
        "hex --perturb -1",
        &["hex", "box", "--perturb", "-1", "-o", "{out}"],
        2,
        &["--perturb"],
    ));
    v.push(case(
        "hex unknown case",
        &["hex", "no-such-case", "-o", "{out}"],
        1,
        &["no-such-case"],
    ));
    v.push(case(
        "bspline --net 100000x100000",
        &["bspline", &co, "--net", "100000x100000", "-o", "{out}"],
        2,
        &["--net 100000x100000", "memory limit"],
    ));
    v.push(case(
        "bspline --net 2x2",
        &["bspline", &co, "--net", "2x2", "-o", "{out}"],
        2,
        &["--net"],
    ));
    v.push(case(
        "bspline --samples 1",
        &["bspline", &co, "--samples", "1", "-o", "{out}"],
        2,
        &["--samples"],
    ));
    v.push(case(
        "decompose --cells 0",
        &["decompose", &sq, "--cells", "0", "-o", "{out}"],
        2,
        &["--cells"],
    ));
    v.push(case(
        "simplify --method foo",
        &["simplify", &tx, "--method", "foo", "-o", "{out}"],
        1,
        &["foo"],
    ));
    v.push(case(
        "simplify bad --svg path: no partial set",
        &[
            "simplify",
            &tx,
            "-o",
            "{out}",
            "--svg",
            "/nonexistent-dir/x.svg",
        ],
        4,
        &["x.svg"],
    ));
}
