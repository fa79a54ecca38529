//! Solver formats: SU2 native meshes and OpenFOAM `polyMesh` directories, boundary patches by
//! name.
//!
//! # SU2 (`.su2`)
//!
//! The native ASCII format of SU2 ("Mesh File", SU2 documentation): `NDIME= 2`, `NELEM=` with
//! one line per quad (`9 n₀ n₁ n₂ n₃ id`, VTK type 9, 0-based node ids, counter-clockwise),
//! `NPOIN=` with `x y id`, `NMARK=` and per marker `MARKER_TAG= <name>`, `MARKER_ELEMS=` and
//! its boundary edges as lines (`3 a b`, VTK type 3). Markers are the [`EdgeGroup`]s in order.
//!
//! # OpenFOAM (`constant/polyMesh`)
//!
//! OpenFOAM meshes are 3D: the 2D mesh is **extruded one cell thick** (`z = 0` and
//! `z = thickness`), the usual way to run a 2D case. Points: the `N` mesh nodes at `z = 0`, then
//! the same at `z = thickness` (node `v` → points `v` and `N + v`). Cells: the quads in order.
//! Faces (OpenFOAM user guide §5.1, "Mesh description"):
//!
//! * **internal faces** — one per interior edge, owner = the lower cell index, neighbour = the
//!   higher, sorted by (owner, neighbour) (upper-triangular order), each face `[a, b, N+b, N+a]`
//!   with `(a, b)` the edge as it runs counter-clockwise in its owner, so by the right-hand rule
//!   the normal points out of the owner;
//! * **boundary faces**, patch by patch in the order of the groups (type `patch`; a group
//!   whose name contains `wall` or `coast` is type `wall`), the same face form;
//! * the patch `frontAndBack` of type `empty` (the front faces `[q₀, q₃, q₂, q₁]` at `z = 0`,
//!   normal `−z`, and the back faces `[N+q₀, …, N+q₃]`, normal `+z`), which makes OpenFOAM
//!   solve in 2D.
//!
//! [`write_openfoam`] writes `points`, `faces`, `owner`, `neighbour` and `boundary` (ASCII,
//! `FoamFile` headers with the `note` OpenFOAM's `checkMesh` prints: nPoints, nCells, nFaces,
//! nInternalFaces), each atomically, and minimal `system/{controlDict,fvSchemes,fvSolution}` so the
//! directory is a case `checkMesh -case <dir>` accepts.

use std::collections::HashMap;
use std::path::Path;

use unamalla_mesh::HasQuadCells;

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::msh::EdgeGroup;

fn check_groups<M: HasQuadCells + ?Sized>(
    path: &Path,
    mesh: &M,
    groups: &[EdgeGroup],
) -> Result<(), IoError> {
    let nn = mesh.num_nodes();
    let mut seen: Vec<&str> = Vec::new();
    for g in groups {
        crate::patches::check_patch_name(&g.name).map_err(|e| IoError::InvalidGroup {
            path: path.to_path_buf(),
            name: g.name.clone(),
            reason: e.to_string(),
        })?;
        if seen.contains(&g.name.as_str()) {
            return Err(IoError::InvalidGroup {
                path: path.to_path_buf(),
                name: g.name.clone(),
                reason: "another group has the same name".into(),
            });
        }
        seen.push(&g.name);
        if let Some(&[a, b]) = g.edges.iter().find(|e| e[0] >= nn || e[1] >= nn) {
            return Err(IoError::InvalidGroup {
                path: path.to_path_buf(),
                name: g.name.clone(),
                reason: format!("edge ({a}, {b}) uses a node ≥ {nn}, the mesh's node count"),
            });
        }
    }
    Ok(())
}

/// The SU2 text of a quad mesh with markers `groups` (see the module docs).
pub fn su2_text<M: HasQuadCells + ?Sized>(mesh: &M, groups: &[EdgeGroup]) -> String {
    let mut s = String::new();
    let nc = mesh.num_quads();
    s.push_str(&format!("NDIME= 2\nNELEM= {nc}\n"));
    for c in 0..nc {
        let q = mesh.quad(c);
        s.push_str(&format!("9 {} {} {} {} {c}\n", q[0], q[1], q[2], q[3]));
    }
    let nodes = mesh.nodes();
    s.push_str(&format!("NPOIN= {}\n", nodes.len()));
    for (k, p) in nodes.iter().enumerate() {
        s.push_str(&format!("{:?} {:?} {k}\n", p.x, p.y));
    }
    s.push_str(&format!("NMARK= {}\n", groups.len()));
    for g in groups {
        s.push_str(&format!(
            "MARKER_TAG= {}\nMARKER_ELEMS= {}\n",
            g.name,
            g.edges.len()
        ));
        for &[a, b] in &g.edges {
            s.push_str(&format!("3 {a} {b}\n"));
        }
    }
    s
}

/// Writes [`su2_text`] atomically; group names must be usable marker tags
/// ([`crate::patches::check_patch_name`]).
pub fn write_su2<M: HasQuadCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    groups: &[EdgeGroup],
) -> Result<(), IoError> {
    let path = path.as_ref();
    check_groups(path, mesh, groups)?;
    let text = su2_text(mesh, groups);
    atomic_write(path, |w| w.write_all(text.as_bytes()))
}

/// The faces of the extruded mesh (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct FoamMesh {
    /// Points: the nodes at `z = 0`, then at `z = thickness`.
    pub points: Vec<[f64; 3]>,
    /// Faces as point ids: internal faces, then each patch's faces.
    pub faces: Vec<Vec<usize>>,
    /// Owner cell of every face.
    pub owner: Vec<usize>,
    /// Neighbour cell of every internal face.
    pub neighbour: Vec<usize>,
    /// Patches: name, type, number of faces, first face.
    pub patches: Vec<(String, &'static str, usize, usize)>,
    /// Number of cells.
    pub cells: usize,
}

/// Builds the extruded mesh of a quad mesh; boundary edges not in any group go to a patch
/// `boundary` (there are none when the groups come from [`crate::patches::named_edge_groups`]
/// or [`crate::boundary_edge_groups`]).
pub fn foam_mesh<M: HasQuadCells + ?Sized>(
    mesh: &M,
    groups: &[EdgeGroup],
    thickness: f64,
) -> FoamMesh {
    let nodes = mesh.nodes();
    let n = nodes.len();
    let mut points: Vec<[f64; 3]> = nodes.iter().map(|p| [p.x, p.y, 0.0]).collect();
    points.extend(nodes.iter().map(|p| [p.x, p.y, thickness]));
    let nc = mesh.num_quads();
    // edge -> (cell, a, b as in that cell) for the first cell seen, neighbour when seen again
    let mut first: HashMap<(usize, usize), (usize, usize, usize)> = HashMap::with_capacity(2 * nc);
    let mut internal: Vec<(usize, usize, usize, usize)> = Vec::new();
    for c in 0..nc {
        let q = mesh.quad(c);
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            let key = (a.min(b), a.max(b));
            match first.remove(&key) {
                Some((o, oa, ob)) => internal.push((o, c, oa, ob)),
                None => {
                    first.insert(key, (c, a, b));
                }
            }
        }
    }
    internal.sort_unstable_by_key(|&(o, nb, _, _)| (o, nb));
    let side = |a: usize, b: usize| vec![a, b, n + b, n + a];
    let mut faces = Vec::new();
    let mut owner = Vec::new();
    let mut neighbour = Vec::new();
    for &(o, nb, a, b) in &internal {
        faces.push(side(a, b));
        owner.push(o);
        neighbour.push(nb);
    }
    let mut patches = Vec::new();
    for g in groups {
        let start = faces.len();
        for &[a, b] in &g.edges {
            if let Some((c, ca, cb)) = first.remove(&(a.min(b), a.max(b))) {
                faces.push(side(ca, cb));
                owner.push(c);
            }
        }
        let lower = g.name.to_ascii_lowercase();
        let ty = if lower.contains("wall") || lower.contains("coast") {
            "wall"
        } else {
            "patch"
        };
        patches.push((g.name.clone(), ty, faces.len() - start, start));
    }
    if !first.is_empty() {
        let start = faces.len();
        let mut rest: Vec<(usize, usize, usize)> = first.into_values().collect();
        rest.sort_unstable();
        for (c, a, b) in rest {
            faces.push(side(a, b));
            owner.push(c);
        }
        patches.push(("boundary".into(), "patch", faces.len() - start, start));
    }
    let start = faces.len();
    for c in 0..nc {
        let q = mesh.quad(c);
        faces.push(vec![q[0], q[3], q[2], q[1]]);
        owner.push(c);
    }
    for c in 0..nc {
        let q = mesh.quad(c);
        faces.push(q.iter().map(|&v| n + v).collect());
        owner.push(c);
    }
    patches.push(("frontAndBack".into(), "empty", 2 * nc, start));
    FoamMesh {
        points,
        faces,
        owner,
        neighbour,
        patches,
        cells: nc,
    }
}

fn foam_header(class: &str, object: &str, note: &str) -> String {
    format!(
        "FoamFile\n{{\n    version     2.0;\n    format      ascii;\n    class       {class};\n    note        \"{note}\";\n    location    \"constant/polyMesh\";\n    object      {object};\n}}\n\n"
    )
}

/// Writes the extruded mesh ([`foam_mesh`], `thickness` > 0) as an OpenFOAM case directory
/// `case`: `constant/polyMesh/{points,faces,owner,neighbour,boundary}` and
/// `system/{controlDict,fvSchemes,fvSolution}`.
pub fn write_openfoam<M: HasQuadCells + ?Sized>(
    case: impl AsRef<Path>,
    mesh: &M,
    groups: &[EdgeGroup],
    thickness: f64,
) -> Result<FoamMesh, IoError> {
    let case = case.as_ref();
    let poly = case.join("constant").join("polyMesh");
    check_groups(&poly, mesh, groups)?;
    if !(thickness.is_finite() && thickness > 0.0) {
        return Err(IoError::InvalidGroup {
            path: poly,
            name: "frontAndBack".into(),
            reason: format!("the extrusion thickness must be positive, got {thickness}"),
        });
    }
    let fm = foam_mesh(mesh, groups, thickness);
    let mk = |p: &Path| {
        std::fs::create_dir_all(p).map_err(|source| IoError::Io {
            path: p.to_path_buf(),
            source,
        })
    };
    mk(&poly)?;
    mk(&case.join("system"))?;
    let note = format!(
        "nPoints:{}  nCells:{}  nFaces:{}  nInternalFaces:{}",
        fm.points.len(),
        fm.cells,
        fm.faces.len(),
        fm.neighbour.len()
    );
    let list = |items: Vec<String>| format!("{}\n(\n{}\n)\n", items.len(), items.join("\n"));
    let points = fm
        .points
        .iter()
        .map(|p| format!("({:?} {:?} {:?})", p[0], p[1], p[2]))
        .collect();
    let faces = fm
        .faces
        .iter()
        .map(|f| {
            let ids: Vec<String> = f.iter().map(usize::to_string).collect();
            format!("{}({})", f.len(), ids.join(" "))
        })
        .collect();
    let labels = |v: &[usize]| v.iter().map(usize::to_string).collect::<Vec<_>>();
    let mut boundary = String::new();
    for (name, ty, nf, start) in &fm.patches {
        boundary.push_str(&format!(
            "    {name}\n    {{\n        type            {ty};\n        nFaces          {nf};\n        startFace       {start};\n    }}\n"
        ));
    }
    let files = [
        (
            "points",
            foam_header("vectorField", "points", &note) + &list(points),
        ),
        (
            "faces",
            foam_header("faceList", "faces", &note) + &list(faces),
        ),
        (
            "owner",
            foam_header("labelList", "owner", &note) + &list(labels(&fm.owner)),
        ),
        (
            "neighbour",
            foam_header("labelList", "neighbour", &note) + &list(labels(&fm.neighbour)),
        ),
        (
            "boundary",
            foam_header("polyBoundaryMesh", "boundary", &note)
                + &format!("{}\n(\n{boundary})\n", fm.patches.len()),
        ),
    ];
    for (name, text) in &files {
        atomic_write(&poly.join(name), |w| w.write_all(text.as_bytes()))?;
    }
    let control = "FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       dictionary;\n    location    \"system\";\n    object      controlDict;\n}\n\napplication     foamRun;\nstartFrom       startTime;\nstartTime       0;\nstopAt          endTime;\nendTime         1;\ndeltaT          1;\nwriteControl    timeStep;\nwriteInterval   1;\n";
    let dict = |object: &str, body: &str| {
        format!("FoamFile\n{{\n    version     2.0;\n    format      ascii;\n    class       dictionary;\n    location    \"system\";\n    object      {object};\n}}\n\n{body}")
    };
    let schemes = dict(
        "fvSchemes",
        "ddtSchemes { default Euler; }\ngradSchemes { default Gauss linear; }\ndivSchemes { default none; }\nlaplacianSchemes { default Gauss linear corrected; }\ninterpolationSchemes { default linear; }\nsnGradSchemes { default corrected; }\n",
    );
    let solution = dict("fvSolution", "solvers {}\n");
    for (name, text) in [
        ("controlDict", control.to_string()),
        ("fvSchemes", schemes),
        ("fvSolution", solution),
    ] {
        atomic_write(&case.join("system").join(name), |w| {
            w.write_all(text.as_bytes())
        })?;
    }
    Ok(fm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msh::boundary_edge_groups;
    use unamalla_mesh::{DVec2, HasNodes, QuadMesh, StructuredGrid2};

    fn grid(m: usize, n: usize) -> QuadMesh {
        QuadMesh::from_grid(
            &StructuredGrid2::from_fn(m, n, |i, j| DVec2::new(i as f64, j as f64)).unwrap(),
        )
    }

    #[test]
    fn su2_lists_cells_points_and_markers() {
        let mesh = grid(3, 2); // 2 cells, 6 nodes, 6 boundary edges
        let groups = boundary_edge_groups(&mesh);
        let t = su2_text(&mesh, &groups);
        assert!(t.starts_with("NDIME= 2\nNELEM= 2\n9 0 1 4 3 0\n9 1 2 5 4 1\nNPOIN= 6\n"));
        assert!(t.contains("NMARK= 1\nMARKER_TAG= outer\nMARKER_ELEMS= 6\n"));
        assert_eq!(t.lines().filter(|l| l.starts_with("3 ")).count(), 6);
    }

    #[test]
    fn foam_faces_are_upper_triangular_and_point_out_of_their_owner() {
        // 3×2 cells: interior edges = 2·3·2 − 3 − 2 = 7; boundary edges 10; 6 cells
        let mesh = grid(4, 3);
        let groups = boundary_edge_groups(&mesh);
        let fm = foam_mesh(&mesh, &groups, 0.5);
        assert_eq!(fm.neighbour.len(), 7);
        assert_eq!(fm.faces.len(), 7 + 10 + 12);
        assert_eq!(fm.patches[0], ("outer".into(), "patch", 10, 7));
        assert_eq!(fm.patches[1], ("frontAndBack".into(), "empty", 12, 17));
        for w in fm.owner[..7].windows(2).zip(fm.neighbour.windows(2)) {
            assert!((w.0[0], w.1[0]) < (w.0[1], w.1[1]), "not upper-triangular");
        }
        // face normal (Newell) · (face centre − owner centre) > 0 for every face
        let centre = |ids: &[usize]| {
            let mut c = [0.0; 3];
            for &v in ids {
                for (ck, pk) in c.iter_mut().zip(fm.points[v]) {
                    *ck += pk / ids.len() as f64;
                }
            }
            c
        };
        for (f, face) in fm.faces.iter().enumerate() {
            let mut nrm = [0.0; 3];
            for k in 0..face.len() {
                let (p, q) = (fm.points[face[k]], fm.points[face[(k + 1) % face.len()]]);
                nrm[0] += (p[1] - q[1]) * (p[2] + q[2]);
                nrm[1] += (p[2] - q[2]) * (p[0] + q[0]);
                nrm[2] += (p[0] - q[0]) * (p[1] + q[1]);
            }
            let q = mesh.quad(fm.owner[f]);
            let mut cell: Vec<usize> = q.to_vec();
            cell.extend(q.iter().map(|&v| v + mesh.num_nodes()));
            let (fc, cc) = (centre(face), centre(&cell));
            let d: f64 = (0..3).map(|k| nrm[k] * (fc[k] - cc[k])).sum();
            assert!(d > 0.0, "face {f} points into its owner");
        }
    }
}
