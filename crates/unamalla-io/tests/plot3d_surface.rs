//! Plot3D (ASCII and Fortran-unformatted binary, 2D and 3D) and OFF/OBJ: round trips,
//! hand-made files with known layout, typed errors, no panic on truncation.

mod common;

use common::*;
use unamalla_io::*;
use unamalla_mesh::{DVec2, DVec3, HasNodes, HasQuadCells, HexMesh, StructuredGrid2};

fn bits2(v: &[DVec2]) -> Vec<[u64; 2]> {
    v.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect()
}
fn bits3(v: &[DVec3]) -> Vec<[u64; 3]> {
    v.iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

fn second_block() -> StructuredGrid2 {
    StructuredGrid2::from_fn(2, 5, |i, j| DVec2::new(10.0 + i as f64, j as f64 / 3.0)).unwrap()
}

#[test]
fn plot3d_round_trips_bitwise() {
    let dir = Scratch::new("p3d");
    let b2 = vec![jittered_grid2(), second_block()];
    let b3 = vec![jittered_grid3(), jittered_grid3()];
    for format in [Plot3dFormat::Ascii, Plot3dFormat::FortranBinary] {
        let p = dir.path("two.xyz");
        write_plot3d2(&p, &b2, format).unwrap();
        let Plot3dBlocks::D2(back) = read_plot3d(&p, Plot3dDim::D2, format).unwrap() else {
            panic!()
        };
        assert_eq!(back.len(), 2);
        for (a, b) in back.iter().zip(&b2) {
            assert_eq!((a.m(), a.n()), (b.m(), b.n()));
            assert_eq!(bits2(a.nodes()), bits2(b.nodes()));
        }
        let p = dir.path("three.xyz");
        write_plot3d3(&p, &b3, format).unwrap();
        let Plot3dBlocks::D3(back) = read_plot3d(&p, Plot3dDim::D3, format).unwrap() else {
            panic!()
        };
        for (a, b) in back.iter().zip(&b3) {
            assert_eq!(a.dims(), b.dims());
            assert_eq!(bits3(a.nodes()), bits3(b.nodes()));
        }
    }
    assert_eq!(dir.entries(), vec!["three.xyz", "two.xyz"]);
}

/// Builds a Fortran record by hand.
fn record(body: &[u8]) -> Vec<u8> {
    let n = (body.len() as u32).to_le_bytes();
    [&n[..], body, &n[..]].concat()
}

#[test]
fn plot3d_hand_made_files() {
    // ASCII, two 2D blocks: a 2 × 2 unit square and a 3 × 2 strip, x then y, i fastest.
    let text = "2\n2 2\n3 2\n0 1 0 1\n0 0 1 1\n1 2 3 1 2 3\n0 0 0 5 5 5\n";
    let Plot3dBlocks::D2(b) = parse_plot3d_ascii(text, Plot3dDim::D2).unwrap() else {
        panic!()
    };
    assert_eq!(b[0].node(1, 1), DVec2::new(1.0, 1.0));
    assert_eq!((b[1].m(), b[1].n()), (3, 2));
    assert_eq!(b[1].node(2, 1), DVec2::new(3.0, 5.0));
    // The same first block as a Fortran-unformatted file, bytes built independently.
    let mut bytes = record(&1i32.to_le_bytes());
    bytes.extend(record(&[2i32.to_le_bytes(), 2i32.to_le_bytes()].concat()));
    let coords: Vec<u8> = [0.0f64, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    bytes.extend(record(&coords));
    let Plot3dBlocks::D2(c) = parse_plot3d_binary(&bytes, Plot3dDim::D2).unwrap() else {
        panic!()
    };
    assert_eq!(c[0], b[0]);
    // What the writer produces is exactly that.
    let dir = Scratch::new("p3d-bytes");
    let p = dir.path("one.x");
    write_plot3d2(&p, &b[..1], Plot3dFormat::FortranBinary).unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), bytes);

    // Errors: wrong dimension, bad markers, truncation, trailing bytes — with byte offsets.
    let e = parse_plot3d_binary(&bytes, Plot3dDim::D3).unwrap_err();
    assert!(
        matches!(e, IoError::MalformedBinary { offset: 16, .. }),
        "{e}"
    );
    let mut bad = bytes.clone();
    let last = bad.len() - 1;
    bad[last] = 9;
    let e = parse_plot3d_binary(&bad, Plot3dDim::D2).unwrap_err();
    assert!(matches!(e, IoError::MalformedBinary { .. }), "{e}");
    let mut extra = bytes.clone();
    extra.push(0);
    let e = parse_plot3d_binary(&extra, Plot3dDim::D2).unwrap_err();
    assert!(
        matches!(e, IoError::MalformedBinary { offset, .. } if offset == bytes.len() as u64),
        "{e}"
    );
    for k in 0..bytes.len() {
        assert!(parse_plot3d_binary(&bytes[..k], Plot3dDim::D2).is_err());
    }
    // A huge announced block count cannot make the reader allocate.
    let mut huge = record(&i32::MAX.to_le_bytes());
    huge.extend(record(&[2i32.to_le_bytes(), 2i32.to_le_bytes()].concat()));
    assert!(parse_plot3d_binary(&huge, Plot3dDim::D2).is_err());

    let e = parse_plot3d_ascii("1\n2 1\n0 0\n", Plot3dDim::D2).unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 2, .. }), "{e}");
    let e = parse_plot3d_ascii("1\n2 2\n0 1 0 1\n0 0 1 y\n", Plot3dDim::D2).unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 4, .. }), "{e}");
    let e = parse_plot3d_ascii(text, Plot3dDim::D3).unwrap_err();
    assert!(e.line().is_some(), "{e}");
    for k in 0..text.len() {
        assert!(parse_plot3d_ascii(&text[..k], Plot3dDim::D2).is_err() || k + 1 >= text.len());
    }
}

#[test]
fn off_obj_round_trips() {
    let dir = Scratch::new("offobj");
    let q = l_shaped_quads();
    for (name, off) in [("q.off", true), ("q.obj", false)] {
        let p = dir.path(name);
        if off {
            write_off_quads(&p, &q).unwrap();
        } else {
            write_obj_quads(&p, &q).unwrap();
        }
        let s = if off { read_off(&p) } else { read_obj(&p) }.unwrap();
        let back = s.to_quad_mesh().unwrap();
        assert_eq!(bits2(back.nodes()), bits2(q.nodes()));
        assert_eq!(back.cells(), q.cells());
    }
    // Hex meshes: all nodes, the outward boundary faces.
    let h = HexMesh::from_grid(&jittered_grid3());
    let faces = hex_boundary_faces(&h);
    for (name, off) in [("h.off", true), ("h.obj", false)] {
        let p = dir.path(name);
        if off {
            write_off_hexes(&p, &h).unwrap();
        } else {
            write_obj_hexes(&p, &h).unwrap();
        }
        let s = if off { read_off(&p) } else { read_obj(&p) }.unwrap();
        assert_eq!(bits3(&s.nodes), bits3(h.nodes()));
        let f: Vec<[usize; 4]> = s.faces.iter().map(|f| [f[0], f[1], f[2], f[3]]).collect();
        assert_eq!(f, faces);
        assert!(s.to_quad_mesh().is_err(), "3D surface is not planar");
    }
    let text = std::fs::read_to_string(dir.path("q.off")).unwrap();
    assert!(text.starts_with("OFF\n8 3 0\n0.0 0.0 0.0\n"));
    assert!(text.ends_with("4 0 1 4 3\n4 1 2 5 4\n4 3 4 7 6\n"));
}

#[test]
fn off_obj_hand_written_and_errors() {
    let off = "OFF # a square\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n\n4 0 1 2 3 0.5 0.5 0.5\n";
    let s = parse_off(off).unwrap();
    assert_eq!(s.faces, vec![vec![0, 1, 2, 3]]);
    assert_eq!(s.to_quad_mesh().unwrap().num_quads(), 1);
    let obj =
        "mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0\nvt 0 0\ng sq\nf 1/1 2/1 -2 -1\n";
    let s2 = parse_obj(obj).unwrap();
    assert_eq!(s2, s);

    let e = parse_off("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 4\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 7, .. }), "{e}");
    let e = parse_off("OFF\n2 0 0\n0 0 0\n1 x 0\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 4, .. }), "{e}");
    assert!(matches!(
        parse_off("COFF\n"),
        Err(IoError::Unsupported { line: 1, .. })
    ));
    assert!(matches!(
        parse_off("OFF\n3 0 0\n0 0 0\n"),
        Err(IoError::Truncated { .. })
    ));
    let e = parse_obj("v 0 0 0\nf 1 2 3\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 2, .. }), "{e}");
    for k in 0..off.len() {
        let _ = parse_off(&off[..k]);
        let _ = parse_obj(&obj[..k.min(obj.len())]);
    }
}
