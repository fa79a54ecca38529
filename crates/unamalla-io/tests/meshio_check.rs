//! Independent check of the VTK writers with a real third-party reader: meshio (Python), driven
//! by `scripts/check_vtk_meshio.py`. If `python3 -c "import meshio"` fails the test prints
//! "skipped: meshio not installed" and passes (CI installs meshio).
//!
//! Besides the counts checked by the script, the values meshio read (dumped by `--dump`, floats
//! as Python `repr` strings) are compared with the written mesh: every coordinate and cell
//! value bit for bit, and every cell's node list exactly (meshio builds the cells of a
//! structured grid itself, in VTK order, so those compare equal to our grid cells too).

mod common;

use std::path::Path;
use std::process::Command;

use common::*;
use unamalla_io::*;
use unamalla_mesh::{DVec2, DVec3, HasHexCells, HasNodes, HasQuadCells, HexMesh};

/// What meshio read, from the script's `--dump` file.
struct Dump {
    points: Vec<Vec<f64>>,
    cells: Vec<Vec<usize>>,
    cell_types: Vec<String>,
    cell_data: Vec<(String, Vec<f64>)>,
}

fn parse_repr(v: &serde_json::Value) -> f64 {
    v.as_str()
        .expect("float as repr string")
        .parse()
        .expect("python repr parses")
}

fn load_dump(path: &Path) -> Dump {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let points = v["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_array().unwrap().iter().map(parse_repr).collect())
        .collect();
    let mut cells = Vec::new();
    let mut cell_types = Vec::new();
    for block in v["cells"].as_array().unwrap() {
        for row in block["data"].as_array().unwrap() {
            cells.push(
                row.as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_u64().unwrap() as usize)
                    .collect(),
            );
            cell_types.push(block["type"].as_str().unwrap().to_string());
        }
    }
    let cell_data = v["cell_data"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, vals)| {
            (
                k.clone(),
                vals.as_array().unwrap().iter().map(parse_repr).collect(),
            )
        })
        .collect();
    Dump {
        points,
        cells,
        cell_types,
        cell_data,
    }
}

fn assert_points2(d: &Dump, nodes: &[DVec2]) {
    assert_eq!(d.points.len(), nodes.len());
    for (p, q) in d.points.iter().zip(nodes) {
        assert_eq!(p[0].to_bits(), q.x.to_bits());
        assert_eq!(p[1].to_bits(), q.y.to_bits());
        assert_eq!(p[2], 0.0);
    }
}

fn assert_points3(d: &Dump, nodes: &[DVec3]) {
    assert_eq!(d.points.len(), nodes.len());
    for (p, q) in d.points.iter().zip(nodes) {
        assert_eq!(
            [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()],
            [q.x.to_bits(), q.y.to_bits(), q.z.to_bits()]
        );
    }
}

fn assert_quads(d: &Dump, m: &impl HasQuadCells) {
    assert_points2(d, m.nodes());
    assert_eq!(d.cells.len(), m.num_quads());
    for (c, cell) in d.cells.iter().enumerate() {
        assert_eq!(cell.as_slice(), m.quad(c).as_slice(), "cell {c}");
        assert_eq!(d.cell_types[c], "quad");
    }
}

fn assert_hexes(d: &Dump, m: &impl HasHexCells) {
    assert_points3(d, m.nodes());
    assert_eq!(d.cells.len(), m.num_hexes());
    for (c, cell) in d.cells.iter().enumerate() {
        assert_eq!(cell.as_slice(), m.hex(c).as_slice(), "cell {c}");
        assert_eq!(d.cell_types[c], "hexahedron");
    }
}

fn assert_arrays(d: &Dump, arrays: &[(&str, &[f64])]) {
    assert_eq!(d.cell_data.len(), arrays.len());
    for (name, values) in arrays {
        let (_, got) = d
            .cell_data
            .iter()
            .find(|(n, _)| n == name)
            .expect("array present");
        let a: Vec<u64> = got.iter().map(|x| x.to_bits()).collect();
        let b: Vec<u64> = values.iter().map(|x| x.to_bits()).collect();
        assert_eq!(a, b, "array {name}");
    }
}

fn meshio_available() -> bool {
    Command::new("python3")
        .args(["-c", "import meshio"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// Runs the script on `file` and returns what meshio read.
fn check(
    file: &Path,
    points: usize,
    cells: usize,
    cell_type: &str,
    arrays: &[&str],
    planar: bool,
) -> Dump {
    let dump = file.with_extension("meshio.json");
    let script = scripts_dir().join("check_vtk_meshio.py");
    let mut cmd = Command::new("python3");
    cmd.arg(&script)
        .arg(file)
        .args(["--points", &points.to_string()])
        .args(["--cells", &cells.to_string()])
        .args(["--cell-type", cell_type]);
    for a in arrays {
        cmd.args(["--cell-array", a]);
    }
    if planar {
        cmd.arg("--planar");
    }
    cmd.arg("--dump").arg(&dump);
    let out = cmd.output().expect("run python3");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{}\n{stdout}", file.display());
    assert!(
        out.status.success(),
        "meshio check failed for {} (status {:?})\nstdout:\n{stdout}\nstderr:\n{stderr}",
        file.display(),
        out.status.code()
    );
    assert!(stdout.contains("\"ok\": true"), "{stdout}");
    load_dump(&dump)
}

#[test]
fn meshio_reads_what_we_write() {
    if !meshio_available() {
        println!("skipped: meshio not installed (pip install meshio to run this check)");
        return;
    }
    let dir = Scratch::new("meshio");

    let quads = l_shaped_quads();
    let p = dir.path("quads.vtk");
    // Extreme magnitudes: the smallest subnormal, the largest finite, and 1/3.
    let (q, b) = ([5e-324, f64::MAX, 1.0 / 3.0], [-0.0, 1e-300, 2.5e17]);
    let arrays: [(&str, &[f64]); 2] = [("quality", &q), ("block", &b)];
    write_vtk_quads(&p, &quads, &arrays).unwrap();
    let d = check(&p, 8, 3, "quad", &["quality", "block"], true);
    assert_quads(&d, &quads);
    assert_arrays(&d, &arrays);

    let g2 = jittered_grid2();
    let a: Vec<f64> = (0..g2.num_cells()).map(|c| c as f64 / 7.0).collect();
    let p = dir.path("grid2.vtk");
    write_vtk_structured2(&p, &g2, &[("skew", &a)]).unwrap();
    let d = check(&p, g2.num_nodes(), g2.num_cells(), "quad", &["skew"], true);
    assert_quads(&d, &g2);
    assert_arrays(&d, &[("skew", &a)]);

    let g3 = jittered_grid3();
    let v: Vec<f64> = (0..g3.num_cells()).map(|c| 1.0 + c as f64 * 0.1).collect();
    let p = dir.path("grid3.vtk");
    write_vtk_structured3(&p, &g3, &[("volume", &v)]).unwrap();
    let d = check(
        &p,
        g3.num_nodes(),
        g3.num_cells(),
        "hexahedron",
        &["volume"],
        false,
    );
    assert_hexes(&d, &g3);
    assert_arrays(&d, &[("volume", &v)]);

    let h = HexMesh::from_grid(&g3);
    let p = dir.path("hexes.vtk");
    let arrays: [(&str, &[f64]); 2] = [("volume", &v), ("jacobian", &a)];
    write_vtk_hexes(&p, &h, &arrays).unwrap();
    let d = check(
        &p,
        h.num_nodes(),
        v.len(),
        "hexahedron",
        &["volume", "jacobian"],
        false,
    );
    assert_hexes(&d, &h);
    assert_arrays(&d, &arrays);

    let h2 = two_hexes();
    let p = dir.path("two_hexes.vtk");
    write_vtk_hexes(&p, &h2, &[("id", &[0.0, 1.0])]).unwrap();
    let d = check(&p, 12, 2, "hexahedron", &["id"], false);
    assert_hexes(&d, &h2);
}

/// The checker itself must fail on a mismatch (otherwise the test above proves nothing).
#[test]
fn meshio_check_detects_mismatch() {
    if !meshio_available() {
        println!("skipped: meshio not installed (pip install meshio to run this check)");
        return;
    }
    let dir = Scratch::new("meshio-neg");
    let p = dir.path("q.vtk");
    write_vtk_quads(&p, &l_shaped_quads(), &[("quality", &[1.0, 2.0, 3.0])]).unwrap();
    let script = scripts_dir().join("check_vtk_meshio.py");
    for extra in [
        vec!["--points", "9", "--cells", "3", "--cell-type", "quad"],
        vec!["--points", "8", "--cells", "4", "--cell-type", "quad"],
        vec!["--points", "8", "--cells", "3", "--cell-type", "hexahedron"],
        vec![
            "--points",
            "8",
            "--cells",
            "3",
            "--cell-type",
            "quad",
            "--cell-array",
            "nope",
        ],
    ] {
        let out = Command::new("python3")
            .arg(&script)
            .arg(&p)
            .args(&extra)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(1),
            "{extra:?}: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(String::from_utf8_lossy(&out.stderr).contains("mismatch"));
    }
}

/// Has meshio write `input` (one of our files) again as VTK legacy ASCII in `format`
/// (`"vtk"` = 5.1 with OFFSETS/CONNECTIVITY and FIELD data, `"vtk42"` = classic CELLS).
fn meshio_rewrite(input: &Path, output: &Path, format: &str) {
    let code = "import sys, meshio\n\
                m = meshio.read(sys.argv[1])\n\
                m.write(sys.argv[2], file_format=sys.argv[3], binary=False)\n";
    let out = Command::new("python3")
        .args(["-c", code])
        .arg(input)
        .arg(output)
        .arg(format)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "meshio rewrite failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Our reader on files written by meshio (an independent writer, both the VTK 5.1 and the
/// 4.2 layouts): the mesh and cell arrays must come back bit for bit.
#[test]
fn we_read_what_meshio_writes() {
    if !meshio_available() {
        println!("skipped: meshio not installed (pip install meshio to run this check)");
        return;
    }
    let dir = Scratch::new("meshio-rev");
    let quads = l_shaped_quads();
    let q = [0.1, 1.0 / 3.0, -2.5e-7];
    let src = dir.path("quads.vtk");
    write_vtk_quads(&src, &quads, &[("quality", &q)]).unwrap();
    let h = HexMesh::from_grid(&jittered_grid3());
    let v: Vec<f64> = (0..h.num_hexes()).map(|c| (c as f64).sqrt()).collect();
    let src_h = dir.path("hexes.vtk");
    write_vtk_hexes(&src_h, &h, &[("volume", &v)]).unwrap();

    for format in ["vtk", "vtk42"] {
        let out = dir.path(&format!("quads-{format}.vtk"));
        meshio_rewrite(&src, &out, format);
        let f = read_vtk(&out).unwrap_or_else(|e| panic!("{format}: {e}"));
        assert!(f.title.contains("meshio"), "{}", f.title);
        let VtkMesh::Quads(back) = &f.mesh else {
            panic!("{format}: expected quads, got {:?}", f.mesh)
        };
        assert_eq!(back, &quads, "{format}");
        let got: Vec<u64> = f
            .cell_array("quality")
            .unwrap()
            .iter()
            .map(|x| x.to_bits())
            .collect();
        let want: Vec<u64> = q.iter().map(|x| x.to_bits()).collect();
        assert_eq!(got, want, "{format}");

        let out = dir.path(&format!("hexes-{format}.vtk"));
        meshio_rewrite(&src_h, &out, format);
        let f = read_vtk(&out).unwrap_or_else(|e| panic!("{format}: {e}"));
        let VtkMesh::Hexes(back) = &f.mesh else {
            panic!("{format}: expected hexes, got {:?}", f.mesh)
        };
        assert_eq!(back, &h, "{format}");
        let got: Vec<u64> = f
            .cell_array("volume")
            .unwrap()
            .iter()
            .map(|x| x.to_bits())
            .collect();
        let want: Vec<u64> = v.iter().map(|x| x.to_bits()).collect();
        assert_eq!(got, want, "{format}");
    }
}
