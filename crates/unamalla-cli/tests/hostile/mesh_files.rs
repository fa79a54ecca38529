//! Mesh files and their options: quality, smooth, pde, refine, eval, counts.

use crate::harness::{bad, case, hostile, p, Case};

/// The cases of mesh files: quality, smooth, pde, refine, eval.
pub(crate) fn cases(v: &mut Vec<Case>) {
    let tangled = p(hostile("tangled-grid.vtk"));
    let dart = p(hostile("fixed-dart.vtk"));
    for sub in ["quality", "eval"] {
        for (f, msg) in [
            (bad("truncated.vtk"), "truncated.vtk"),
            (bad("nan.vtk"), "nan.vtk"),
            (hostile("garbage.bin"), "garbage.bin"),
        ] {
            let name: &'static str =
                Box::leak(format!("{sub} {}", f.file_name().unwrap().to_string_lossy()).into());
            let msg: &'static [&'static str] = Box::leak(vec![&*Box::leak(msg.into())].into());
            let mut args = vec![sub.to_string(), p(f)];
            if sub == "eval" {
                args.extend(["--functional".to_string(), "area".to_string()]);
            }
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
    v.push(case("quality tangled grid", &["quality", &tangled], 0, &[]));
    v.push(case(
        "eval --functional nonsense",
        &["eval", &tangled, "--functional", "nonsense"],
        1,
        &["nonsense"],
    ));
    v.push(case(
        "smooth untangles a tangled grid",
        &["smooth", &tangled, "-o", "{out}", "--quiet"],
        0,
        &[],
    ));
    v.push(case(
        "smooth a fixed dart: nothing can move",
        &["smooth", &dart, "-o", "{out}", "--quiet"],
        1,
        &["no free nodes"],
    ));
    v.push(case(
        "smooth --solver nonsense",
        &["smooth", &tangled, "--solver", "nonsense", "-o", "{out}"],
        1,
        &["nonsense"],
    ));
    v.push(case(
        "smooth --functional area-ortho --sigma 0.7 (weight fixed at 0.5)",
        &[
            "smooth",
            &tangled,
            "--functional",
            "area-ortho",
            "--sigma",
            "0.7",
            "-o",
            "{out}",
        ],
        1,
        &["fixed at 0.5"],
    ));
    v.push(case(
        "smooth --sigma 1.5",
        &["smooth", &tangled, "--sigma", "1.5", "-o", "{out}"],
        1,
        &["sigma"],
    ));
    v.push(case(
        "smooth --homotopy t4",
        &[
            "smooth",
            &tangled,
            "--functional",
            "karea-length",
            "--homotopy",
            "t4",
            "-o",
            "{out}",
        ],
        1,
        &["t4", "linear, t2, t3, sine"],
    ));
    v.push(case(
        "smooth --pointwise-mode diagonal",
        &[
            "smooth",
            &tangled,
            "--pointwise-mode",
            "diagonal",
            "-o",
            "{out}",
        ],
        1,
        &["diagonal", "simultaneous, components"],
    ));
    v.push(case(
        "smooth --lbfgs-memory 0",
        &[
            "smooth",
            &tangled,
            "--solver",
            "lbfgs",
            "--lbfgs-memory",
            "0",
            "-o",
            "{out}",
        ],
        1,
        &["lbfgs_memory"],
    ));
    v.push(case(
        "smooth karea-length, sine homotopy, σ 0.9, L-BFGS m = 3",
        &[
            "smooth",
            &tangled,
            "--functional",
            "karea-length",
            "--homotopy",
            "sine",
            "--sigma",
            "0.9",
            "--solver",
            "lbfgs",
            "--lbfgs-memory",
            "3",
            "-o",
            "{out}",
            "--quiet",
        ],
        0,
        &[],
    ));
    v.push(case(
        "smooth --functional ivanenko untangles",
        &[
            "smooth",
            &tangled,
            "--functional",
            "ivanenko",
            "-o",
            "{out}",
            "--quiet",
        ],
        0,
        &[],
    ));
    v.push(case(
        "smooth pointwise by components, t3 homotopy",
        &[
            "smooth",
            &tangled,
            "--functional",
            "ksmooth-area",
            "--homotopy",
            "t3",
            "--solver",
            "pointwise",
            "--pointwise-mode",
            "components",
            "-o",
            "{out}",
            "--quiet",
        ],
        0,
        &[],
    ));
    v.push(case(
        "pde --g const:1e300 overflow",
        &["pde", &tangled, "--g", "const:1e300", "-o", "{out}"],
        2,
        &["numeric overflow", "--g"],
    ));
    v.push(case(
        "pde --a 1e308 overflow",
        &["pde", &tangled, "--a", "1e308", "-o", "{out}"],
        2,
        &["numeric overflow", "--a"],
    ));
    v.push(case(
        "pde --solver nonsense",
        &["pde", &tangled, "--solver", "nonsense", "-o", "{out}"],
        2,
        &["--solver"],
    ));
    v.push(case(
        "refine a folded grid",
        &["refine", &tangled, "--factor", "2", "-o", "{out}"],
        1,
        &[],
    ));
    v.push(case(
        "counts malformed problem",
        &["counts", &p(bad("malformed-json.geojson"))],
        1,
        &["malformed-json.geojson"],
    ));
}
