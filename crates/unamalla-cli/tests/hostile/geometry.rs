//! Degenerate but valid geometry: a square, a clockwise L, 10⁻⁶/10⁶ scales, a 10⁹ offset, the
//! 10⁻⁷ spike, a hole 10⁻⁹ from the outer ring, MultiPolygons, a 10⁻³ slit.

use crate::harness::{case, hostile, mesh_ok, p, Case};

/// The cases of degenerate but valid geometry.
pub(crate) fn cases(v: &mut Vec<Case>) {
    v.push(mesh_ok(
        "mesh square",
        hostile("square.geojson"),
        &["--cells", "400"],
    ));
    v.push(mesh_ok(
        "mesh clockwise L",
        hostile("l-clockwise.geojson"),
        &["--cells", "300"],
    ));
    v.push(mesh_ok(
        "mesh L at 1e-6",
        hostile("l-1e-6.geojson"),
        &["--cells", "300"],
    ));
    v.push(mesh_ok(
        "mesh L at 1e6",
        hostile("l-1e6.geojson"),
        &["--cells", "300"],
    ));
    // an L of 2 units at (10⁹, 10⁹): the cut test and the area check work in the coordinates'
    // precision (docs/reliability.md)
    v.push(mesh_ok(
        "mesh L offset 1e9",
        hostile("l-offset-1e9.geojson"),
        &["--cells", "300"],
    ));
    v.push(mesh_ok(
        "mesh 1e-7 spike (simplified)",
        hostile("spike-1e-7.geojson"),
        &["--cells", "300"],
    ));
    // a spike 2·10⁻⁷ wide (below 0.01 × the cell size 0.58) cannot be meshed as given: refused
    // before the work, the vertex and the width named (preflight::check_narrow_features)
    v.push(case(
        "mesh 1e-7 spike --no-simplify: refused before the work",
        &[
            "mesh",
            &p(hostile("spike-1e-7.geojson")),
            "--no-simplify",
            "--cells",
            "300",
            "-o",
            "{out}",
            "--quiet",
        ],
        1,
        &[
            "the outer ring, vertex",
            "is 2.000e-7 from the same ring",
            "meshable gap",
            "drop --no-simplify",
        ],
    ));
    // a best effort asked for: the check is skipped, the mesh fails the guarantee and is
    // written with a warning, exit 3
    v.push(case(
        "mesh 1e-7 spike --no-simplify --allow-non-convex: written, exit 3",
        &[
            "mesh",
            &p(hostile("spike-1e-7.geojson")),
            "--no-simplify",
            "--allow-non-convex",
            "--cells",
            "300",
            "-o",
            "{out}",
            "--quiet",
        ],
        3,
        &["WARNING", "guarantee is NOT met", "outside the region"],
    ));
    v.push(case(
        "mesh hole 1e-9 from the outer ring",
        &[
            "mesh",
            &p(hostile("hole-1e-9.geojson")),
            "--cells",
            "500",
            "-o",
            "{out}",
            "--quiet",
        ],
        1,
        &["hole 0 is 1.000e-9 from the outer ring", "cell size"],
    ));
    v.push(mesh_ok(
        "mesh two-part MultiPolygon: every part",
        hostile("two-parts.geojson"),
        &["--cells", "300"],
    ));
    v.push(case(
        "mesh two-part MultiPolygon --part 5",
        &[
            "mesh",
            &p(hostile("two-parts.geojson")),
            "--part",
            "5",
            "-o",
            "{out}",
        ],
        1,
        &["--part 5", "2 polygon part"],
    ));
    v.push(case(
        "tfi two-part MultiPolygon without --part",
        &[
            "tfi",
            &p(hostile("two-parts.geojson")),
            "--size",
            "10x10",
            "-o",
            "{out}",
        ],
        1,
        &["MultiPolygon with 2 parts", "--part"],
    ));
    v.push(case(
        "decompose two-part MultiPolygon without --part",
        &["decompose", &p(hostile("two-parts.geojson")), "-o", "{out}"],
        1,
        &["--part"],
    ));
    v.push(mesh_ok(
        "mesh slit 1e-3 wide (simplified)",
        hostile("slit.geojson"),
        &["--cells", "300"],
    ));
}
