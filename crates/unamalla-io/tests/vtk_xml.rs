//! VTK XML (`.vts`, `.vtu`, `.vtm`): bit-exact round trips, `write_block_mesh`, hand-written
//! files with known values, typed errors, no panic on truncation, and independent checks with
//! meshio (`.vtu`, `scripts/check_vtk_meshio.py`) and VTK's own readers (`.vts`, `.vtu`,
//! `.vtm`, `scripts/check_vtk_xml_vtk.py`); each check is skipped with a message when its
//! Python package is missing.

mod common;

use std::path::Path;
use std::process::Command;

use common::*;
use unamalla_io::*;
use unamalla_mesh::{
    BlockMesh2, DVec2, DVec3, HasHexCells, HasNodes, HasQuadCells, HexMesh, StructuredGrid2,
};

fn bits2(v: &[DVec2]) -> Vec<[u64; 2]> {
    v.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect()
}
fn bits3(v: &[DVec3]) -> Vec<[u64; 3]> {
    v.iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}
fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn two_blocks() -> BlockMesh2 {
    let grid = |x0: f64, m: usize| {
        StructuredGrid2::from_fn(m, 3, |i, j| {
            let x = x0 + i as f64 * 0.5;
            DVec2::new(x, j as f64 * 0.25 * (1.0 + 0.1 * x))
        })
        .unwrap()
    };
    // [0, 1.5] and [1.5, 2.5] share the side x = 1.5 (3 nodes).
    BlockMesh2::merge(vec![grid(0.0, 4), grid(1.5, 3)], 1e-9).unwrap()
}

#[test]
fn vts2_round_trip_bitwise_and_layout() {
    let dir = Scratch::new("vts2");
    let g = jittered_grid2();
    let q: Vec<f64> = (0..g.num_cells()).map(|c| 1.0 / (c as f64 + 3.0)).collect();
    let p = dir.path("g.vts");
    write_vts2(&p, &g, &[("quality", &q)]).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains("<StructuredGrid WholeExtent=\"0 3 0 2 0 0\">"));
    assert!(text.contains("<Piece Extent=\"0 3 0 2 0 0\">"));
    assert!(text.contains("NumberOfComponents=\"3\""));
    let f = read_vtk_xml(&p).unwrap();
    let VtkMesh::Structured2(back) = &f.mesh else {
        panic!("{:?}", f.mesh)
    };
    assert_eq!((back.m(), back.n()), (4, 3));
    assert_eq!(bits2(back.nodes()), bits2(g.nodes()));
    assert_eq!(bits(f.cell_array("quality").unwrap()), bits(&q));
    assert_eq!(dir.entries(), vec!["g.vts".to_string()]);
}

#[test]
fn vts3_and_vtu_round_trip_bitwise() {
    let dir = Scratch::new("vts3");
    let g = jittered_grid3();
    let v: Vec<f64> = (0..g.num_cells())
        .map(|c| (c as f64).sqrt() - 1e-9)
        .collect();
    let p = dir.path("g.vts");
    write_vts3(&p, &g, &[("volume", &v)]).unwrap();
    let f = read_vtk_xml(&p).unwrap();
    let VtkMesh::Structured3(back) = &f.mesh else {
        panic!()
    };
    assert_eq!(back.dims(), (3, 4, 2));
    assert_eq!(bits3(back.nodes()), bits3(g.nodes()));
    assert_eq!(bits(f.cell_array("volume").unwrap()), bits(&v));

    let h = HexMesh::from_grid(&g);
    let p = dir.path("h.vtu");
    write_vtu_hexes(&p, &h, &[("volume", &v)]).unwrap();
    let f = read_vtk_xml(&p).unwrap();
    assert_eq!(f.mesh, VtkMesh::Hexes(h.clone()));
    assert_eq!(bits(f.cell_array("volume").unwrap()), bits(&v));

    let quads = l_shaped_quads();
    let p = dir.path("q.vtu");
    let a = [0.5, -0.0, 1e-300];
    write_vtu_quads(&p, &quads, &[("a<&>\"b", &a)]).unwrap();
    let f = read_vtk_xml(&p).unwrap();
    assert_eq!(f.mesh, VtkMesh::Quads(quads));
    assert_eq!(f.cell_data[0].0, "a<&>\"b");
    assert_eq!(bits(&f.cell_data[0].1), bits(&a));
}

#[test]
fn block_mesh_files() {
    let dir = Scratch::new("blocks");
    let bm = two_blocks();
    let q0: Vec<f64> = (0..6).map(|c| c as f64).collect();
    let q1: Vec<f64> = (0..4).map(|c| 10.0 + c as f64).collect();
    let qg: Vec<f64> = (0..10).map(|c| c as f64 * 0.1).collect();
    let blk: Vec<f64> = (0..10).map(|c| if c < 6 { 0.0 } else { 1.0 }).collect();
    let files = write_block_mesh(
        &dir.0,
        &bm,
        &[&[("quality", &q0)], &[("quality", &q1)]],
        &[("quality", &qg), ("block", &blk)],
    )
    .unwrap();
    assert_eq!(
        dir.entries(),
        vec!["block-0.vts", "block-1.vts", "blocks.vtm", "mesh.vtu"]
    );
    assert_eq!(files.blocks.len(), 2);
    // The index references the block files relatively and in order.
    let vtm = std::fs::read_to_string(&files.index).unwrap();
    assert!(vtm.contains("file=\"block-0.vts\"") && vtm.contains("file=\"block-1.vts\""));
    let entries = read_vtm(&files.index).unwrap();
    assert_eq!(
        entries.iter().map(|e| e.file.clone()).collect::<Vec<_>>(),
        files.blocks
    );
    assert_eq!(entries[1].name, "block-1");
    for (k, e) in entries.iter().enumerate() {
        let f = read_vtk_xml(&e.file).unwrap();
        let VtkMesh::Structured2(b) = &f.mesh else {
            panic!()
        };
        assert_eq!(b, &bm.blocks()[k]);
        let want = if k == 0 { &q0 } else { &q1 };
        assert_eq!(f.cell_array("quality").unwrap(), want.as_slice());
    }
    let f = read_vtk_xml(&files.global).unwrap();
    let VtkMesh::Quads(g) = &f.mesh else { panic!() };
    assert_eq!(g, bm.global());
    assert_eq!(g.num_nodes(), 12 + 9 - 3);
    assert_eq!(f.cell_array("block").unwrap(), blk.as_slice());

    // Wrong number of per-block lists, or a bad array: nothing is written.
    let d2 = Scratch::new("blocks-bad");
    let e = write_block_mesh(&d2.0, &bm, &[&[("quality", &q0)]], &[]).unwrap_err();
    assert!(matches!(e, IoError::Unrepresentable { .. }), "{e}");
    let e = write_block_mesh(&d2.0, &bm, &[&[], &[("quality", &q0)]], &[]).unwrap_err();
    assert!(matches!(e, IoError::CellDataLength { .. }), "{e}");
    assert!(d2.entries().is_empty());
    // No arrays at all is fine.
    write_block_mesh(&d2.0, &bm, &[], &[]).unwrap();
    assert_eq!(d2.entries().len(), 4);
}

/// A `.vtu` written by hand (two quads, point data, a multi-component array that is skipped,
/// a comment, and integers spread over lines).
const HAND_VTU: &str = r#"<?xml version="1.0"?>
<!-- two unit squares side by side -->
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="6" NumberOfCells="2">
      <PointData>
        <DataArray type="Float32" Name="height" format="ascii">0 1 2 3 4 5</DataArray>
      </PointData>
      <CellData>
        <DataArray type="Float64" Name="vec" NumberOfComponents="2" format="ascii">1 2 3 4</DataArray>
        <DataArray type="Float64" Name="q" format="ascii">
          0.25 1e-3
        </DataArray>
      </CellData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">
          0 0 0  1 0 0  2 0 0
          0 1 0  1 1 0  2 1 0
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 4 3
          1 2 5 4</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">4 8</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">9 9</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;

#[test]
fn hand_written_vtu_and_vts() {
    let f = parse_vtk_xml(HAND_VTU).unwrap();
    let VtkMesh::Quads(q) = &f.mesh else { panic!() };
    assert_eq!(q.cells(), &[[0, 1, 4, 3], [1, 2, 5, 4]]);
    assert_eq!(q.nodes()[5], DVec2::new(2.0, 1.0));
    assert_eq!(f.cell_data.len(), 1);
    assert_eq!(f.cell_array("q"), Some(&[0.25, 1e-3][..]));
    assert_eq!(f.point_array("height").unwrap().len(), 6);

    let vts = "<VTKFile type=\"StructuredGrid\"><StructuredGrid WholeExtent=\"0 1 0 1 0 1\">\n\
               <Piece Extent=\"0 1 0 1 0 1\"><Points><DataArray NumberOfComponents=\"3\">\n\
               0 0 0 1 0 0 0 1 0 1 1 0\n0 0 1 1 0 1 0 1 1 1 1 1\n\
               </DataArray></Points></Piece></StructuredGrid></VTKFile>";
    let f = parse_vtk_xml(vts).unwrap();
    let VtkMesh::Structured3(g) = &f.mesh else {
        panic!()
    };
    assert_eq!(g.dims(), (2, 2, 2));
    assert_eq!(g.node(1, 0, 1), DVec3::new(1.0, 0.0, 1.0));
    assert_eq!(g.hex(0), [0, 1, 3, 2, 4, 5, 7, 6]);
}

#[test]
fn reader_errors_are_typed_with_line_numbers() {
    let line_of = |t: &str| parse_vtk_xml(t).unwrap_err().line();
    // Bad number on line 18 (second row of points).
    assert_eq!(
        line_of(&HAND_VTU.replacen("0 1 0  1 1 0", "0 1 0  x 1 0", 1)),
        Some(18)
    );
    // Count mismatch, reported at the DataArray.
    let e = parse_vtk_xml(&HAND_VTU.replacen("0.25 1e-3", "0.25", 1)).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::CountMismatch {
                line: 11,
                expected: 2,
                found: 1,
                ..
            }
        ),
        "{e}"
    );
    // Unsupported cell type.
    let e = parse_vtk_xml(&HAND_VTU.replacen(">9 9<", ">9 5<", 1)).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::UnsupportedCellType {
                cell: 1,
                cell_type: 5,
                ..
            }
        ),
        "{e}"
    );
    // Non-planar quads.
    let e = parse_vtk_xml(&HAND_VTU.replacen("2 1 0\n", "2 1 7\n", 1)).unwrap_err();
    assert!(matches!(e, IoError::NotPlanar { node: 5, .. }), "{e}");
    // ASCII numbers declared binary are an error, not misread; appended arrays are unsupported.
    let e = parse_vtk_xml(&HAND_VTU.replacen(
        "Name=\"offsets\" format=\"ascii\"",
        "Name=\"offsets\" format=\"binary\"",
        1,
    ))
    .unwrap_err();
    assert!(matches!(e, IoError::Malformed { .. }), "{e}");
    assert!(e.to_string().contains("not base64"), "{e}");
    let e = parse_vtk_xml(&HAND_VTU.replacen(
        "Name=\"offsets\" format=\"ascii\"",
        "Name=\"offsets\" format=\"appended\"",
        1,
    ))
    .unwrap_err();
    assert!(matches!(e, IoError::Unsupported { line: 24, .. }), "{e}");
    // Mismatched tags.
    let e = parse_vtk_xml(&HAND_VTU.replacen("</Cells>", "</Cell>", 1)).unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 26, .. }), "{e}");
    // Node index out of range.
    let e = parse_vtk_xml(&HAND_VTU.replacen("1 2 5 4", "1 2 6 4", 1)).unwrap_err();
    assert!(matches!(e, IoError::Mesh { .. }), "{e}");
    // Bad offsets.
    let e = parse_vtk_xml(&HAND_VTU.replacen(">4 8<", ">4 9<", 1)).unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 24, .. }), "{e}");
    // Other data set types.
    let e = parse_vtk_xml("<VTKFile type=\"PolyData\"/>").unwrap_err();
    assert!(matches!(e, IoError::Unsupported { line: 1, .. }), "{e}");
    let e = parse_vtk_xml("\n<Foo/>").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 2, .. }), "{e}");
}

#[test]
fn no_panic_on_any_truncation() {
    let dir = Scratch::new("vtx-trunc");
    let p = dir.path("g.vts");
    write_vts3(&p, &jittered_grid3(), &[]).unwrap();
    let vts = std::fs::read_to_string(&p).unwrap();
    for t in [HAND_VTU, vts.as_str()] {
        for k in 0..t.len() {
            if t.is_char_boundary(k) {
                assert!(parse_vtk_xml(&t[..k]).is_err() || k + 2 > t.trim_end().len());
            }
        }
    }
}

#[test]
fn failed_write_keeps_the_previous_file() {
    let dir = Scratch::new("vtx-atomic");
    let p = dir.path("q.vtu");
    std::fs::write(&p, "previous").unwrap();
    let e = write_vtu_quads(&p, &l_shaped_quads(), &[("q", &[1.0])]).unwrap_err();
    assert!(matches!(e, IoError::CellDataLength { .. }));
    let e = write_vts2(&p, &jittered_grid2(), &[("bad name", &[0.0; 6])]).unwrap_err();
    assert!(matches!(e, IoError::InvalidArrayName { .. }));
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "previous");
    assert_eq!(dir.entries(), vec!["q.vtu".to_string()]);
}

// --- Independent readers --------------------------------------------------------------------

fn python_has(module: &str) -> bool {
    Command::new("python3")
        .args(["-c", &format!("import {module}")])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

fn run_script(script: &str, file: &Path, args: &[String]) -> serde_json::Value {
    let dump = file.with_extension("dump.json");
    let out = Command::new("python3")
        .arg(scripts_dir().join(script))
        .arg(file)
        .args(args)
        .arg("--dump")
        .arg(&dump)
        .output()
        .expect("run python3");
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "{script} failed for {}:\n{stdout}\n{}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(&dump).unwrap()).unwrap()
}

fn dumped_points(d: &serde_json::Value) -> Vec<[u64; 3]> {
    d["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let v: Vec<u64> = p
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_str().unwrap().parse::<f64>().unwrap().to_bits())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

fn dumped_array(d: &serde_json::Value, name: &str) -> Vec<u64> {
    d["cell_data"][name]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().parse::<f64>().unwrap().to_bits())
        .collect()
}

fn lift(v: &[DVec2]) -> Vec<DVec3> {
    v.iter().map(|p| p.extend(0.0)).collect()
}

fn a(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn meshio_reads_our_vtu() {
    if !python_has("meshio") {
        println!("skipped: meshio not installed (pip install meshio to run this check)");
        return;
    }
    let dir = Scratch::new("vtx-meshio");
    let bm = two_blocks();
    let q: Vec<f64> = (0..10).map(|c| 1.0 / (c as f64 + 1.0)).collect();
    let files = write_block_mesh(&dir.0, &bm, &[], &[("quality", &q)]).unwrap();
    let d = run_script(
        "check_vtk_meshio.py",
        &files.global,
        &a(&[
            "--points",
            "18",
            "--cells",
            "10",
            "--cell-type",
            "quad",
            "--cell-array",
            "quality",
            "--planar",
        ]),
    );
    assert_eq!(dumped_points(&d), bits3(&lift(bm.nodes())));
    assert_eq!(dumped_array(&d, "quality"), bits(&q));
    let cells: Vec<Vec<usize>> = d["cells"][0]["data"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_u64().unwrap() as usize)
                .collect()
        })
        .collect();
    for (c, cell) in cells.iter().enumerate() {
        assert_eq!(cell.as_slice(), bm.quad(c).as_slice());
    }

    let h = HexMesh::from_grid(&jittered_grid3());
    let p = dir.path("h.vtu");
    let v: Vec<f64> = (0..h.num_hexes()).map(|c| c as f64 + 0.5).collect();
    write_vtu_hexes(&p, &h, &[("volume", &v)]).unwrap();
    let d = run_script(
        "check_vtk_meshio.py",
        &p,
        &a(&[
            "--points",
            "24",
            "--cells",
            "6",
            "--cell-type",
            "hexahedron",
            "--cell-array",
            "volume",
        ]),
    );
    assert_eq!(dumped_points(&d), bits3(h.nodes()));
    assert_eq!(dumped_array(&d, "volume"), bits(&v));
}

#[test]
fn vtk_reads_our_vts_vtu_and_vtm() {
    if !python_has("vtkmodules.vtkIOXML") {
        println!(
            "skipped: the vtk Python package is not installed (pip install vtk to run this check)"
        );
        return;
    }
    let dir = Scratch::new("vtx-vtk");
    let bm = two_blocks();
    let q0: Vec<f64> = (0..6).map(|c| c as f64 / 3.0).collect();
    let q1: Vec<f64> = (0..4).map(|c| -(c as f64) * 1e-7).collect();
    let qg: Vec<f64> = (0..10).map(|c| c as f64 * 0.1).collect();
    let files = write_block_mesh(
        &dir.0,
        &bm,
        &[&[("quality", &q0)], &[("quality", &q1)]],
        &[("quality", &qg)],
    )
    .unwrap();
    let d = run_script(
        "check_vtk_xml_vtk.py",
        &files.blocks[0],
        &a(&[
            "--points",
            "12",
            "--cells",
            "6",
            "--cell-type",
            "quad",
            "--dims",
            "4",
            "3",
            "1",
            "--cell-array",
            "quality",
            "--planar",
        ]),
    );
    assert_eq!(dumped_points(&d), bits3(&lift(bm.blocks()[0].nodes())));
    assert_eq!(dumped_array(&d, "quality"), bits(&q0));
    let d = run_script(
        "check_vtk_xml_vtk.py",
        &files.index,
        &a(&[
            "--blocks",
            "2",
            "--points",
            "21",
            "--cells",
            "10",
            "--cell-type",
            "quad",
            "--cell-array",
            "quality",
        ]),
    );
    let mut want = lift(bm.blocks()[0].nodes());
    want.extend(lift(bm.blocks()[1].nodes()));
    assert_eq!(dumped_points(&d), bits3(&want));
    assert_eq!(
        dumped_array(&d, "quality"),
        bits(&[q0.clone(), q1.clone()].concat())
    );
    let d = run_script(
        "check_vtk_xml_vtk.py",
        &files.global,
        &a(&[
            "--points",
            "18",
            "--cells",
            "10",
            "--cell-type",
            "quad",
            "--cell-array",
            "quality",
            "--planar",
        ]),
    );
    assert_eq!(dumped_points(&d), bits3(&lift(bm.nodes())));

    let g = jittered_grid3();
    let p = dir.path("g3.vts");
    let v: Vec<f64> = (0..g.num_cells()).map(|c| c as f64).collect();
    write_vts3(&p, &g, &[("volume", &v)]).unwrap();
    let d = run_script(
        "check_vtk_xml_vtk.py",
        &p,
        &a(&[
            "--points",
            "24",
            "--cells",
            "6",
            "--cell-type",
            "hexahedron",
            "--dims",
            "3",
            "4",
            "2",
            "--cell-array",
            "volume",
        ]),
    );
    assert_eq!(dumped_points(&d), bits3(g.nodes()));
    let p = dir.path("h.vtu");
    write_vtu_hexes(&p, &HexMesh::from_grid(&g), &[]).unwrap();
    run_script(
        "check_vtk_xml_vtk.py",
        &p,
        &a(&[
            "--points",
            "24",
            "--cells",
            "6",
            "--cell-type",
            "hexahedron",
        ]),
    );
}

/// The VTK checker must fail on wrong expectations.
#[test]
fn vtk_check_detects_mismatch() {
    if !python_has("vtkmodules.vtkIOXML") {
        println!(
            "skipped: the vtk Python package is not installed (pip install vtk to run this check)"
        );
        return;
    }
    let dir = Scratch::new("vtx-vtk-neg");
    let p = dir.path("g.vts");
    write_vts2(&p, &jittered_grid2(), &[]).unwrap();
    for extra in [
        a(&["--points", "13", "--cells", "6", "--cell-type", "quad"]),
        a(&[
            "--points",
            "12",
            "--cells",
            "6",
            "--cell-type",
            "hexahedron",
        ]),
        a(&[
            "--points",
            "12",
            "--cells",
            "6",
            "--cell-type",
            "quad",
            "--dims",
            "3",
            "4",
            "1",
        ]),
        a(&[
            "--points",
            "12",
            "--cells",
            "6",
            "--cell-type",
            "quad",
            "--cell-array",
            "nope",
        ]),
    ] {
        let out = Command::new("python3")
            .arg(scripts_dir().join("check_vtk_xml_vtk.py"))
            .arg(&p)
            .args(&extra)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{extra:?}");
    }
    // A corrupt file is reported by VTK itself.
    std::fs::write(&p, "<VTKFile type=\"StructuredGrid\"><StructuredGrid").unwrap();
    let out = Command::new("python3")
        .arg(scripts_dir().join("check_vtk_xml_vtk.py"))
        .arg(&p)
        .args(a(&[
            "--points",
            "12",
            "--cells",
            "6",
            "--cell-type",
            "quad",
        ]))
        .output()
        .unwrap();
    assert_ne!(out.status.code(), Some(0));
}

/// Our reader on a `.vtu` written by meshio (an independent writer; ASCII with 11 significant
/// digits, so values are compared to 1e-10).
#[test]
fn we_read_what_meshio_writes() {
    if !python_has("meshio") {
        println!("skipped: meshio not installed (pip install meshio to run this check)");
        return;
    }
    let dir = Scratch::new("vtx-meshio-rev");
    let bm = two_blocks();
    let q: Vec<f64> = (0..10).map(|c| 0.5 + c as f64).collect();
    let files = write_block_mesh(&dir.0, &bm, &[], &[("quality", &q)]).unwrap();
    let out = dir.path("meshio.vtu");
    let code = "import sys, meshio\n\
                meshio.read(sys.argv[1]).write(sys.argv[2], binary=False)\n";
    let o = Command::new("python3")
        .args(["-c", code])
        .arg(&files.global)
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = read_vtk_xml(&out).unwrap_or_else(|e| panic!("{e}"));
    let VtkMesh::Quads(m) = &f.mesh else { panic!() };
    assert_eq!(m.cells(), bm.global().cells());
    for (a, b) in m.nodes().iter().zip(bm.nodes()) {
        assert!(a.distance(*b) < 1e-10);
    }
    let got = f.cell_array("quality").unwrap();
    for (a, b) in got.iter().zip(&q) {
        assert!((a - b).abs() < 1e-10);
    }
}
