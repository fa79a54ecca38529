//! The VTK XML readers: `.vts` and `.vtu` into a [`VtkFile`], `.vtm` into its entries.

use std::path::{Path, PathBuf};

use unamalla_mesh::{DVec2, DVec3, HexMesh, QuadMesh, StructuredGrid2, StructuredGrid3};

use super::binary::{binary_values, is_binary};
use crate::error::IoError;
use crate::geojson::{read_text, STRING_SOURCE};
use crate::lex::{Lexer, MAX_PREALLOC};
use crate::vtk::{VtkFile, VtkMesh, VTK_HEXAHEDRON, VTK_QUAD};
use crate::xml::{self, Element};

/// One data set listed in a `.vtm` index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VtmEntry {
    /// The `name` attribute (empty if absent).
    pub name: String,
    /// The `file` attribute resolved against the index's directory.
    pub file: PathBuf,
}

/// Reads a `.vtm` index: every `<DataSet file="…">` (nested `<Block>`s included), in document
/// order, with `file` resolved against the directory of `path`.
pub fn read_vtm(path: impl AsRef<Path>) -> Result<Vec<VtmEntry>, IoError> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let root = xml::parse(&text, path)?;
    check_root(&root, "vtkMultiBlockDataSet", path)?;
    let base = path.parent().unwrap_or(Path::new(""));
    let Some(mb) = root.child("vtkMultiBlockDataSet") else {
        return Err(missing(path, &root, "<vtkMultiBlockDataSet>"));
    };
    let mut out = Vec::new();
    let mut stack: Vec<&Element> = vec![mb];
    // Depth-first, document order.
    while let Some(e) = stack.pop() {
        if e.name == "DataSet" {
            let file = e
                .attr("file")
                .ok_or_else(|| missing(path, e, "attribute file"))?;
            out.push(VtmEntry {
                name: e.attr("name").unwrap_or("").to_string(),
                file: base.join(file),
            });
        }
        stack.extend(e.children.iter().rev());
    }
    Ok(out)
}

/// Reads a `.vts` or `.vtu` file (ASCII or binary data arrays) — see the [module docs](crate::vtk_xml).
pub fn read_vtk_xml(path: impl AsRef<Path>) -> Result<VtkFile, IoError> {
    let path = path.as_ref();
    let text = read_text(path)?;
    parse_at(&text, path)
}

/// Like [`read_vtk_xml`], for text held in memory (errors name `<string>`).
pub fn parse_vtk_xml(text: &str) -> Result<VtkFile, IoError> {
    parse_at(text, Path::new(STRING_SOURCE))
}

pub(super) fn missing(path: &Path, e: &Element, what: &str) -> IoError {
    IoError::Malformed {
        path: path.to_path_buf(),
        line: e.line,
        message: format!("<{}> has no {what}", e.name),
    }
}

fn check_root(root: &Element, kind: &str, path: &Path) -> Result<(), IoError> {
    if root.name != "VTKFile" {
        return Err(IoError::Malformed {
            path: path.to_path_buf(),
            line: root.line,
            message: format!("expected <VTKFile>, found <{}>", root.name),
        });
    }
    match root.attr("type") {
        Some(t) if t == kind => Ok(()),
        Some(t) => Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: root.line,
            what: format!("VTKFile type {t:?} (expected {kind:?})"),
        }),
        None => Err(missing(path, root, "attribute type")),
    }
}

fn parse_at(text: &str, path: &Path) -> Result<VtkFile, IoError> {
    let root = xml::parse(text, path)?;
    if root.name != "VTKFile" {
        return Err(IoError::Malformed {
            path: path.to_path_buf(),
            line: root.line,
            message: format!("expected <VTKFile>, found <{}>", root.name),
        });
    }
    let kind = root
        .attr("type")
        .ok_or_else(|| missing(path, &root, "attribute type"))?;
    match kind {
        "StructuredGrid" => read_structured(&root, path),
        "UnstructuredGrid" => read_unstructured(&root, path),
        other => Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: root.line,
            what: format!(
                "VTKFile type {other:?} (only StructuredGrid and UnstructuredGrid are read)"
            ),
        }),
    }
}

/// The single `<Piece>` of a data set element.
fn single_piece<'e>(ds: &'e Element, path: &Path) -> Result<&'e Element, IoError> {
    let mut pieces = ds.children_named("Piece");
    let piece = pieces.next().ok_or_else(|| missing(path, ds, "<Piece>"))?;
    if let Some(p2) = pieces.next() {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: p2.line,
            what: "more than one <Piece>".into(),
        });
    }
    Ok(piece)
}

fn parse_usize_attr(e: &Element, name: &str, path: &Path) -> Result<usize, IoError> {
    let v = e
        .attr(name)
        .ok_or_else(|| missing(path, e, &format!("attribute {name}")))?;
    v.trim().parse().map_err(|_| IoError::Malformed {
        path: path.to_path_buf(),
        line: e.line,
        message: format!("{name}={v:?}: expected a non-negative integer"),
    })
}

fn parse_extent(e: &Element, name: &str, path: &Path) -> Result<[i64; 6], IoError> {
    let v = e
        .attr(name)
        .ok_or_else(|| missing(path, e, &format!("attribute {name}")))?;
    let bad = || IoError::Malformed {
        path: path.to_path_buf(),
        line: e.line,
        message: format!("{name}={v:?}: expected six integers x0 x1 y0 y1 z0 z1 with x0 <= x1, …"),
    };
    let nums: Vec<i64> = v
        .split_whitespace()
        .map(|t| t.parse::<i64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    let ext: [i64; 6] = nums.try_into().map_err(|_| bad())?;
    if ext[0] > ext[1] || ext[2] > ext[3] || ext[4] > ext[5] {
        return Err(bad());
    }
    Ok(ext)
}

/// The numbers of an ASCII `<DataArray>`, exactly `count` of them.
pub(super) fn array_values(e: &Element, count: usize, path: &Path) -> Result<Vec<f64>, IoError> {
    let name = e.attr("Name").unwrap_or("(unnamed)");
    if is_binary(e, path)? {
        let v = binary_values(e, path)?;
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            return Err(IoError::Malformed {
                path: path.to_path_buf(),
                line: e.text_line,
                message: format!("DataArray {name}: value {k} is not finite"),
            });
        }
        if v.len() != count {
            return Err(IoError::CountMismatch {
                path: path.to_path_buf(),
                line: e.line,
                what: format!("DataArray {name} values"),
                expected: count,
                found: v.len(),
            });
        }
        return Ok(v);
    }
    let mut lx = Lexer::starting_at(&e.text, path, e.text_line);
    let mut v = Vec::with_capacity(count.min(MAX_PREALLOC));
    while let Some((t, line)) = lx.next() {
        let x = crate::lex::parse_f64(t)
            .filter(|x| x.is_finite())
            .ok_or_else(|| IoError::Malformed {
                path: path.to_path_buf(),
                line,
                message: format!("DataArray {name}: expected a finite number, found {t:?}"),
            })?;
        if v.len() == count {
            return Err(IoError::CountMismatch {
                path: path.to_path_buf(),
                line: e.line,
                what: format!("DataArray {name} values"),
                expected: count,
                found: count + 1 + lx_rest_count(&mut lx),
            });
        }
        v.push(x);
    }
    if v.len() != count {
        return Err(IoError::CountMismatch {
            path: path.to_path_buf(),
            line: e.line,
            what: format!("DataArray {name} values"),
            expected: count,
            found: v.len(),
        });
    }
    Ok(v)
}

fn lx_rest_count(lx: &mut Lexer<'_>) -> usize {
    let mut n = 0;
    while lx.next().is_some() {
        n += 1;
    }
    n
}

/// Integer `<DataArray>` (connectivity, offsets, types).
fn array_ints(e: &Element, count: Option<usize>, path: &Path) -> Result<Vec<usize>, IoError> {
    let name = e.attr("Name").unwrap_or("(unnamed)");
    let mut v = Vec::with_capacity(count.unwrap_or(0).min(MAX_PREALLOC));
    let binary = is_binary(e, path)?;
    if binary {
        for (k, x) in binary_values(e, path)?.into_iter().enumerate() {
            if !(x >= 0.0 && x.fract() == 0.0 && x < 9.0e15) {
                return Err(IoError::Malformed {
                    path: path.to_path_buf(),
                    line: e.text_line,
                    message: format!(
                        "DataArray {name}: value {k} ({x}) is not a non-negative integer"
                    ),
                });
            }
            v.push(x as usize);
        }
    }
    let mut lx = Lexer::starting_at(if binary { "" } else { &e.text }, path, e.text_line);
    while let Some((t, line)) = lx.next() {
        let x = t.parse::<usize>().map_err(|_| IoError::Malformed {
            path: path.to_path_buf(),
            line,
            message: format!("DataArray {name}: expected a non-negative integer, found {t:?}"),
        })?;
        v.push(x);
    }
    if let Some(c) = count {
        if v.len() != c {
            return Err(IoError::CountMismatch {
                path: path.to_path_buf(),
                line: e.line,
                what: format!("DataArray {name} values"),
                expected: c,
                found: v.len(),
            });
        }
    }
    Ok(v)
}

pub(super) fn components(e: &Element, path: &Path) -> Result<usize, IoError> {
    match e.attr("NumberOfComponents") {
        None => Ok(1),
        Some(_) => parse_usize_attr(e, "NumberOfComponents", path),
    }
}

/// Points of a piece: `n` points of 3 components.
fn read_points(piece: &Element, n: usize, path: &Path) -> Result<(Vec<DVec3>, usize), IoError> {
    let pts = piece
        .child("Points")
        .ok_or_else(|| missing(path, piece, "<Points>"))?;
    let arr = pts
        .child("DataArray")
        .ok_or_else(|| missing(path, pts, "<DataArray>"))?;
    let nc = components(arr, path)?;
    if nc != 3 {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: arr.line,
            what: format!("points with {nc} components (3 expected)"),
        });
    }
    let count = n.checked_mul(3).ok_or_else(|| IoError::Malformed {
        path: path.to_path_buf(),
        line: arr.line,
        message: "number of points too large".into(),
    })?;
    let v = array_values(arr, count, path)?;
    Ok((
        v.chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect(),
        arr.text_line,
    ))
}

/// One-component arrays of `<CellData>` or `<PointData>` with `n` values each.
fn read_arrays(
    piece: &Element,
    section: &str,
    n: usize,
    path: &Path,
) -> Result<Vec<(String, Vec<f64>)>, IoError> {
    let mut out = Vec::new();
    for sec in piece.children_named(section) {
        for arr in sec.children_named("DataArray") {
            if components(arr, path)? != 1 {
                continue;
            }
            let name = arr
                .attr("Name")
                .ok_or_else(|| missing(path, arr, "attribute Name"))?;
            let v = array_values(arr, n, path)?;
            out.push((name.to_string(), v));
        }
    }
    Ok(out)
}

/// 2D points: every z must be 0.
fn planar(pts: Vec<DVec3>, line: usize, path: &Path) -> Result<Vec<DVec2>, IoError> {
    if let Some((node, p)) = pts.iter().enumerate().find(|(_, p)| p.z != 0.0) {
        return Err(IoError::NotPlanar {
            path: path.to_path_buf(),
            line,
            node,
            z: p.z,
        });
    }
    Ok(pts.iter().map(|p| p.truncate()).collect())
}

fn mesh_err(path: &Path) -> impl Fn(unamalla_mesh::MeshError) -> IoError + '_ {
    move |source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    }
}

fn read_structured(root: &Element, path: &Path) -> Result<VtkFile, IoError> {
    let ds = root
        .child("StructuredGrid")
        .ok_or_else(|| missing(path, root, "<StructuredGrid>"))?;
    let whole = parse_extent(ds, "WholeExtent", path)?;
    let piece = single_piece(ds, path)?;
    let ext = parse_extent(piece, "Extent", path)?;
    if ext != whole {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: piece.line,
            what: "a piece extent different from the whole extent".into(),
        });
    }
    let too_big = || IoError::Malformed {
        path: path.to_path_buf(),
        line: ds.line,
        message: "extent too large".into(),
    };
    let dim = |a: i64, b: i64| -> Result<usize, IoError> {
        usize::try_from(b.checked_sub(a).ok_or_else(too_big)?)
            .ok()
            .and_then(|d| d.checked_add(1))
            .ok_or_else(too_big)
    };
    let (m, n, p) = (
        dim(ext[0], ext[1])?,
        dim(ext[2], ext[3])?,
        dim(ext[4], ext[5])?,
    );
    let np = m
        .checked_mul(n)
        .and_then(|x| x.checked_mul(p))
        .ok_or_else(too_big)?;
    let nc = (m - 1)
        .max(1)
        .checked_mul((n - 1).max(1))
        .and_then(|x| x.checked_mul((p - 1).max(1)))
        .ok_or_else(too_big)?;
    let unsupported = |what: String| IoError::Unsupported {
        path: path.to_path_buf(),
        line: ds.line,
        what,
    };
    if m < 2 || n < 2 {
        return Err(unsupported(format!(
            "a structured grid of {m} × {n} × {p} nodes (at least 2 × 2 needed)"
        )));
    }
    let (pts, pline) = read_points(piece, np, path)?;
    let cell_data = read_arrays(piece, "CellData", nc, path)?;
    let point_data = read_arrays(piece, "PointData", np, path)?;
    let mesh = if p == 1 {
        let nodes = planar(pts, pline, path)?;
        VtkMesh::Structured2(StructuredGrid2::new(m, n, nodes).map_err(mesh_err(path))?)
    } else {
        VtkMesh::Structured3(StructuredGrid3::new(m, n, p, pts).map_err(mesh_err(path))?)
    };
    Ok(VtkFile {
        title: String::new(),
        mesh,
        cell_data,
        point_data,
    })
}

fn read_unstructured(root: &Element, path: &Path) -> Result<VtkFile, IoError> {
    let ds = root
        .child("UnstructuredGrid")
        .ok_or_else(|| missing(path, root, "<UnstructuredGrid>"))?;
    let piece = single_piece(ds, path)?;
    let np = parse_usize_attr(piece, "NumberOfPoints", path)?;
    let nc = parse_usize_attr(piece, "NumberOfCells", path)?;
    let (pts, pline) = read_points(piece, np, path)?;
    let cells = piece
        .child("Cells")
        .ok_or_else(|| missing(path, piece, "<Cells>"))?;
    let named = |n: &str| {
        cells
            .children_named("DataArray")
            .find(|a| a.attr("Name") == Some(n))
            .ok_or_else(|| missing(path, cells, &format!("DataArray {n}")))
    };
    let conn_e = named("connectivity")?;
    let offs_e = named("offsets")?;
    let types_e = named("types")?;
    let types = array_ints(types_e, Some(nc), path)?;
    let offsets = array_ints(offs_e, Some(nc), path)?;
    let conn = array_ints(conn_e, None, path)?;
    let kind = types.first().copied();
    let want = match kind {
        None => 0,
        Some(t) if t == usize::from(VTK_QUAD) => 4,
        Some(t) if t == usize::from(VTK_HEXAHEDRON) => 8,
        Some(t) => {
            return Err(IoError::UnsupportedCellType {
                path: path.to_path_buf(),
                line: types_e.text_line,
                cell: 0,
                cell_type: i64::try_from(t).unwrap_or(i64::MAX),
            })
        }
    };
    if let Some((c, &t)) = types.iter().enumerate().find(|(_, &t)| Some(t) != kind) {
        return Err(IoError::UnsupportedCellType {
            path: path.to_path_buf(),
            line: types_e.text_line,
            cell: c,
            cell_type: i64::try_from(t).unwrap_or(i64::MAX),
        });
    }
    let mut prev = 0usize;
    for (c, &o) in offsets.iter().enumerate() {
        if o.checked_sub(prev) != Some(want) {
            return Err(IoError::Malformed {
                path: path.to_path_buf(),
                line: offs_e.text_line,
                message: format!(
                    "offset of cell {c} is {o}, expected {} ({want} nodes per cell)",
                    prev.saturating_add(want)
                ),
            });
        }
        prev = o;
    }
    if conn.len() != prev {
        return Err(IoError::CountMismatch {
            path: path.to_path_buf(),
            line: conn_e.line,
            what: "connectivity entries (last offset)".into(),
            expected: prev,
            found: conn.len(),
        });
    }
    let cell_data = read_arrays(piece, "CellData", nc, path)?;
    let point_data = read_arrays(piece, "PointData", np, path)?;
    let mesh = if want == 8 {
        let cells: Vec<[usize; 8]> = conn
            .chunks_exact(8)
            .map(|c| std::array::from_fn(|k| c[k]))
            .collect();
        VtkMesh::Hexes(HexMesh::new(pts, cells).map_err(mesh_err(path))?)
    } else {
        let cells: Vec<[usize; 4]> = conn
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        let nodes = planar(pts, pline, path)?;
        VtkMesh::Quads(QuadMesh::new(nodes, cells).map_err(mesh_err(path))?)
    };
    Ok(VtkFile {
        title: String::new(),
        mesh,
        cell_data,
        point_data,
    })
}
