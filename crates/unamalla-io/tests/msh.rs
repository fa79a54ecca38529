//! Gmsh MSH 4.1: round trips with groups, boundary loops, a hand-written file with known
//! values, typed errors, no panic on truncation, writer validation, and the independent check
//! with Gmsh's own Python API (`scripts/check_msh_gmsh.py`; skipped when `gmsh` is missing).

mod common;

use std::process::Command;

use common::*;
use unamalla_io::*;
use unamalla_mesh::{DVec2, DVec3, HasNodes, HasQuadCells, HexMesh, QuadMesh};

fn bits2(v: &[DVec2]) -> Vec<[u64; 2]> {
    v.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect()
}
fn bits3(v: &[DVec3]) -> Vec<[u64; 3]> {
    v.iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

/// A 5 × 5-node square grid with the middle 1 × 1 cell block removed… 4 × 4 cells, the cell
/// (1..2, 1..2) region removed: 15 cells around a square hole of area 1 (unit cells).
///
/// Node (i, j) is at (i, j), id j * 5 + i; every cell is counter-clockwise.
fn mesh_with_hole() -> QuadMesh {
    let nodes: Vec<DVec2> = (0..25)
        .map(|k| DVec2::new((k % 5) as f64, (k / 5) as f64))
        .collect();
    let mut cells = Vec::new();
    for j in 0..4 {
        for i in 0..4 {
            if (i, j) == (1, 1) {
                continue;
            }
            let a = j * 5 + i;
            cells.push([a, a + 1, a + 6, a + 5]);
        }
    }
    QuadMesh::new(nodes, cells).unwrap()
}

#[test]
fn boundary_loops_of_a_mesh_with_a_hole() {
    let m = mesh_with_hole();
    let loops = boundary_loops(&m);
    assert_eq!(loops.len(), 2);
    // Outer: the 4 × 4 square, 16 edges, counter-clockwise.
    assert_eq!(loops[0].edges.len(), 16);
    assert_eq!(loops[0].signed_area, 16.0);
    // Hole: the unit square (1,1)-(2,2), 4 edges, clockwise.
    assert_eq!(loops[1].edges.len(), 4);
    assert_eq!(loops[1].signed_area, -1.0);
    for l in &loops {
        for k in 0..l.edges.len() {
            assert_eq!(l.edges[k][1], l.edges[(k + 1) % l.edges.len()][0]);
        }
    }
    let mut hole_nodes: Vec<usize> = loops[1].edges.iter().map(|e| e[0]).collect();
    hole_nodes.sort();
    assert_eq!(hole_nodes, vec![6, 7, 11, 12]);
    let groups = boundary_edge_groups(&m);
    let names: Vec<&str> = groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["outer", "hole-1"]);
}

#[test]
fn hex_boundary_faces_point_out() {
    let g = jittered_grid3(); // 3 × 4 × 2 nodes: 2 × 3 × 1 cells
    let faces = hex_boundary_faces(&g);
    assert_eq!(faces.len(), 2 * (2 * 3 + 2 + 3));
    let centre = g.nodes().iter().copied().sum::<DVec3>() / g.num_nodes() as f64;
    for f in &faces {
        let p: Vec<DVec3> = f.iter().map(|&v| g.nodes()[v]).collect();
        let normal = (p[2] - p[0]).cross(p[3] - p[1]);
        let mid = (p[0] + p[1] + p[2] + p[3]) / 4.0;
        assert!(normal.dot(mid - centre) > 0.0, "face {f:?} points in");
    }
}

#[test]
fn quads_round_trip_with_groups() {
    let dir = Scratch::new("msh2");
    let g = jittered_grid2();
    let mut groups = boundary_edge_groups(&g);
    groups.push(EdgeGroup {
        name: "cut-1".into(),
        edges: vec![
            [g.index(1, 0), g.index(1, 1)],
            [g.index(1, 1), g.index(1, 2)],
        ],
    });
    let p = dir.path("g.msh");
    write_msh_quads(&p, &g, "domain", &groups).unwrap();
    assert_eq!(dir.entries(), vec!["g.msh".to_string()]);
    let f = read_msh(&p).unwrap();
    let MshMesh::Quads(q) = &f.mesh else {
        panic!("expected quads")
    };
    assert_eq!(bits2(q.nodes()), bits2(g.nodes()));
    assert_eq!(q.num_quads(), g.num_quads());
    for c in 0..g.num_quads() {
        assert_eq!(q.quad(c), g.quad(c));
    }
    assert_eq!(f.domain.as_deref(), Some("domain"));
    assert_eq!(f.edge_groups, groups);
    assert!(f.face_groups.is_empty());
    assert_eq!(f.edge_group("outer").unwrap().edges.len(), 2 * (3 + 2));
}

#[test]
fn hexes_round_trip_with_groups() {
    let dir = Scratch::new("msh3");
    let h = HexMesh::from_grid(&jittered_grid3());
    let faces = hex_boundary_faces(&h);
    let (bottom, rest): (Vec<[usize; 4]>, Vec<[usize; 4]>) = faces
        .iter()
        .partition(|f| f.iter().all(|&v| h.nodes()[v].z.abs() < 1.0));
    let groups = vec![
        FaceGroup {
            name: "bottom".into(),
            faces: bottom,
        },
        FaceGroup {
            name: "walls and top".into(),
            faces: rest,
        },
    ];
    assert_eq!(groups[0].faces.len(), 6);
    let p = dir.path("h.msh");
    write_msh_hexes(&p, &h, "solid", &groups).unwrap();
    let f = read_msh(&p).unwrap();
    let MshMesh::Hexes(back) = &f.mesh else {
        panic!("expected hexes")
    };
    assert_eq!(bits3(back.nodes()), bits3(h.nodes()));
    assert_eq!(back.cells(), h.cells());
    assert_eq!(f.domain.as_deref(), Some("solid"));
    assert_eq!(f.face_groups, groups);
    assert!(f.edge_groups.is_empty());
}

/// A file written by hand after the Gmsh manual, with two node blocks (one parametric), tags
/// that are not 1..N, a `$Comments` section, a point element (ignored) and an unnamed
/// physical group.
const HAND: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$Comments
anything at all $Foo
$EndComments
$PhysicalNames
2
1 7 "bottom side"
2 9 "fluid"
$EndPhysicalNames
$Entities
1 2 1 0
1 0 0 0 0
1 0 0 0 2 0 0 1 7 0
2 0 1 0 2 1 0 1 5 0
1 0 0 0 2 1 0 1 9 0
$EndEntities
$Nodes
2 6 10 60
1 1 1 3
10
20
30
0 0 0 0
1 0 0 0.5
2 0 0 1
2 1 0 3
40
50
60
0 1 0
1 1 0
2 1 0
$EndNodes
$Elements
4 6 1 100
2 1 3 2
1 10 20 50 40
2 20 30 60 50
1 1 1 2
3 10 20
4 20 30
1 2 1 1
5 40 50
0 1 15 1
100 10
$EndElements
"#;

#[test]
fn hand_written_file() {
    let f = parse_msh(HAND).unwrap();
    let MshMesh::Quads(q) = &f.mesh else {
        panic!("expected quads")
    };
    let want: Vec<DVec2> = [(0., 0.), (1., 0.), (2., 0.), (0., 1.), (1., 1.), (2., 1.)]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect();
    assert_eq!(q.nodes(), want.as_slice());
    assert_eq!(q.cells(), &[[0, 1, 4, 3], [1, 2, 5, 4]]);
    assert_eq!(f.domain.as_deref(), Some("fluid"));
    assert_eq!(f.edge_groups.len(), 2);
    assert_eq!(f.edge_groups[0].name, "physical-5");
    assert_eq!(f.edge_groups[0].edges, vec![[3, 4]]);
    assert_eq!(f.edge_groups[1].name, "bottom side");
    assert_eq!(f.edge_groups[1].edges, vec![[0, 1], [1, 2]]);
}

/// What the writer emits, byte for byte, for a one-quad mesh with one group.
#[test]
fn writer_output_is_the_documented_layout() {
    let dir = Scratch::new("msh-layout");
    let m = QuadMesh::new(
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 0.5),
            DVec2::new(0.0, 0.5),
        ],
        vec![[0, 1, 2, 3]],
    )
    .unwrap();
    let p = dir.path("one.msh");
    let groups = [EdgeGroup {
        name: "inflow".into(),
        edges: vec![[3, 0]],
    }];
    write_msh_quads(&p, &m, "domain", &groups).unwrap();
    let want = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
$PhysicalNames\n2\n2 1 \"domain\"\n1 2 \"inflow\"\n$EndPhysicalNames\n\
$Entities\n0 1 1 0\n\
1 0.0 0.0 0.0 0.0 0.5 0.0 1 2 0\n\
1 0.0 0.0 0.0 1.0 0.5 0.0 1 1 0\n$EndEntities\n\
$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0.0 0.0 0.0\n1.0 0.0 0.0\n1.0 0.5 0.0\n0.0 0.5 0.0\n$EndNodes\n\
$Elements\n2 2 1 2\n2 1 3 1\n1 1 2 3 4\n1 1 1 1\n2 4 1\n$EndElements\n";
    assert_eq!(std::fs::read_to_string(&p).unwrap(), want);
}

fn err(text: &str) -> IoError {
    match parse_msh(text) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

#[test]
fn reader_errors_are_typed_with_line_numbers() {
    let e = err("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    assert!(matches!(e, IoError::Unsupported { line: 2, .. }), "{e}");
    let e = err("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n");
    assert!(matches!(e, IoError::Unsupported { line: 2, .. }), "{e}");
    let e = err("$Nodes\n");
    assert!(matches!(e, IoError::Malformed { line: 1, .. }), "{e}");
    // Bad coordinate on line 26.
    let bad = HAND.replacen("1 0 0 0.5", "1 x 0 0.5", 1);
    let e = err(&bad);
    assert_eq!(e.line(), Some(26), "{e}");
    // Unknown node tag in an element.
    let bad = HAND.replacen("1 10 20 50 40", "1 10 20 55 40", 1);
    let e = err(&bad);
    assert!(matches!(e, IoError::Malformed { line: 39, .. }), "{e}");
    // Element count mismatch.
    let bad = HAND.replacen("4 6 1 100", "4 7 1 100", 1);
    assert!(matches!(err(&bad), IoError::CountMismatch { .. }));
    // Triangles are not supported.
    let bad = HAND.replacen(
        "2 1 3 2\n1 10 20 50 40\n2 20 30 60 50",
        "2 1 2 2\n1 10 20 50\n2 20 30 60",
        1,
    );
    assert!(matches!(err(&bad), IoError::Unsupported { .. }));
    // Non-planar quads.
    let bad = HAND.replacen("0 1 0\n", "0 1 0.25\n", 1);
    assert!(matches!(err(&bad), IoError::NotPlanar { node: 3, .. }));
    // Duplicate node tag.
    let bad = HAND.replacen("40\n50", "40\n10", 1);
    assert!(
        matches!(err(&bad), IoError::Malformed { line: 30, .. }),
        "{}",
        err(&bad)
    );
    // Bad physical name line.
    let bad = HAND.replacen("1 7 \"bottom side\"", "1 7 bottom", 1);
    assert!(matches!(err(&bad), IoError::Malformed { line: 9, .. }));
}

#[test]
fn no_panic_on_any_truncation() {
    let dir = Scratch::new("msh-trunc");
    let p = dir.path("h.msh");
    let h = HexMesh::from_grid(&jittered_grid3());
    let groups = [FaceGroup {
        name: "all".into(),
        faces: hex_boundary_faces(&h),
    }];
    write_msh_hexes(&p, &h, "domain", &groups).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    for t in [text.as_str(), HAND] {
        for k in 0..t.len() {
            if t.is_char_boundary(k) {
                let _ = parse_msh(&t[..k]);
            }
        }
        assert!(parse_msh(t).is_ok());
    }
    // Truncated at a section boundary: a typed "truncated" error.
    let cut = &HAND[..HAND.find("$Elements").unwrap()];
    assert!(matches!(parse_msh(cut), Err(IoError::Truncated { .. })));
}

#[test]
fn writer_validates_groups_before_touching_the_disk() {
    let dir = Scratch::new("msh-bad");
    let g = jittered_grid2();
    let p = dir.path("x.msh");
    let cases = [
        ("", vec![[0, 1]]),
        ("a\"b", vec![[0, 1]]),
        ("domain", vec![[0, 1]]),
        ("ok", vec![[0, 12]]),
    ];
    for (name, edges) in cases {
        let e = write_msh_quads(
            &p,
            &g,
            "domain",
            &[EdgeGroup {
                name: name.into(),
                edges,
            }],
        )
        .unwrap_err();
        assert!(matches!(e, IoError::InvalidGroup { .. }), "{e}");
    }
    let two = [
        EdgeGroup {
            name: "a".into(),
            edges: vec![],
        },
        EdgeGroup {
            name: "a".into(),
            edges: vec![],
        },
    ];
    assert!(write_msh_quads(&p, &g, "domain", &two).is_err());
    assert!(dir.entries().is_empty());
}

// --- Independent check with Gmsh --------------------------------------------------------------

fn gmsh_available() -> bool {
    Command::new("python3")
        .args(["-c", "import gmsh"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

fn gmsh_check(file: &std::path::Path, args: &[String]) -> (bool, String, String) {
    let out = Command::new("python3")
        .arg(scripts_dir().join("check_msh_gmsh.py"))
        .arg(file)
        .args(args)
        .output()
        .expect("run python3");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn s(v: &[&str]) -> Vec<String> {
    v.iter().map(|x| x.to_string()).collect()
}

#[test]
fn gmsh_reads_what_we_write() {
    if !gmsh_available() {
        println!("skipped: the gmsh Python package is not installed (pip install gmsh to run this check)");
        return;
    }
    let dir = Scratch::new("gmsh");

    // 2D: a convex mesh around a hole, with outer, hole and a cut group.
    let m = mesh_with_hole();
    let mut groups = boundary_edge_groups(&m);
    groups.push(EdgeGroup {
        name: "cut-1".into(),
        edges: vec![[5, 6]],
    });
    let p = dir.path("hole.msh");
    write_msh_quads(&p, &m, "domain", &groups).unwrap();
    let (ok, out, errs) = gmsh_check(
        &p,
        &s(&[
            "--nodes",
            "25",
            "--elements",
            "quad=15",
            "--elements",
            "line=21",
            "--group",
            "2:domain=15",
            "--group",
            "1:outer=16",
            "--group",
            "1:hole-1=4",
            "--group",
            "1:cut-1=1",
            "--min-sicn-positive",
            "2",
        ]),
    );
    println!("{out}");
    assert!(ok, "gmsh check failed:\n{out}\n{errs}");
    assert!(out.contains("\"ok\": true"));

    // 2D jittered structured grid.
    let g = jittered_grid2();
    let p = dir.path("grid.msh");
    write_msh_quads(&p, &g, "domain", &boundary_edge_groups(&g)).unwrap();
    let (ok, out, errs) = gmsh_check(
        &p,
        &s(&[
            "--nodes",
            "12",
            "--elements",
            "quad=6",
            "--elements",
            "line=10",
            "--group",
            "2:domain=6",
            "--group",
            "1:outer=10",
            "--min-sicn-positive",
            "2",
        ]),
    );
    assert!(ok, "gmsh check failed:\n{out}\n{errs}");

    // 3D hexes with one face group.
    let h = HexMesh::from_grid(&jittered_grid3());
    let faces = hex_boundary_faces(&h);
    let nf = faces.len();
    let p = dir.path("hex.msh");
    write_msh_hexes(
        &p,
        &h,
        "domain",
        &[FaceGroup {
            name: "boundary".into(),
            faces,
        }],
    )
    .unwrap();
    let (ok, out, errs) = gmsh_check(
        &p,
        &[
            s(&["--nodes", "24", "--elements", "hexahedron=6"]),
            vec!["--elements".into(), format!("quad={nf}")],
            s(&["--group", "3:domain=6"]),
            vec!["--group".into(), format!("2:boundary={nf}")],
            s(&["--min-sicn-positive", "3"]),
        ]
        .concat(),
    );
    println!("{out}");
    assert!(ok, "gmsh check failed:\n{out}\n{errs}");
}

/// The checker must fail on wrong expectations and on a non-convex element.
#[test]
fn gmsh_check_detects_mismatch_and_non_convex_cells() {
    if !gmsh_available() {
        println!("skipped: the gmsh Python package is not installed (pip install gmsh to run this check)");
        return;
    }
    let dir = Scratch::new("gmsh-neg");
    let m = mesh_with_hole();
    let p = dir.path("m.msh");
    write_msh_quads(&p, &m, "domain", &boundary_edge_groups(&m)).unwrap();
    let base = [
        "--nodes",
        "25",
        "--elements",
        "quad=15",
        "--elements",
        "line=20",
        "--group",
        "2:domain=15",
        "--group",
        "1:outer=16",
        "--group",
        "1:hole-1=4",
    ];
    assert!(gmsh_check(&p, &s(&base)).0);
    for (from, to) in [
        ("25", "26"),
        ("quad=15", "quad=14"),
        ("1:outer=16", "1:outer=15"),
    ] {
        let args: Vec<String> = base
            .iter()
            .map(|a| if *a == from { to } else { a }.to_string())
            .collect();
        let (ok, _, errs) = gmsh_check(&p, &args);
        assert!(!ok && errs.contains("mismatch"), "{from} -> {to}");
    }
    // A non-convex (dart-shaped) cell has minSICN < 0. (For planar quads Gmsh measures the
    // Jacobian against the element's own normal, so a merely clockwise cell still scores 1;
    // orientation is checked by our own tests, not by this one.)
    let mut nodes = m.nodes().to_vec();
    nodes[0] = DVec2::new(0.9, 0.9);
    let cells = m.cells().to_vec();
    let bad = QuadMesh::new(nodes, cells).unwrap();
    let p = dir.path("bad.msh");
    write_msh_quads(&p, &bad, "domain", &[]).unwrap();
    let (ok, out, errs) = gmsh_check(
        &p,
        &s(&[
            "--nodes",
            "25",
            "--elements",
            "quad=15",
            "--group",
            "2:domain=15",
            "--min-sicn-positive",
            "2",
        ]),
    );
    assert!(!ok && errs.contains("minSICN"), "{out}\n{errs}");
}

/// Our reader on files written by Gmsh itself (`gmsh.write` after opening our file, MSH 4.1
/// ASCII): counts, group names and sizes, and the geometry (cell areas, group lengths) agree.
#[test]
fn we_read_what_gmsh_writes() {
    if !gmsh_available() {
        println!("skipped: the gmsh Python package is not installed (pip install gmsh to run this check)");
        return;
    }
    let dir = Scratch::new("gmsh-rev");
    let m = mesh_with_hole();
    let mut groups = boundary_edge_groups(&m);
    groups.push(EdgeGroup {
        name: "cut 1".into(),
        edges: vec![[5, 6]],
    });
    let src = dir.path("ours.msh");
    write_msh_quads(&src, &m, "domain", &groups).unwrap();
    let out = dir.path("gmsh.msh");
    let code = "import sys, gmsh\n\
                gmsh.initialize(['-noenv'], readConfigFiles=False)\n\
                gmsh.option.setNumber('General.Terminal', 0)\n\
                gmsh.open(sys.argv[1])\n\
                gmsh.option.setNumber('Mesh.MshFileVersion', 4.1)\n\
                gmsh.option.setNumber('Mesh.Binary', 0)\n\
                gmsh.write(sys.argv[2])\n\
                gmsh.finalize()\n";
    let o = Command::new("python3")
        .args(["-c", code])
        .arg(&src)
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = read_msh(&out).unwrap_or_else(|e| panic!("{e}"));
    let MshMesh::Quads(q) = &f.mesh else {
        panic!("expected quads")
    };
    assert_eq!(q.num_quads(), 15);
    let area: f64 = (0..q.num_quads())
        .map(|c| {
            let p = q.quad_points(c);
            0.5 * (0..4).map(|k| p[k].perp_dot(p[(k + 1) % 4])).sum::<f64>()
        })
        .sum();
    assert!((area - 15.0).abs() < 1e-12, "{area}");
    assert_eq!(f.domain.as_deref(), Some("domain"));
    let mut got: Vec<(String, usize, f64)> = f
        .edge_groups
        .iter()
        .map(|g| {
            let len = g
                .edges
                .iter()
                .map(|&[a, b]| q.nodes()[a].distance(q.nodes()[b]))
                .sum::<f64>();
            (g.name.clone(), g.edges.len(), len)
        })
        .collect();
    got.sort_by(|a, b| a.0.cmp(&b.0));
    let want = [("cut 1", 1, 1.0), ("hole-1", 4, 4.0), ("outer", 16, 16.0)];
    assert_eq!(got.len(), 3);
    for ((n, c, l), (wn, wc, wl)) in got.iter().zip(want) {
        assert_eq!((n.as_str(), *c), (wn, wc));
        assert!((l - wl).abs() < 1e-12);
    }
}
