//! VTK legacy ASCII reader.

use std::path::Path;

use unamalla_mesh::{DVec2, HexMesh, QuadMesh, StructuredGrid2, StructuredGrid3};

use super::sections::{
    read_attribute, read_cell_types, read_cells, read_field, read_points, Arrays, Attr, CellTypes,
    Cells, Dataset, Points,
};
use super::write::VTK_QUAD;
use crate::error::IoError;
use crate::geojson::STRING_SOURCE;
use crate::lex::Lexer;

/// The mesh stored in a VTK file.
#[derive(Debug, Clone, PartialEq)]
pub enum VtkMesh {
    /// `STRUCTURED_GRID` with `DIMENSIONS m n 1` (all `z = 0`).
    Structured2(StructuredGrid2),
    /// `STRUCTURED_GRID` with `DIMENSIONS m n p`, `p > 1`.
    Structured3(StructuredGrid3),
    /// `UNSTRUCTURED_GRID` whose cells are all quads (type 9), all `z = 0`.
    Quads(QuadMesh),
    /// `UNSTRUCTURED_GRID` whose cells are all hexahedra (type 12).
    Hexes(HexMesh),
}

impl VtkMesh {
    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        match self {
            VtkMesh::Structured2(g) => g.num_cells(),
            VtkMesh::Structured3(g) => g.num_cells(),
            VtkMesh::Quads(q) => q.cells().len(),
            VtkMesh::Hexes(h) => h.cells().len(),
        }
    }

    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        use unamalla_mesh::HasNodes;
        match self {
            VtkMesh::Structured2(g) => g.num_nodes(),
            VtkMesh::Structured3(g) => g.num_nodes(),
            VtkMesh::Quads(q) => q.num_nodes(),
            VtkMesh::Hexes(h) => h.num_nodes(),
        }
    }
}

/// Everything [`read_vtk`] extracts from a file: the mesh and its scalar data arrays.
#[derive(Debug, Clone, PartialEq)]
pub struct VtkFile {
    /// The title line (second line of the file), without the line break.
    pub title: String,
    /// The mesh.
    pub mesh: VtkMesh,
    /// One-component cell arrays (`SCALARS … 1` or one-component `FIELD` arrays) in file
    /// order, each with one value per cell. Multi-component arrays, vectors, tensors, … are
    /// skipped.
    pub cell_data: Vec<(String, Vec<f64>)>,
    /// One-component point arrays, likewise, each with one value per node.
    pub point_data: Vec<(String, Vec<f64>)>,
}

impl VtkFile {
    /// The cell array with this name, if present.
    pub fn cell_array(&self, name: &str) -> Option<&[f64]> {
        self.cell_data
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The point array with this name, if present.
    pub fn point_array(&self, name: &str) -> Option<&[f64]> {
        self.point_data
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }
}

/// Reads a VTK legacy ASCII file (see the [module docs](crate::vtk) for what is supported).
pub fn read_vtk(path: impl AsRef<Path>) -> Result<VtkFile, IoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    match std::str::from_utf8(&bytes) {
        Ok(text) => parse_at(text, path),
        Err(e) => {
            let valid = &bytes[..e.valid_up_to()];
            let prefix = std::str::from_utf8(valid).unwrap_or("");
            let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
            if prefix
                .lines()
                .nth(2)
                .is_some_and(|l| l.trim().eq_ignore_ascii_case("BINARY"))
            {
                return Err(IoError::Unsupported {
                    path: path.to_path_buf(),
                    line: 3,
                    what: "BINARY VTK legacy files (only ASCII is read)".into(),
                });
            }
            Err(IoError::Malformed {
                path: path.to_path_buf(),
                line,
                message: "the file is not valid UTF-8/ASCII text".into(),
            })
        }
    }
}

/// Parses VTK legacy ASCII text held in memory (errors name the path `<string>`).
pub fn parse_vtk(text: &str) -> Result<VtkFile, IoError> {
    parse_at(text, Path::new(STRING_SOURCE))
}

fn parse_at(text: &str, path: &Path) -> Result<VtkFile, IoError> {
    let mut lx = Lexer::new(text, path);

    // Header: version line, title line, ASCII.
    let (first, line) = lx.next_line().ok_or_else(|| IoError::Truncated {
        path: path.to_path_buf(),
        line: 1,
        expected: "the \"# vtk DataFile Version\" header".into(),
    })?;
    let norm: String = first
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_ascii_lowercase();
    if !norm.starts_with("# vtk datafile version") {
        return Err(lx.malformed(
            line,
            format!("expected \"# vtk DataFile Version x.y\", found {first:?}"),
        ));
    }
    let (title, _) = lx.next_line().ok_or_else(|| IoError::Truncated {
        path: path.to_path_buf(),
        line: 1,
        expected: "the title line".into(),
    })?;
    let title = title.trim_end().to_string();
    let (fmt, line) = lx.next_line().ok_or_else(|| IoError::Truncated {
        path: path.to_path_buf(),
        line: 2,
        expected: "ASCII".into(),
    })?;
    let fmt = fmt.trim();
    if fmt.eq_ignore_ascii_case("BINARY") {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line,
            what: "BINARY VTK legacy files (only ASCII is read)".into(),
        });
    }
    if !fmt.eq_ignore_ascii_case("ASCII") {
        return Err(lx.malformed(line, format!("expected ASCII, found {fmt:?}")));
    }

    lx.keyword("DATASET")?;
    let (ds, ds_line) = lx.token("the dataset type")?;
    let dataset = if ds.eq_ignore_ascii_case("STRUCTURED_GRID") {
        Dataset::Structured
    } else if ds.eq_ignore_ascii_case("UNSTRUCTURED_GRID") {
        Dataset::Unstructured
    } else {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: ds_line,
            what: format!("DATASET {ds} (only STRUCTURED_GRID and UNSTRUCTURED_GRID are read)"),
        });
    };

    let mut dims: Option<([usize; 3], usize)> = None;
    let mut points: Option<Points> = None;
    let mut cells: Option<Cells> = None;
    let mut types: Option<CellTypes> = None;
    let mut attr = Attr::None;
    let mut cell_data: Arrays = Vec::new();
    let mut point_data: Arrays = Vec::new();

    while let Some((kw, line)) = lx.next() {
        let k = kw.to_ascii_uppercase();
        match k.as_str() {
            "DIMENSIONS" if dataset == Dataset::Structured => {
                if dims.is_some() {
                    return Err(lx.malformed(line, "DIMENSIONS given twice".into()));
                }
                let (a, _) = lx.usize("DIMENSIONS nx")?;
                let (b, _) = lx.usize("DIMENSIONS ny")?;
                let (c, _) = lx.usize("DIMENSIONS nz")?;
                if a == 0 || b == 0 || c == 0 {
                    return Err(lx.malformed(line, format!("DIMENSIONS {a} {b} {c}: zero size")));
                }
                dims = Some(([a, b, c], line));
            }
            "POINTS" => {
                if points.is_some() {
                    return Err(lx.malformed(line, "POINTS given twice".into()));
                }
                points = Some(read_points(&mut lx, line)?);
            }
            "CELLS" if dataset == Dataset::Unstructured => {
                if cells.is_some() {
                    return Err(lx.malformed(line, "CELLS given twice".into()));
                }
                cells = Some(read_cells(&mut lx, line)?);
            }
            "CELL_TYPES" if dataset == Dataset::Unstructured => {
                if types.is_some() {
                    return Err(lx.malformed(line, "CELL_TYPES given twice".into()));
                }
                types = Some(read_cell_types(&mut lx, line)?);
            }
            "METADATA" => lx.skip_block_to_blank_line(),
            "CELL_DATA" | "POINT_DATA" => {
                let (n, _) = lx.usize(&k)?;
                if k == "CELL_DATA" {
                    let expected = match dataset {
                        Dataset::Structured => dims.map(|(d, _)| structured_cells(d)),
                        Dataset::Unstructured => types.as_ref().map(|t| t.count),
                    };
                    let expected = expected.ok_or_else(|| {
                        lx.malformed(line, "CELL_DATA before the cells are defined".into())
                    })?;
                    if n != expected {
                        return Err(count_mismatch(
                            path,
                            line,
                            "CELL_DATA count vs number of cells",
                            expected,
                            n,
                        ));
                    }
                    attr = Attr::Cell(n);
                } else {
                    let expected = points
                        .as_ref()
                        .map(|p| p.nodes.len())
                        .ok_or_else(|| lx.malformed(line, "POINT_DATA before POINTS".into()))?;
                    if n != expected {
                        return Err(count_mismatch(
                            path,
                            line,
                            "POINT_DATA count vs number of points",
                            expected,
                            n,
                        ));
                    }
                    attr = Attr::Point(n);
                }
            }
            "FIELD" => {
                // Dataset-level field data (attr None) is read and discarded.
                let keep = match attr {
                    Attr::Cell(n) => Some((n, &mut cell_data)),
                    Attr::Point(n) => Some((n, &mut point_data)),
                    Attr::None => None,
                };
                read_field(&mut lx, keep)?;
            }
            "SCALARS"
            | "VECTORS"
            | "NORMALS"
            | "TENSORS"
            | "TENSORS6"
            | "TEXTURE_COORDINATES"
            | "COLOR_SCALARS"
            | "LOOKUP_TABLE" => {
                let (n, target) = match attr {
                    Attr::Cell(n) => (n, &mut cell_data),
                    Attr::Point(n) => (n, &mut point_data),
                    Attr::None => {
                        return Err(lx.malformed(
                            line,
                            format!("{kw} outside a CELL_DATA or POINT_DATA section"),
                        ))
                    }
                };
                read_attribute(&mut lx, &k, line, n, target)?;
            }
            _ => {
                return Err(lx.malformed(line, format!("unexpected keyword {kw:?}")));
            }
        }
    }

    let end_line = lx.line();
    let points = points.ok_or_else(|| IoError::Truncated {
        path: path.to_path_buf(),
        line: end_line,
        expected: "POINTS".into(),
    })?;
    let mesh_err = |source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    };

    let mesh = match dataset {
        Dataset::Structured => {
            let ([a, b, c], dline) = dims.ok_or_else(|| IoError::Truncated {
                path: path.to_path_buf(),
                line: end_line,
                expected: "DIMENSIONS".into(),
            })?;
            let total = a
                .checked_mul(b)
                .and_then(|ab| ab.checked_mul(c))
                .ok_or_else(|| lx.malformed(dline, "DIMENSIONS: count too large".into()))?;
            if total != points.nodes.len() {
                return Err(count_mismatch(
                    path,
                    points.line,
                    &format!("POINTS count vs DIMENSIONS {a} {b} {c}"),
                    total,
                    points.nodes.len(),
                ));
            }
            if c == 1 {
                check_planar(path, &points)?;
                let nodes = points.nodes.iter().map(|p| DVec2::new(p.x, p.y)).collect();
                VtkMesh::Structured2(StructuredGrid2::new(a, b, nodes).map_err(mesh_err)?)
            } else if a == 1 || b == 1 {
                return Err(IoError::Unsupported {
                    path: path.to_path_buf(),
                    line: dline,
                    what: format!(
                        "DIMENSIONS {a} {b} {c}: only nz = 1 is read as a 2D grid; nx = 1 or ny = 1 is not supported"
                    ),
                });
            } else {
                VtkMesh::Structured3(StructuredGrid3::new(a, b, c, points.nodes).map_err(mesh_err)?)
            }
        }
        Dataset::Unstructured => {
            let cells = cells.ok_or_else(|| IoError::Truncated {
                path: path.to_path_buf(),
                line: end_line,
                expected: "CELLS".into(),
            })?;
            let types = types.ok_or_else(|| IoError::Truncated {
                path: path.to_path_buf(),
                line: end_line,
                expected: "CELL_TYPES".into(),
            })?;
            let ncells = cells.lines.len();
            if types.count != ncells {
                return Err(count_mismatch(
                    path,
                    types.line,
                    "CELL_TYPES count vs CELLS count",
                    ncells,
                    types.count,
                ));
            }
            let kind = types.kind.ok_or_else(|| IoError::Unsupported {
                path: path.to_path_buf(),
                line: cells.header_line,
                what: "an unstructured grid without cells (quad or hex cannot be told)".into(),
            })?;
            let arity = if kind == VTK_QUAD { 4 } else { 8 };
            for c in 0..ncells {
                let len = cells.offsets[c + 1] - cells.offsets[c];
                if len != arity {
                    return Err(count_mismatch(
                        path,
                        cells.lines[c],
                        &format!("number of nodes of cell {c} (VTK type {kind})"),
                        arity,
                        len,
                    ));
                }
            }
            if kind == VTK_QUAD {
                check_planar(path, &points)?;
                let nodes = points.nodes.iter().map(|p| DVec2::new(p.x, p.y)).collect();
                let conn: Vec<[usize; 4]> = cells
                    .conn
                    .chunks_exact(4)
                    .map(|s| [s[0], s[1], s[2], s[3]])
                    .collect();
                VtkMesh::Quads(QuadMesh::new(nodes, conn).map_err(mesh_err)?)
            } else {
                let conn: Vec<[usize; 8]> = cells
                    .conn
                    .chunks_exact(8)
                    .map(|s| std::array::from_fn(|k| s[k]))
                    .collect();
                VtkMesh::Hexes(HexMesh::new(points.nodes, conn).map_err(mesh_err)?)
            }
        }
    };

    Ok(VtkFile {
        title,
        mesh,
        cell_data,
        point_data,
    })
}

pub(super) fn structured_cells(d: [usize; 3]) -> usize {
    let c = |n: usize| n.saturating_sub(1).max(1);
    c(d[0]).saturating_mul(c(d[1])).saturating_mul(c(d[2]))
}

pub(super) fn count_mismatch(
    path: &Path,
    line: usize,
    what: &str,
    expected: usize,
    found: usize,
) -> IoError {
    IoError::CountMismatch {
        path: path.to_path_buf(),
        line,
        what: what.to_string(),
        expected,
        found,
    }
}

pub(super) fn check_planar(path: &Path, points: &Points) -> Result<(), IoError> {
    match points.first_nonzero_z {
        Some((node, line, z)) => Err(IoError::NotPlanar {
            path: path.to_path_buf(),
            line,
            node,
            z,
        }),
        None => Ok(()),
    }
}
