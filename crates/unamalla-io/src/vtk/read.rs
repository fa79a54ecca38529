//! VTK legacy ASCII reader.

use std::path::{Path, PathBuf};

use unamalla_mesh::{DVec2, DVec3, HexMesh, QuadMesh, StructuredGrid2, StructuredGrid3};

use super::write::{VTK_HEXAHEDRON, VTK_QUAD};
use crate::error::IoError;
use crate::geojson::STRING_SOURCE;

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

/// Named data arrays in file order.
type Arrays = Vec<(String, Vec<f64>)>;

/// Upper bound for capacities taken from counts in the file (a lying count must not make us
/// allocate gigabytes before the data runs out).
const MAX_PREALLOC: usize = 1 << 20;

struct Lexer<'a> {
    path: &'a Path,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    cur: std::str::SplitWhitespace<'a>,
    /// 1-based number of the line `cur` comes from (0 before the first line).
    line: usize,
    peeked: Option<(&'a str, usize)>,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str, path: &'a Path) -> Self {
        Self {
            path,
            lines: text.lines().enumerate(),
            cur: "".split_whitespace(),
            line: 0,
            peeked: None,
        }
    }

    fn pb(&self) -> PathBuf {
        self.path.to_path_buf()
    }

    /// The next whole line (used for the header only, before any token was read).
    fn raw_line(&mut self) -> Option<(&'a str, usize)> {
        let (k, l) = self.lines.next()?;
        self.line = k + 1;
        Some((l, k + 1))
    }

    fn next(&mut self) -> Option<(&'a str, usize)> {
        if let Some(t) = self.peeked.take() {
            return Some(t);
        }
        loop {
            if let Some(t) = self.cur.next() {
                return Some((t, self.line));
            }
            let (k, l) = self.lines.next()?;
            self.line = k + 1;
            self.cur = l.split_whitespace();
        }
    }

    fn peek(&mut self) -> Option<(&'a str, usize)> {
        if self.peeked.is_none() {
            self.peeked = self.next();
        }
        self.peeked
    }

    /// Drops the rest of the current line and everything up to and including the next blank
    /// line (VTK 5 `METADATA` blocks end with a blank line).
    fn skip_block_to_blank_line(&mut self) {
        self.peeked = None;
        self.cur = "".split_whitespace();
        for (k, l) in self.lines.by_ref() {
            self.line = k + 1;
            if l.trim().is_empty() {
                break;
            }
        }
    }

    fn token(&mut self, expected: &str) -> Result<(&'a str, usize), IoError> {
        self.next().ok_or_else(|| IoError::Truncated {
            path: self.pb(),
            line: self.line.max(1),
            expected: expected.to_string(),
        })
    }

    fn malformed(&self, line: usize, message: String) -> IoError {
        IoError::Malformed {
            path: self.pb(),
            line,
            message,
        }
    }

    fn keyword(&mut self, kw: &str) -> Result<usize, IoError> {
        let (t, line) = self.token(kw)?;
        if t.eq_ignore_ascii_case(kw) {
            Ok(line)
        } else {
            Err(self.malformed(line, format!("expected {kw}, found {t:?}")))
        }
    }

    fn usize(&mut self, what: &str) -> Result<(usize, usize), IoError> {
        let (t, line) = self.token(what)?;
        t.parse::<usize>().map(|v| (v, line)).map_err(|_| {
            self.malformed(
                line,
                format!("{what}: expected a non-negative integer, found {t:?}"),
            )
        })
    }

    fn f64(&mut self, what: &str) -> Result<(f64, usize), IoError> {
        let (t, line) = self.token(what)?;
        t.parse::<f64>()
            .map(|v| (v, line))
            .map_err(|_| self.malformed(line, format!("{what}: expected a number, found {t:?}")))
    }

    /// Reads `count` numbers.
    fn numbers(&mut self, count: usize, what: &str) -> Result<Vec<f64>, IoError> {
        let mut v = Vec::with_capacity(count.min(MAX_PREALLOC));
        for _ in 0..count {
            v.push(self.f64(what)?.0);
        }
        Ok(v)
    }

    /// `a * b` or a "count too large" error.
    fn mul(&self, a: usize, b: usize, line: usize, what: &str) -> Result<usize, IoError> {
        a.checked_mul(b)
            .ok_or_else(|| self.malformed(line, format!("{what}: count too large")))
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Dataset {
    Structured,
    Unstructured,
}

#[derive(Clone, Copy, PartialEq)]
enum Attr {
    None,
    Cell(usize),
    Point(usize),
}

struct Points {
    nodes: Vec<DVec3>,
    line: usize,
    /// First node with `z ≠ 0`: (node, line, z).
    first_nonzero_z: Option<(usize, usize, f64)>,
}

struct Cells {
    /// `offsets[c]..offsets[c + 1]` indexes `conn` for cell `c`.
    offsets: Vec<usize>,
    conn: Vec<usize>,
    /// Line where each cell starts.
    lines: Vec<usize>,
    header_line: usize,
}

struct CellTypes {
    /// `VTK_QUAD` or `VTK_HEXAHEDRON` (`None` when there are no cells).
    kind: Option<u8>,
    count: usize,
    line: usize,
}

fn parse_at(text: &str, path: &Path) -> Result<VtkFile, IoError> {
    let mut lx = Lexer::new(text, path);

    // Header: version line, title line, ASCII.
    let (first, line) = lx.raw_line().ok_or_else(|| IoError::Truncated {
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
    let (title, _) = lx.raw_line().ok_or_else(|| IoError::Truncated {
        path: path.to_path_buf(),
        line: 1,
        expected: "the title line".into(),
    })?;
    let title = title.trim_end().to_string();
    let (fmt, line) = lx.raw_line().ok_or_else(|| IoError::Truncated {
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

    let end_line = lx.line.max(1);
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

fn structured_cells(d: [usize; 3]) -> usize {
    let c = |n: usize| n.saturating_sub(1).max(1);
    c(d[0]).saturating_mul(c(d[1])).saturating_mul(c(d[2]))
}

fn count_mismatch(path: &Path, line: usize, what: &str, expected: usize, found: usize) -> IoError {
    IoError::CountMismatch {
        path: path.to_path_buf(),
        line,
        what: what.to_string(),
        expected,
        found,
    }
}

fn check_planar(path: &Path, points: &Points) -> Result<(), IoError> {
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

/// `POINTS n type` followed by `3 n` numbers (any numeric type is read as `f64`).
fn read_points(lx: &mut Lexer<'_>, line: usize) -> Result<Points, IoError> {
    let (n, _) = lx.usize("POINTS count")?;
    lx.token("POINTS data type")?;
    let mut nodes = Vec::with_capacity(n.min(MAX_PREALLOC));
    let mut first_nonzero_z = None;
    for v in 0..n {
        let (x, _) = lx.f64("point x")?;
        let (y, _) = lx.f64("point y")?;
        let (z, zline) = lx.f64("point z")?;
        if z != 0.0 && first_nonzero_z.is_none() {
            first_nonzero_z = Some((v, zline, z));
        }
        nodes.push(DVec3::new(x, y, z));
    }
    if lx
        .peek()
        .is_some_and(|(t, _)| t.eq_ignore_ascii_case("METADATA"))
    {
        lx.skip_block_to_blank_line();
    }
    Ok(Points {
        nodes,
        line,
        first_nonzero_z,
    })
}

/// `CELLS n size` in the classic form (`k i1 … ik` per cell) or the VTK 5 form
/// (`OFFSETS type` + `n` offsets, `CONNECTIVITY type` + `size` ids; here `n` is cells + 1).
fn read_cells(lx: &mut Lexer<'_>, header_line: usize) -> Result<Cells, IoError> {
    let (n, _) = lx.usize("CELLS count")?;
    let (size, _) = lx.usize("CELLS size")?;
    let path = lx.path;
    if lx
        .peek()
        .is_some_and(|(t, _)| t.eq_ignore_ascii_case("OFFSETS"))
    {
        lx.next();
        lx.token("OFFSETS data type")?;
        let mut offsets = Vec::with_capacity(n.min(MAX_PREALLOC));
        let mut lines = Vec::with_capacity(n.min(MAX_PREALLOC));
        for c in 0..n {
            let (o, line) = lx.usize("cell offset")?;
            let prev = offsets.last().copied();
            if (c == 0 && o != 0) || prev.is_some_and(|p| o < p) || o > size {
                return Err(lx.malformed(
                    line,
                    format!("offset {c} = {o}: offsets must start at 0, not decrease and not exceed {size}"),
                ));
            }
            offsets.push(o);
            lines.push(line);
        }
        let last = offsets.last().copied().unwrap_or(0);
        if last != size {
            return Err(count_mismatch(
                path,
                header_line,
                "last OFFSETS entry vs CONNECTIVITY size",
                size,
                last,
            ));
        }
        lx.keyword("CONNECTIVITY")?;
        lx.token("CONNECTIVITY data type")?;
        let mut conn = Vec::with_capacity(size.min(MAX_PREALLOC));
        for _ in 0..size {
            conn.push(lx.usize("node id")?.0);
        }
        // One line per cell, for the cells (offsets has one more entry than cells).
        lines.pop();
        if offsets.is_empty() {
            offsets.push(0);
        }
        return Ok(Cells {
            offsets,
            conn,
            lines,
            header_line,
        });
    }
    let mut offsets = Vec::with_capacity(n.min(MAX_PREALLOC).saturating_add(1));
    offsets.push(0);
    let mut lines = Vec::with_capacity(n.min(MAX_PREALLOC));
    let mut conn = Vec::with_capacity(size.min(MAX_PREALLOC));
    let mut consumed: usize = 0;
    for _ in 0..n {
        let (k, line) = lx.usize("number of nodes of a cell")?;
        consumed = consumed.saturating_add(k).saturating_add(1);
        if consumed > size {
            return Err(count_mismatch(
                path,
                header_line,
                "CELLS size (total number of integers)",
                size,
                consumed,
            ));
        }
        for _ in 0..k {
            conn.push(lx.usize("node id")?.0);
        }
        offsets.push(conn.len());
        lines.push(line);
    }
    if consumed != size {
        return Err(count_mismatch(
            path,
            header_line,
            "CELLS size (total number of integers)",
            size,
            consumed,
        ));
    }
    Ok(Cells {
        offsets,
        conn,
        lines,
        header_line,
    })
}

/// `CELL_TYPES n` and `n` integers, which must all be 9 or all be 12.
fn read_cell_types(lx: &mut Lexer<'_>, line: usize) -> Result<CellTypes, IoError> {
    let (n, _) = lx.usize("CELL_TYPES count")?;
    let mut kind: Option<u8> = None;
    for c in 0..n {
        let (t, tline) = lx.token("cell type")?;
        let ty: i64 = t.parse().map_err(|_| {
            lx.malformed(
                tline,
                format!("cell type: expected an integer, found {t:?}"),
            )
        })?;
        let ok = match kind {
            None => ty == i64::from(VTK_QUAD) || ty == i64::from(VTK_HEXAHEDRON),
            Some(k) => ty == i64::from(k),
        };
        if !ok {
            return Err(IoError::UnsupportedCellType {
                path: lx.pb(),
                line: tline,
                cell: c,
                cell_type: ty,
            });
        }
        // `ty` is 9 or 12 here.
        kind = Some(if ty == i64::from(VTK_QUAD) {
            VTK_QUAD
        } else {
            VTK_HEXAHEDRON
        });
    }
    Ok(CellTypes {
        kind,
        count: n,
        line,
    })
}

/// An attribute inside `CELL_DATA`/`POINT_DATA` with `n` tuples; one-component `SCALARS` are
/// stored in `target`, everything else is consumed and dropped.
fn read_attribute(
    lx: &mut Lexer<'_>,
    kw: &str,
    line: usize,
    n: usize,
    target: &mut Arrays,
) -> Result<(), IoError> {
    match kw {
        "SCALARS" => {
            let (name, _) = lx.token("SCALARS name")?;
            lx.token("SCALARS data type")?;
            // Optional number of components, on the same line.
            let mut ncomp = 1;
            if let Some((t, tl)) = lx.peek() {
                if tl == line {
                    ncomp = t.parse::<usize>().map_err(|_| {
                        lx.malformed(
                            tl,
                            format!("SCALARS: expected the number of components, found {t:?}"),
                        )
                    })?;
                    lx.next();
                    if !(1..=4).contains(&ncomp) {
                        return Err(lx.malformed(
                            tl,
                            format!("SCALARS with {ncomp} components (1 to 4 allowed)"),
                        ));
                    }
                }
            }
            if lx
                .peek()
                .is_some_and(|(t, _)| t.eq_ignore_ascii_case("LOOKUP_TABLE"))
            {
                lx.next();
                lx.token("LOOKUP_TABLE name")?;
            }
            let count = lx.mul(n, ncomp, line, "SCALARS")?;
            let values = lx.numbers(count, &format!("SCALARS {name} value"))?;
            if ncomp == 1 {
                target.push((name.to_string(), values));
            }
        }
        "LOOKUP_TABLE" => {
            // A table definition: name, size, then size RGBA tuples.
            lx.token("LOOKUP_TABLE name")?;
            let (size, _) = lx.usize("LOOKUP_TABLE size")?;
            let count = lx.mul(size, 4, line, "LOOKUP_TABLE")?;
            lx.numbers(count, "LOOKUP_TABLE value")?;
        }
        "COLOR_SCALARS" => {
            lx.token("COLOR_SCALARS name")?;
            let (nv, _) = lx.usize("COLOR_SCALARS number of values")?;
            let count = lx.mul(n, nv, line, "COLOR_SCALARS")?;
            lx.numbers(count, "COLOR_SCALARS value")?;
        }
        "TEXTURE_COORDINATES" => {
            lx.token("TEXTURE_COORDINATES name")?;
            let (dim, _) = lx.usize("TEXTURE_COORDINATES dimension")?;
            lx.token("TEXTURE_COORDINATES data type")?;
            let count = lx.mul(n, dim, line, "TEXTURE_COORDINATES")?;
            lx.numbers(count, "TEXTURE_COORDINATES value")?;
        }
        _ => {
            // VECTORS, NORMALS (3), TENSORS (9), TENSORS6 (6).
            let width = match kw {
                "TENSORS" => 9,
                "TENSORS6" => 6,
                _ => 3,
            };
            lx.token("attribute name")?;
            lx.token("attribute data type")?;
            let count = lx.mul(n, width, line, kw)?;
            lx.numbers(count, &format!("{kw} value"))?;
        }
    }
    if lx
        .peek()
        .is_some_and(|(t, _)| t.eq_ignore_ascii_case("METADATA"))
    {
        lx.skip_block_to_blank_line();
    }
    Ok(())
}

/// `FIELD name k` followed by `k` arrays `name ncomp ntuples type` + values. One-component
/// arrays with exactly the section's tuple count are kept when `keep` is given.
fn read_field(lx: &mut Lexer<'_>, mut keep: Option<(usize, &mut Arrays)>) -> Result<(), IoError> {
    lx.token("FIELD name")?;
    let (k, _) = lx.usize("FIELD number of arrays")?;
    for _ in 0..k {
        let (name, aline) = lx.token("FIELD array name")?;
        let (ncomp, _) = lx.usize("FIELD array components")?;
        let (ntuples, _) = lx.usize("FIELD array tuples")?;
        lx.token("FIELD array data type")?;
        let count = lx.mul(ncomp, ntuples, aline, "FIELD array")?;
        let values = lx.numbers(count, &format!("FIELD array {name} value"))?;
        if let Some((n, target)) = keep.as_mut() {
            if ncomp == 1 && ntuples == *n {
                target.push((name.to_string(), values));
            }
        }
        if lx
            .peek()
            .is_some_and(|(t, _)| t.eq_ignore_ascii_case("METADATA"))
        {
            lx.skip_block_to_blank_line();
        }
    }
    Ok(())
}
