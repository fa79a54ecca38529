//! OFF and Wavefront OBJ polygon files, for a quick look at a mesh in any viewer (MeshLab,
//! Blender, Geomview, f3d, …).
//!
//! * Quad meshes are written as planar surfaces (`z = 0`), one quad face per cell, in cell order.
//! * Hex meshes are written as their **boundary surface** ([`crate::hex_boundary_faces`], faces
//!   oriented outwards); all nodes are written so node ids are kept.
//! * OFF: `OFF`, `nV nF 0`, `x y z` per vertex, `k i₀ … i_{k−1}` per face (0-based).
//!   OBJ: `v x y z` per vertex, `f a b c d` per face (1-based).
//!
//! The readers return a [`SurfaceMesh`] (vertices and polygonal faces).
//! [`SurfaceMesh::to_quad_mesh`] gives the quad mesh back when every face is a quad and
//! every `z` is 0. OFF: plain `OFF` only (`COFF`, `NOFF`, `4OFF`, … are unsupported), `#`
//! comments, face colours after the indices are ignored. OBJ: `v` (an optional `w` is ignored)
//! and `f` (with `v/vt/vn` forms and negative, relative indices) are used; `vt`, `vn`, `g`, `o`,
//! `s`, `l`, `usemtl`, `mtllib`, … are ignored. Errors carry line numbers; numbers are written
//! in shortest round-trip form so write → read is exact.

use std::path::Path;

use unamalla_mesh::{DVec2, DVec3, HasHexCells, HasQuadCells, MeshError, QuadMesh};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::{read_text, STRING_SOURCE};
use crate::lex::{parse_f64, MAX_PREALLOC};
use crate::msh::hex_boundary_faces;

/// A polygon surface read from an OFF or OBJ file.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceMesh {
    /// The vertices.
    pub nodes: Vec<DVec3>,
    /// The faces as 0-based vertex ids.
    pub faces: Vec<Vec<usize>>,
}

impl SurfaceMesh {
    /// The quad mesh, if every face has 4 vertices and every `z` is 0.
    pub fn to_quad_mesh(&self) -> Result<QuadMesh, MeshError> {
        if let Some(v) = self.nodes.iter().position(|p| p.z != 0.0) {
            return Err(MeshError::InvalidSize(format!(
                "vertex {v} has z = {}; a quad mesh is planar",
                self.nodes[v].z
            )));
        }
        let mut cells = Vec::with_capacity(self.faces.len());
        for (k, f) in self.faces.iter().enumerate() {
            let q: [usize; 4] = f.as_slice().try_into().map_err(|_| {
                MeshError::InvalidSize(format!("face {k} has {} vertices, not 4", f.len()))
            })?;
            cells.push(q);
        }
        QuadMesh::new(self.nodes.iter().map(|p| p.truncate()).collect(), cells)
    }
}

fn quads_of<M: HasQuadCells + ?Sized>(mesh: &M) -> (Vec<DVec3>, Vec<[usize; 4]>) {
    (
        mesh.nodes().iter().map(|p: &DVec2| p.extend(0.0)).collect(),
        (0..mesh.num_quads()).map(|c| mesh.quad(c)).collect(),
    )
}

fn hexes_of<M: HasHexCells + ?Sized>(mesh: &M) -> (Vec<DVec3>, Vec<[usize; 4]>) {
    (mesh.nodes().to_vec(), hex_boundary_faces(mesh))
}

fn write_off(path: &Path, nodes: &[DVec3], faces: &[[usize; 4]]) -> Result<(), IoError> {
    atomic_write(path, |w| {
        writeln!(w, "OFF")?;
        writeln!(w, "{} {} 0", nodes.len(), faces.len())?;
        for p in nodes {
            writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
        }
        for f in faces {
            writeln!(w, "4 {} {} {} {}", f[0], f[1], f[2], f[3])?;
        }
        Ok(())
    })
}

fn write_obj(path: &Path, nodes: &[DVec3], faces: &[[usize; 4]]) -> Result<(), IoError> {
    atomic_write(path, |w| {
        writeln!(w, "# written by unamalla-io")?;
        for p in nodes {
            writeln!(w, "v {:?} {:?} {:?}", p.x, p.y, p.z)?;
        }
        for f in faces {
            writeln!(w, "f {} {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1, f[3] + 1)?;
        }
        Ok(())
    })
}

/// Writes a quad mesh as an OFF file (`z = 0`).
pub fn write_off_quads<M: HasQuadCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
) -> Result<(), IoError> {
    let (n, f) = quads_of(mesh);
    write_off(path.as_ref(), &n, &f)
}

/// Writes the boundary surface of a hex mesh as an OFF file.
pub fn write_off_hexes<M: HasHexCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
) -> Result<(), IoError> {
    let (n, f) = hexes_of(mesh);
    write_off(path.as_ref(), &n, &f)
}

/// Writes a quad mesh as an OBJ file (`z = 0`).
pub fn write_obj_quads<M: HasQuadCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
) -> Result<(), IoError> {
    let (n, f) = quads_of(mesh);
    write_obj(path.as_ref(), &n, &f)
}

/// Writes the boundary surface of a hex mesh as an OBJ file.
pub fn write_obj_hexes<M: HasHexCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
) -> Result<(), IoError> {
    let (n, f) = hexes_of(mesh);
    write_obj(path.as_ref(), &n, &f)
}

/// Reads an OFF file.
pub fn read_off(path: impl AsRef<Path>) -> Result<SurfaceMesh, IoError> {
    let path = path.as_ref();
    parse_off_at(&read_text(path)?, path)
}

/// Like [`read_off`], for text held in memory.
pub fn parse_off(text: &str) -> Result<SurfaceMesh, IoError> {
    parse_off_at(text, Path::new(STRING_SOURCE))
}

/// Reads an OBJ file.
pub fn read_obj(path: impl AsRef<Path>) -> Result<SurfaceMesh, IoError> {
    let path = path.as_ref();
    parse_obj_at(&read_text(path)?, path)
}

/// Like [`read_obj`], for text held in memory.
pub fn parse_obj(text: &str) -> Result<SurfaceMesh, IoError> {
    parse_obj_at(text, Path::new(STRING_SOURCE))
}

/// Non-empty lines with comments removed, numbered from 1.
fn content_lines(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(k, l)| {
        let toks: Vec<&str> = l
            .split('#')
            .next()
            .unwrap_or("")
            .split_whitespace()
            .collect();
        (!toks.is_empty()).then_some((k + 1, toks))
    })
}

fn parse_off_at(text: &str, path: &Path) -> Result<SurfaceMesh, IoError> {
    let bad = |line: usize, message: String| IoError::Malformed {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = content_lines(text);
    let eof = |what: &str| IoError::Truncated {
        path: path.to_path_buf(),
        line: text.lines().count().max(1),
        expected: what.to_string(),
    };
    let (l0, mut toks) = lines.next().ok_or_else(|| eof("the OFF keyword"))?;
    match toks[0] {
        "OFF" => {}
        k if k.ends_with("OFF") => {
            return Err(IoError::Unsupported {
                path: path.to_path_buf(),
                line: l0,
                what: format!("{k} files (only plain OFF is read)"),
            })
        }
        k => return Err(bad(l0, format!("expected OFF, found {k:?}"))),
    }
    toks.remove(0);
    let (lc, counts) = if toks.is_empty() {
        lines
            .next()
            .ok_or_else(|| eof("the vertex and face counts"))?
    } else {
        (l0, toks)
    };
    let count = |k: usize, what: &str| -> Result<usize, IoError> {
        counts
            .get(k)
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| bad(lc, format!("expected the {what} count")))
    };
    let nv = count(0, "vertex")?;
    let nf = count(1, "face")?;
    let mut nodes = Vec::with_capacity(nv.min(MAX_PREALLOC));
    for k in 0..nv {
        let (l, t) = lines.next().ok_or_else(|| eof(&format!("vertex {k}")))?;
        if t.len() < 3 {
            return Err(bad(l, format!("vertex {k}: expected x y z")));
        }
        let mut c = [0.0; 3];
        for (v, s) in c.iter_mut().zip(&t) {
            *v = parse_f64(s).filter(|v| v.is_finite()).ok_or_else(|| {
                bad(
                    l,
                    format!("vertex {k}: expected a finite number, found {s:?}"),
                )
            })?;
        }
        nodes.push(DVec3::from_array(c));
    }
    let mut faces = Vec::with_capacity(nf.min(MAX_PREALLOC));
    for k in 0..nf {
        let (l, t) = lines.next().ok_or_else(|| eof(&format!("face {k}")))?;
        let n: usize = t[0].parse().map_err(|_| {
            bad(
                l,
                format!("face {k}: expected the vertex count, found {:?}", t[0]),
            )
        })?;
        if n < 3 || t.len() < n + 1 {
            return Err(bad(
                l,
                format!(
                    "face {k}: {n} vertices announced, {} given (at least 3 needed)",
                    t.len() - 1
                ),
            ));
        }
        let mut f = Vec::with_capacity(n);
        for s in &t[1..=n] {
            let v: usize =
                s.parse().ok().filter(|&v| v < nv).ok_or_else(|| {
                    bad(l, format!("face {k}: vertex index {s:?} is not in 0..{nv}"))
                })?;
            f.push(v);
        }
        faces.push(f);
    }
    if let Some((l, _)) = lines.next() {
        return Err(bad(l, format!("unexpected data after the {nf} faces")));
    }
    Ok(SurfaceMesh { nodes, faces })
}

fn parse_obj_at(text: &str, path: &Path) -> Result<SurfaceMesh, IoError> {
    let bad = |line: usize, message: String| IoError::Malformed {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut nodes: Vec<DVec3> = Vec::new();
    let mut faces = Vec::new();
    for (l, t) in content_lines(text) {
        match t[0] {
            "v" => {
                if t.len() < 4 {
                    return Err(bad(l, "v: expected x y z".into()));
                }
                let mut c = [0.0; 3];
                for (v, s) in c.iter_mut().zip(&t[1..4]) {
                    *v = parse_f64(s).filter(|v| v.is_finite()).ok_or_else(|| {
                        bad(l, format!("v: expected a finite number, found {s:?}"))
                    })?;
                }
                nodes.push(DVec3::from_array(c));
            }
            "f" => {
                if t.len() < 4 {
                    return Err(bad(l, "f: a face needs at least 3 vertices".into()));
                }
                let mut f = Vec::with_capacity(t.len() - 1);
                for s in &t[1..] {
                    let idx = s.split('/').next().unwrap_or("");
                    let i: i64 = idx
                        .parse()
                        .map_err(|_| bad(l, format!("f: expected a vertex index, found {s:?}")))?;
                    let n = nodes.len() as i64;
                    let v = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || !(0..n).contains(&v) {
                        return Err(bad(
                            l,
                            format!("f: vertex index {i} out of range (1..={n} or -{n}..=-1)"),
                        ));
                    }
                    f.push(v as usize);
                }
                faces.push(f);
            }
            _ => {}
        }
    }
    Ok(SurfaceMesh { nodes, faces })
}
