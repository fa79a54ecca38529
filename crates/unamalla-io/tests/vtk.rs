//! VTK legacy writer and reader: bit-exact round trips, a hand-written file with known values,
//! typed errors, atomicity of the writers, and no panic on any truncation of a valid file.

mod common;

use common::*;
use unamalla_io::*;
use unamalla_mesh::{DVec2, DVec3, HasHexCells, HasNodes, HasQuadCells, HexMesh, QuadMesh};

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

/// Values that stress shortest-round-trip formatting.
fn awkward_values(n: usize, seed: u64) -> Vec<f64> {
    let specials = [
        0.1,
        1.0 / 3.0,
        -0.0,
        1e-300,
        5e-324,
        1.7976931348623157e308,
        std::f64::consts::PI,
        -2.5e17,
        123_456_789.123_456_79,
    ];
    let mut r = Rng::new(seed);
    (0..n)
        .map(|k| specials.get(k).copied().unwrap_or_else(|| r.unit() * 1e3))
        .collect()
}

#[test]
fn quads_round_trip_bitwise() {
    let dir = Scratch::new("quads");
    let mesh = l_shaped_quads();
    let q = awkward_values(3, 1);
    let id = [0.0, 1.0, 2.0];
    let path = dir.path("l.vtk");
    write_vtk_quads(&path, &mesh, &[("quality", &q), ("id", &id)]).unwrap();
    assert_eq!(dir.entries(), vec!["l.vtk".to_string()]);

    let f = read_vtk(&path).unwrap();
    let VtkMesh::Quads(back) = &f.mesh else {
        panic!("expected quads, got {:?}", f.mesh)
    };
    assert_eq!(bits2(back.nodes()), bits2(mesh.nodes()));
    assert_eq!(back.cells(), mesh.cells());
    assert_eq!(f.cell_data.len(), 2);
    assert_eq!(f.cell_data[0].0, "quality");
    assert_eq!(bits(f.cell_array("quality").unwrap()), bits(&q));
    assert_eq!(bits(f.cell_array("id").unwrap()), bits(&id));
    assert!(f.point_data.is_empty());
}

#[test]
fn structured2_round_trip_bitwise_and_layout() {
    let dir = Scratch::new("s2");
    let g = jittered_grid2();
    let a = awkward_values(g.num_cells(), 2);
    let path = dir.path("g.vtk");
    write_vtk_structured2(&path, &g, &[("a", &a)]).unwrap();

    // The header is what the VTK legacy spec asks for.
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "# vtk DataFile Version 3.0");
    assert_eq!(lines[2], "ASCII");
    assert_eq!(lines[3], "DATASET STRUCTURED_GRID");
    assert_eq!(lines[4], "DIMENSIONS 4 3 1");
    assert_eq!(lines[5], "POINTS 12 double");
    assert!(text.contains("CELL_DATA 6\nSCALARS a double 1\nLOOKUP_TABLE default\n"));

    let f = read_vtk(&path).unwrap();
    let VtkMesh::Structured2(back) = &f.mesh else {
        panic!("expected a 2D grid, got {:?}", f.mesh)
    };
    assert_eq!((back.m(), back.n()), (4, 3));
    assert_eq!(bits2(back.nodes()), bits2(g.nodes()));
    assert_eq!(bits(f.cell_array("a").unwrap()), bits(&a));
}

#[test]
fn structured3_and_hexes_round_trip_bitwise() {
    let dir = Scratch::new("s3");
    let g = jittered_grid3();
    let a = awkward_values(g.num_cells(), 3);
    let p = dir.path("g3.vtk");
    write_vtk_structured3(&p, &g, &[("vol", &a)]).unwrap();
    let f = read_vtk(&p).unwrap();
    let VtkMesh::Structured3(back) = &f.mesh else {
        panic!("expected a 3D grid, got {:?}", f.mesh)
    };
    assert_eq!(back.dims(), (3, 4, 2));
    assert_eq!(bits3(back.nodes()), bits3(g.nodes()));
    assert_eq!(bits(f.cell_array("vol").unwrap()), bits(&a));

    // The same grid as an unstructured hex mesh.
    let h = HexMesh::from_grid(&g);
    let p = dir.path("h.vtk");
    write_vtk_hexes(&p, &h, &[("vol", &a)]).unwrap();
    let f = read_vtk(&p).unwrap();
    let VtkMesh::Hexes(back) = &f.mesh else {
        panic!("expected hexes, got {:?}", f.mesh)
    };
    assert_eq!(bits3(back.nodes()), bits3(h.nodes()));
    assert_eq!(back.cells(), h.cells());
    assert_eq!(back.fixed(), h.fixed());
    assert_eq!(bits(f.cell_array("vol").unwrap()), bits(&a));

    // A small explicit hex mesh without cell data: no CELL_DATA section at all.
    let h2 = two_hexes();
    let p = dir.path("two.vtk");
    write_vtk_hexes(&p, &h2, &[]).unwrap();
    assert!(!std::fs::read_to_string(&p).unwrap().contains("CELL_DATA"));
    let f = read_vtk(&p).unwrap();
    assert_eq!(f.mesh, VtkMesh::Hexes(h2));
    assert!(f.cell_data.is_empty());
}

#[test]
fn structured_grid_written_as_quads_keeps_grid_cells() {
    let dir = Scratch::new("gq");
    let g = jittered_grid2();
    let p = dir.path("gq.vtk");
    write_vtk_quads(&p, &g, &[]).unwrap();
    let f = read_vtk(&p).unwrap();
    let VtkMesh::Quads(q) = f.mesh else { panic!() };
    assert_eq!(q.num_quads(), g.num_quads());
    for c in 0..g.num_quads() {
        assert_eq!(q.quad(c), g.quad(c));
    }
}

/// A file written by hand (not by our writer), exercising free whitespace, a POINT_DATA
/// section, SCALARS without LOOKUP_TABLE, VECTORS to skip, a FIELD array and lower-case
/// keywords; values checked against what is written here.
#[test]
fn hand_written_unstructured_quads() {
    let text = "# vtk DataFile Version 2.0\n\
        hand made: two unit squares side by side\n\
        ASCII\n\
        \n\
        DATASET UNSTRUCTURED_GRID\n\
        POINTS 6 float\n\
        0 0 0   1 0 0   2 0 0\n\
        0 1 0\n1 1 0\n\
        2 1\n0\n\
        CELLS 2 10\n\
        4 0 1 4 3\n\
        4   1 2\n 5 4\n\
        CELL_TYPES 2\n9\n9\n\
        POINT_DATA 6\n\
        SCALARS height float\n\
        LOOKUP_TABLE default\n\
        0 1 2 3 4 5\n\
        VECTORS velocity double\n\
        1 0 0 1 0 0 1 0 0 1 0 0 1 0 0 1 0 0\n\
        cell_data 2\n\
        scalars quality double 1\n\
        lookup_table default\n\
        0.25 -1.5e-3\n\
        FIELD FieldData 2\n\
        block 1 2 int\n\
        7 8\n\
        vec 2 2 double\n\
        1 2 3 4\n";
    let f = parse_vtk(text).unwrap();
    assert_eq!(f.title, "hand made: two unit squares side by side");
    let VtkMesh::Quads(q) = &f.mesh else {
        panic!("expected quads, got {:?}", f.mesh)
    };
    assert_eq!(
        q.nodes(),
        &[
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, 1.0),
        ]
    );
    assert_eq!(q.cells(), &[[0, 1, 4, 3], [1, 2, 5, 4]]);
    assert_eq!(
        f.point_array("height").unwrap(),
        &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    );
    assert_eq!(f.point_data.len(), 1, "VECTORS are skipped");
    assert_eq!(f.cell_array("quality").unwrap(), &[0.25, -1.5e-3]);
    assert_eq!(f.cell_array("block").unwrap(), &[7.0, 8.0]);
    assert!(
        f.cell_array("vec").is_none(),
        "2-component FIELD array is skipped"
    );

    // The same file with Windows line endings reads the same.
    let crlf = parse_vtk(&text.replace('\n', "\r\n")).unwrap();
    assert_eq!(crlf, f);
}

#[test]
fn hand_written_structured_grid_and_vtk51_hexahedron() {
    // 3 × 2 × 1 grid: x varies fastest.
    let text = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_GRID\n\
        DIMENSIONS 3 2 1\nPOINTS 6 double\n\
        0 0 0 10 0 0 20 0 0 0 5 0 10 5 0 20 6 0\n\
        CELL_DATA 2\nSCALARS s double\nLOOKUP_TABLE default\n1.5 2.5\n";
    let f = parse_vtk(text).unwrap();
    let VtkMesh::Structured2(g) = &f.mesh else {
        panic!("expected a 2D grid")
    };
    assert_eq!((g.m(), g.n()), (3, 2));
    assert_eq!(g.node(2, 1), DVec2::new(20.0, 6.0));
    assert_eq!(g.node(1, 0), DVec2::new(10.0, 0.0));
    assert_eq!(f.cell_array("s").unwrap(), &[1.5, 2.5]);

    // VTK 5.1 OFFSETS/CONNECTIVITY form with METADATA blocks, as VTK 9 writes it.
    let text = "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET UNSTRUCTURED_GRID\n\
        POINTS 8 float\n0 0 0 1 0 0 1 1 0 0 1 0\n0 0 2 1 0 2 1 1 2 0 1 2\n\
        METADATA\nINFORMATION 0\n\n\
        CELLS 2 8\nOFFSETS vtktypeint64\n0 8\nCONNECTIVITY vtktypeint64\n0 1 2 3 4 5 6 7\n\
        CELL_TYPES 1\n12\n\
        CELL_DATA 1\nFIELD FieldData 1\nvolume 1 1 double\n2\nMETADATA\nINFORMATION 0\n\n";
    let f = parse_vtk(text).unwrap();
    let VtkMesh::Hexes(h) = &f.mesh else {
        panic!("expected hexes, got {:?}", f.mesh)
    };
    assert_eq!(h.cells(), &[[0, 1, 2, 3, 4, 5, 6, 7]]);
    assert_eq!(h.hex_points(0)[6], DVec3::new(1.0, 1.0, 2.0));
    assert_eq!(f.cell_array("volume").unwrap(), &[2.0]);
}

fn err(text: &str) -> IoError {
    match parse_vtk(text) {
        Ok(f) => panic!("expected an error, got {f:?}"),
        Err(e) => e,
    }
}

const QUAD_HEAD: &str = "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n\
    POINTS 4 double\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

#[test]
fn reader_errors_are_typed_with_line_numbers() {
    // Unsupported cell type (triangle = 5) on line 9.
    let e = err(&format!("{QUAD_HEAD}CELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n5\n"));
    assert!(
        matches!(
            e,
            IoError::UnsupportedCellType {
                line: 13,
                cell: 0,
                cell_type: 5,
                ..
            }
        ),
        "{e:?}"
    );
    // Mixed quad and hex types.
    let e = err(&format!(
        "{QUAD_HEAD}CELLS 2 10\n4 0 1 2 3\n4 0 1 2 3\nCELL_TYPES 2\n9 12\n"
    ));
    assert!(
        matches!(
            e,
            IoError::UnsupportedCellType {
                cell: 1,
                cell_type: 12,
                ..
            }
        ),
        "{e:?}"
    );
    // CELLS size disagrees with the records.
    let e = err(&format!(
        "{QUAD_HEAD}CELLS 1 6\n4 0 1 2 3\nCELL_TYPES 1\n9\n"
    ));
    assert!(
        matches!(
            e,
            IoError::CountMismatch {
                line: 10,
                expected: 6,
                found: 5,
                ..
            }
        ),
        "{e:?}"
    );
    // CELL_TYPES count disagrees with CELLS.
    let e = err(&format!(
        "{QUAD_HEAD}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n9 9\n"
    ));
    assert!(
        matches!(
            e,
            IoError::CountMismatch {
                line: 12,
                expected: 1,
                found: 2,
                ..
            }
        ),
        "{e:?}"
    );
    // A quad with 3 nodes.
    let e = err(&format!("{QUAD_HEAD}CELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n9\n"));
    assert!(
        matches!(
            e,
            IoError::CountMismatch {
                line: 11,
                expected: 4,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );
    // CELL_DATA count wrong.
    let e = err(&format!(
        "{QUAD_HEAD}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n9\nCELL_DATA 3\n"
    ));
    assert!(
        matches!(
            e,
            IoError::CountMismatch {
                line: 14,
                expected: 1,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );
    // Node id out of range.
    let e = err(&format!(
        "{QUAD_HEAD}CELLS 1 5\n4 0 1 2 9\nCELL_TYPES 1\n9\n"
    ));
    assert!(matches!(e, IoError::Mesh { .. }), "{e:?}");
    // Non-number in the points.
    let e = err("# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 zero 0\n");
    assert!(matches!(e, IoError::Malformed { line: 6, .. }), "{e:?}");
    // Truncated points.
    let e = err("# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3 double\n0 0 0\n1 1");
    assert!(matches!(e, IoError::Truncated { line: 7, .. }), "{e:?}");
    assert_eq!(e.line(), Some(7));
    // Quads off the plane z = 0.
    let e = err(
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n\
        POINTS 4 double\n0 0 0\n1 0 0\n1 1 0.5\n0 1 0\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n9\n",
    );
    assert!(
        matches!(
            e,
            IoError::NotPlanar {
                line: 8,
                node: 2,
                ..
            }
        ),
        "{e:?}"
    );
    // Binary files, other datasets, bad header.
    let e = err("# vtk DataFile Version 3.0\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\n");
    assert!(matches!(e, IoError::Unsupported { line: 3, .. }), "{e:?}");
    let e = err("# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n");
    assert!(matches!(e, IoError::Unsupported { line: 4, .. }), "{e:?}");
    let e = err("hello\n");
    assert!(matches!(e, IoError::Malformed { line: 1, .. }), "{e:?}");
    let e = err("");
    assert!(matches!(e, IoError::Truncated { .. }), "{e:?}");
    // Structured: DIMENSIONS and POINTS disagree.
    let e = err(
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 2 2 1\n\
        POINTS 3 double\n0 0 0 1 0 0 0 1 0\n",
    );
    assert!(
        matches!(
            e,
            IoError::CountMismatch {
                line: 6,
                expected: 4,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );
    // A count far larger than the data must fail cleanly (no huge allocation, no panic).
    let e = err("# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 18446744073709551615 double\n0 0 0\n");
    assert!(matches!(e, IoError::Truncated { .. }), "{e:?}");
    let e = err(&format!(
        "{QUAD_HEAD}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n9\nCELL_DATA 1\nSCALARS q double 4611686018427387904\n"
    ));
    assert!(matches!(e, IoError::Malformed { line: 15, .. }), "{e:?}");
    // nx = 1 with nz > 1 is not read as a 2D grid.
    let e = err(
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 1 2 2\n\
        POINTS 4 double\n0 0 0 0 1 0 0 0 1 0 1 1\n",
    );
    assert!(matches!(e, IoError::Unsupported { line: 5, .. }), "{e:?}");
    // Unexpected keyword.
    let e = err(&format!("{QUAD_HEAD}BOGUS 3\n"));
    assert!(matches!(e, IoError::Malformed { line: 10, .. }), "{e:?}");
}

#[test]
fn binary_file_is_reported_not_misread() {
    let dir = Scratch::new("bin");
    let p = dir.path("b.vtk");
    let mut bytes = b"# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_GRID\nDIMENSIONS 2 2 1\nPOINTS 4 double\n".to_vec();
    bytes.extend_from_slice(&[0xff, 0xfe, 0x00, 0x80]);
    std::fs::write(&p, bytes).unwrap();
    let e = read_vtk(&p).unwrap_err();
    assert!(matches!(e, IoError::Unsupported { line: 3, .. }), "{e:?}");
    let e = read_vtk(dir.path("missing.vtk")).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
}

/// Every prefix of valid files (cut at every character) is read without panicking. A prefix
/// that is accepted must hold the complete mesh (a cut between sections, e.g. before
/// `CELL_DATA`, is a valid file) and only complete arrays.
#[test]
fn no_panic_on_any_truncation() {
    let dir = Scratch::new("trunc");
    let m = l_shaped_quads();
    let q = [1.0, 2.0, 3.0];
    let p = dir.path("t.vtk");
    write_vtk_quads(&p, &m, &[("q", &q), ("r", &q)]).unwrap();
    let quads = std::fs::read_to_string(&p).unwrap();
    let p3 = dir.path("h.vtk");
    write_vtk_hexes(&p3, &two_hexes(), &[("v", &[1.0, 2.0])]).unwrap();
    let hexes = std::fs::read_to_string(&p3).unwrap();
    let p2 = dir.path("g.vtk");
    write_vtk_structured2(&p2, &jittered_grid2(), &[("v", &[1.0; 6])]).unwrap();
    let grid = std::fs::read_to_string(&p2).unwrap();
    for text in [quads, hexes, grid] {
        let full = parse_vtk(&text).unwrap();
        let mut accepted = 0;
        for cut in 0..text.len() {
            if let Ok(f) = parse_vtk(&text[..cut]) {
                accepted += 1;
                assert_eq!(f.mesh.num_cells(), full.mesh.num_cells());
                assert_eq!(f.mesh.num_nodes(), full.mesh.num_nodes());
                assert!(f.cell_data.len() <= full.cell_data.len());
                for (name, values) in &f.cell_data {
                    assert_eq!(values.len(), full.mesh.num_cells(), "array {name}");
                }
            }
        }
        // Only cuts near section ends and inside the very last numbers can be accepted.
        assert!(
            accepted < text.len() / 4,
            "{accepted} of {} prefixes accepted",
            text.len()
        );
    }
}

#[test]
fn writer_validates_cell_data_before_touching_the_disk() {
    let dir = Scratch::new("val");
    let m = l_shaped_quads();
    let p = dir.path("bad.vtk");
    let e = write_vtk_quads(&p, &m, &[("q", &[1.0, 2.0])]).unwrap_err();
    assert!(
        matches!(e, IoError::CellDataLength { expected: 3, found: 2, ref name, .. } if name == "q"),
        "{e:?}"
    );
    let e = write_vtk_quads(&p, &m, &[("my quality", &[1.0, 2.0, 3.0])]).unwrap_err();
    assert!(matches!(e, IoError::InvalidArrayName { .. }), "{e:?}");
    let e = write_vtk_quads(&p, &m, &[("", &[1.0, 2.0, 3.0])]).unwrap_err();
    assert!(matches!(e, IoError::InvalidArrayName { .. }), "{e:?}");
    let e =
        write_vtk_quads(&p, &m, &[("a", &[1.0, 2.0, 3.0]), ("a", &[1.0, 2.0, 3.0])]).unwrap_err();
    assert!(matches!(e, IoError::InvalidArrayName { .. }), "{e:?}");
    let e = write_vtk_quads(&p, &m, &[("a", &[1.0, f64::NAN, 3.0])]).unwrap_err();
    assert!(
        matches!(e, IoError::NonFiniteValue { cell: 1, .. }),
        "{e:?}"
    );
    let g = jittered_grid3();
    let e = write_vtk_structured3(&p, &g, &[("a", &[1.0])]).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::CellDataLength {
                expected: 6,
                found: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(
        dir.entries().is_empty(),
        "nothing may be written: {:?}",
        dir.entries()
    );
}

#[test]
fn failed_write_keeps_the_previous_file() {
    let dir = Scratch::new("keep");
    let p = dir.path("mesh.vtk");
    let m = l_shaped_quads();
    write_vtk_quads(&p, &m, &[]).unwrap();
    let before = std::fs::read(&p).unwrap();
    // Writing into a directory path that is a file fails at the OS level.
    let bad = p.join("child.vtk");
    let e = write_vtk_quads(&bad, &m, &[]).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
    assert_eq!(std::fs::read(&p).unwrap(), before);
    assert_eq!(dir.entries(), vec!["mesh.vtk".to_string()]);
    // An empty quad mesh is written and read back as an error (quad or hex cannot be told).
    let empty = QuadMesh::new(vec![DVec2::ZERO], vec![]).unwrap();
    let pe = dir.path("empty.vtk");
    write_vtk_quads(&pe, &empty, &[]).unwrap();
    assert!(matches!(
        read_vtk(&pe).unwrap_err(),
        IoError::Unsupported { .. }
    ));
}
