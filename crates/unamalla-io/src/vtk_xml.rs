//! VTK XML files: `.vts` (structured grid), `.vtu` (unstructured grid), `.vtm` (multiblock
//! index); ASCII data arrays, binary (base64) ones above [`BINARY_THRESHOLD_POINTS`] points.
//!
//! # Writing
//!
//! * [`write_vts2`] / [`write_vts3`]: one structured block as `<VTKFile type="StructuredGrid">`
//!   with `WholeExtent = Piece Extent = "0 m-1 0 n-1 0 p-1"` (`0 0` for `k` in 2D), points as
//!   a `Float64` array of 3 components in the grid's node order (i fastest, which is VTK's
//!   order; `z = 0` in 2D), cell arrays as `Float64` `<CellData>` arrays in cell order.
//! * [`write_vtu_quads`] / [`write_vtu_hexes`]: `<VTKFile type="UnstructuredGrid">` with
//!   `Int64` `connectivity` and `offsets` and `UInt8` `types` (9 = quad, 12 = hexahedron).
//! * [`write_vtm`]: a `vtkMultiBlockDataSet` index whose `<DataSet file="…">` entries are the
//!   given paths, written relative to the index (ParaView opens the index and loads them).
//! * [`write_block_mesh`]: a whole [`BlockMesh2`] in one call — `block-K.vts` per block,
//!   `blocks.vtm` indexing them and `mesh.vtu` for the global conformal mesh.
//!
//! Meshes with more than [`BINARY_THRESHOLD_POINTS`] points get binary data arrays.
//!
//! Every file is written atomically ([`crate::atomic_write`]); cell arrays are validated first
//! exactly like the legacy writers do (one finite value per cell, printable ASCII names without
//! whitespace, no duplicates). Numbers use the shortest round-trip representation, so a
//! write/read round trip is bit-exact.
//!
//! # Reading
//!
//! [`read_vtk_xml`] / [`parse_vtk_xml`] read `.vts` and `.vtu` files in ASCII format (the subset
//! the writers produce, and what VTK/ParaView/meshio write with `format="ascii"`) into the same
//! [`VtkFile`] the legacy reader returns (its `title` is empty). One `<Piece>` whose extent is
//! the whole extent; unstructured grids of all quads or all hexahedra. Binary data arrays
//! (`format="binary"`: base64, uncompressed, `UInt64` or `UInt32` header — what the writers
//! produce above the threshold and VTK/meshio write with `binary`) are read too; `appended`
//! and compressed arrays are reported as [`IoError::Unsupported`]. [`read_vtm`] lists the data sets of a
//! `.vtm`, resolved against its directory. Errors carry 1-based line numbers.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use unamalla_mesh::{
    BlockMesh2, DVec2, DVec3, HasHexCells, HasNodes, HasQuadCells, HexMesh, QuadMesh,
    StructuredGrid2, StructuredGrid3,
};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::{read_text, STRING_SOURCE};
use crate::lex::{Lexer, MAX_PREALLOC};
use crate::vtk::{check_cell_data, CellData, VtkFile, VtkMesh, VTK_HEXAHEDRON, VTK_QUAD};
use crate::xml::{self, Element};

/// Values per line in ASCII data arrays (points are written one per line).
const PER_LINE: usize = 6;

fn head(w: &mut dyn Write, kind: &str) -> io::Result<()> {
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )
}

/// Meshes with more points than this are written with binary data arrays
/// (`format="binary"`: base64 of a `UInt64` byte count, then base64 of the little-endian
/// values, encoded separately as VTK and meshio do), smaller ones in ASCII. Both read back bit
/// for bit (sizes measured in `docs/solvers-and-gis.md`).
pub const BINARY_THRESHOLD_POINTS: usize = 10_000;

/// Base64 text of a binary data array: the 8-byte little-endian byte count, then the bytes,
/// each encoded separately.
fn binary_text(bytes: &[u8]) -> String {
    use base64::Engine as _;
    let e = &base64::engine::general_purpose::STANDARD;
    let mut s = e.encode((bytes.len() as u64).to_le_bytes());
    s.push_str(&e.encode(bytes));
    s
}

fn f64_bytes(v: impl Iterator<Item = f64>) -> Vec<u8> {
    v.flat_map(f64::to_le_bytes).collect()
}

fn binary_array(
    w: &mut dyn Write,
    ty: &str,
    name: &str,
    comps: usize,
    bytes: &[u8],
) -> io::Result<()> {
    let nc = if comps > 1 {
        format!(" NumberOfComponents=\"{comps}\"")
    } else {
        String::new()
    };
    writeln!(
        w,
        "        <DataArray type=\"{ty}\" Name=\"{}\"{nc} format=\"binary\">",
        xml::escape(name)
    )?;
    writeln!(w, "          {}", binary_text(bytes))?;
    writeln!(w, "        </DataArray>")
}

fn points_array(
    w: &mut dyn Write,
    pts: impl Iterator<Item = DVec3>,
    binary: bool,
) -> io::Result<()> {
    writeln!(w, "      <Points>")?;
    if binary {
        let bytes = f64_bytes(pts.flat_map(|p| [p.x, p.y, p.z]));
        binary_array(w, "Float64", "Points", 3, &bytes)?;
        return writeln!(w, "      </Points>");
    }
    writeln!(
        w,
        "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">"
    )?;
    for p in pts {
        writeln!(w, "          {:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(w, "      </Points>")
}

fn values_line(w: &mut dyn Write, values: &[String]) -> io::Result<()> {
    for chunk in values.chunks(PER_LINE) {
        writeln!(w, "          {}", chunk.join(" "))?;
    }
    Ok(())
}

fn data_array(w: &mut dyn Write, ty: &str, name: &str, values: &[String]) -> io::Result<()> {
    writeln!(
        w,
        "        <DataArray type=\"{ty}\" Name=\"{}\" format=\"ascii\">",
        xml::escape(name)
    )?;
    values_line(w, values)?;
    writeln!(w, "        </DataArray>")
}

fn cell_data_section(w: &mut dyn Write, cell_data: &CellData<'_>, binary: bool) -> io::Result<()> {
    if cell_data.is_empty() {
        return Ok(());
    }
    writeln!(w, "      <CellData>")?;
    for &(name, values) in cell_data {
        if binary {
            binary_array(w, "Float64", name, 1, &f64_bytes(values.iter().copied()))?;
        } else {
            let v: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
            data_array(w, "Float64", name, &v)?;
        }
    }
    writeln!(w, "      </CellData>")
}

fn lift(p: &DVec2) -> DVec3 {
    DVec3::new(p.x, p.y, 0.0)
}

/// Writes a structured 2D grid as a `.vts` file (`z = 0`, extent `0 m-1 0 n-1 0 0`).
pub fn write_vts2(
    path: impl AsRef<Path>,
    grid: &StructuredGrid2,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    check_cell_data(path, grid.num_cells(), cell_data)?;
    let ext = format!("0 {} 0 {} 0 0", grid.m() - 1, grid.n() - 1);
    atomic_write(path, |w| {
        write_vts_body(w, &ext, grid.nodes().iter().map(lift), cell_data)
    })
}

/// Writes a structured 3D grid as a `.vts` file (extent `0 m-1 0 n-1 0 p-1`).
pub fn write_vts3(
    path: impl AsRef<Path>,
    grid: &StructuredGrid3,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    check_cell_data(path, grid.num_cells(), cell_data)?;
    let (m, n, p) = grid.dims();
    let ext = format!("0 {} 0 {} 0 {}", m - 1, n - 1, p - 1);
    atomic_write(path, |w| {
        write_vts_body(w, &ext, grid.nodes().iter().copied(), cell_data)
    })
}

fn write_vts_body(
    w: &mut dyn Write,
    ext: &str,
    pts: impl ExactSizeIterator<Item = DVec3>,
    cell_data: &CellData<'_>,
) -> io::Result<()> {
    let binary = pts.len() > BINARY_THRESHOLD_POINTS;
    head(w, "StructuredGrid")?;
    writeln!(w, "  <StructuredGrid WholeExtent=\"{ext}\">")?;
    writeln!(w, "    <Piece Extent=\"{ext}\">")?;
    cell_data_section(w, cell_data, binary)?;
    points_array(w, pts, binary)?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </StructuredGrid>")?;
    writeln!(w, "</VTKFile>")
}

/// Writes any quad mesh (a [`QuadMesh`], a structured grid, a [`BlockMesh2`], …) as a `.vtu`
/// file of VTK quads (type 9), `z = 0`, cells in the mesh's order.
pub fn write_vtu_quads<M: HasQuadCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    let nc = mesh.num_quads();
    check_cell_data(path, nc, cell_data)?;
    atomic_write(path, |w| {
        write_vtu_body(
            w,
            mesh.nodes().iter().map(lift),
            mesh.num_nodes(),
            nc,
            4,
            VTK_QUAD,
            &mut |c| mesh.quad(c).to_vec(),
            cell_data,
        )
    })
}

/// Writes any hex mesh as a `.vtu` file of VTK hexahedra (type 12, VTK vertex order).
pub fn write_vtu_hexes<M: HasHexCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    let nc = mesh.num_hexes();
    check_cell_data(path, nc, cell_data)?;
    atomic_write(path, |w| {
        write_vtu_body(
            w,
            mesh.nodes().iter().copied(),
            mesh.num_nodes(),
            nc,
            8,
            VTK_HEXAHEDRON,
            &mut |c| mesh.hex(c).to_vec(),
            cell_data,
        )
    })
}

#[allow(clippy::too_many_arguments)]
fn write_vtu_body(
    w: &mut dyn Write,
    pts: impl Iterator<Item = DVec3>,
    np: usize,
    nc: usize,
    nv: usize,
    ty: u8,
    cell: &mut dyn FnMut(usize) -> Vec<usize>,
    cell_data: &CellData<'_>,
) -> io::Result<()> {
    head(w, "UnstructuredGrid")?;
    writeln!(w, "  <UnstructuredGrid>")?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">"
    )?;
    let binary = np > BINARY_THRESHOLD_POINTS;
    cell_data_section(w, cell_data, binary)?;
    points_array(w, pts, binary)?;
    writeln!(w, "      <Cells>")?;
    if binary {
        let conn: Vec<u8> = (0..nc)
            .flat_map(cell)
            .flat_map(|v| (v as i64).to_le_bytes())
            .collect();
        binary_array(w, "Int64", "connectivity", 1, &conn)?;
        let offsets: Vec<u8> = (1..=nc)
            .flat_map(|c| ((c * nv) as i64).to_le_bytes())
            .collect();
        binary_array(w, "Int64", "offsets", 1, &offsets)?;
        binary_array(w, "UInt8", "types", 1, &vec![ty; nc])?;
    } else {
        writeln!(
            w,
            "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
        )?;
        for c in 0..nc {
            let ids: Vec<String> = cell(c).iter().map(|v| v.to_string()).collect();
            writeln!(w, "          {}", ids.join(" "))?;
        }
        writeln!(w, "        </DataArray>")?;
        let offsets: Vec<String> = (1..=nc).map(|c| (c * nv).to_string()).collect();
        data_array(w, "Int64", "offsets", &offsets)?;
        let types: Vec<String> = (0..nc).map(|_| ty.to_string()).collect();
        data_array(w, "UInt8", "types", &types)?;
    }
    writeln!(w, "      </Cells>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")
}

/// Writes a `.vtm` multiblock index. Each entry is `(name, file)`; `file` is written as given
/// (use paths relative to the index's directory, e.g. `block-0.vts`, so the set can be moved).
/// Names and files are XML-escaped; a file path must be valid UTF-8 and must not be empty.
pub fn write_vtm(path: impl AsRef<Path>, entries: &[(&str, &Path)]) -> Result<(), IoError> {
    let path = path.as_ref();
    let mut files = Vec::with_capacity(entries.len());
    for (name, f) in entries {
        let s = f
            .to_str()
            .filter(|s| !s.is_empty())
            .ok_or_else(|| IoError::Unrepresentable {
                path: path.to_path_buf(),
                reason: format!("data set {name:?}: file path {f:?} is empty or not UTF-8"),
            })?;
        files.push((xml::escape(name), xml::escape(s)));
    }
    atomic_write(path, |w| {
        head(w, "vtkMultiBlockDataSet")?;
        writeln!(w, "  <vtkMultiBlockDataSet>")?;
        for (k, (name, file)) in files.iter().enumerate() {
            writeln!(
                w,
                "    <DataSet index=\"{k}\" name=\"{name}\" file=\"{file}\"/>"
            )?;
        }
        writeln!(w, "  </vtkMultiBlockDataSet>")?;
        writeln!(w, "</VTKFile>")
    })
}

/// The files [`write_block_mesh`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockMeshFiles {
    /// `dir/mesh.vtu`: the global conformal mesh.
    pub global: PathBuf,
    /// `dir/block-K.vts` for every block `K` (0-based).
    pub blocks: Vec<PathBuf>,
    /// `dir/blocks.vtm`: the multiblock index of the block files.
    pub index: PathBuf,
}

/// Writes a block-structured mesh into the existing directory `dir`: `block-K.vts` for every
/// block (with `block_cell_data[K]`), `blocks.vtm` referencing them relatively, and `mesh.vtu`
/// for the global conformal mesh (with `global_cell_data`).
///
/// `block_cell_data` must be empty (no block arrays) or have one entry per block. All arrays
/// are validated before any file is written; each file is then written atomically (block
/// files first, then the index, then the global mesh).
pub fn write_block_mesh(
    dir: impl AsRef<Path>,
    mesh: &BlockMesh2,
    block_cell_data: &[&CellData<'_>],
    global_cell_data: &CellData<'_>,
) -> Result<BlockMeshFiles, IoError> {
    let dir = dir.as_ref();
    let blocks = mesh.blocks();
    let global = dir.join("mesh.vtu");
    let index = dir.join("blocks.vtm");
    let names: Vec<String> = (0..blocks.len()).map(|k| format!("block-{k}")).collect();
    let files: Vec<PathBuf> = names
        .iter()
        .map(|n| PathBuf::from(format!("{n}.vts")))
        .collect();
    let block_paths: Vec<PathBuf> = files.iter().map(|f| dir.join(f)).collect();
    if !block_cell_data.is_empty() && block_cell_data.len() != blocks.len() {
        return Err(IoError::Unrepresentable {
            path: index,
            reason: format!(
                "{} block cell-array lists for {} blocks (give none or one per block)",
                block_cell_data.len(),
                blocks.len()
            ),
        });
    }
    let empty: &CellData<'_> = &[];
    let data_of = |k: usize| block_cell_data.get(k).copied().unwrap_or(empty);
    for (k, b) in blocks.iter().enumerate() {
        check_cell_data(&block_paths[k], b.num_cells(), data_of(k))?;
    }
    check_cell_data(&global, mesh.num_quads(), global_cell_data)?;
    for (k, b) in blocks.iter().enumerate() {
        write_vts2(&block_paths[k], b, data_of(k))?;
    }
    let entries: Vec<(&str, &Path)> = names
        .iter()
        .zip(&files)
        .map(|(n, f)| (n.as_str(), f.as_path()))
        .collect();
    write_vtm(&index, &entries)?;
    write_vtu_quads(&global, mesh.global(), global_cell_data)?;
    Ok(BlockMeshFiles {
        global,
        blocks: block_paths,
        index,
    })
}

// ---------------------------------------------------------------------------------------------
// Reading

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

/// Reads a `.vts` or `.vtu` file (ASCII or binary data arrays) — see the [module docs](self).
pub fn read_vtk_xml(path: impl AsRef<Path>) -> Result<VtkFile, IoError> {
    let path = path.as_ref();
    let text = read_text(path)?;
    parse_at(&text, path)
}

/// Like [`read_vtk_xml`], for text held in memory (errors name `<string>`).
pub fn parse_vtk_xml(text: &str) -> Result<VtkFile, IoError> {
    parse_at(text, Path::new(STRING_SOURCE))
}

fn missing(path: &Path, e: &Element, what: &str) -> IoError {
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
fn array_values(e: &Element, count: usize, path: &Path) -> Result<Vec<f64>, IoError> {
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

/// Whether a `<DataArray>` is binary (`format="binary"`, uncompressed); other formats than
/// `ascii` and `binary`, and compressed data, are unsupported.
fn is_binary(e: &Element, path: &Path) -> Result<bool, IoError> {
    match e.attr("format") {
        None | Some("ascii") => Ok(false),
        Some("binary") => Ok(true),
        Some(f) => Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: e.line,
            what: format!("DataArray format {f:?} (ascii and binary are read)"),
        }),
    }
}

/// The values of a binary `<DataArray>` as `f64`: its base64 text decoded (a `UInt64` or
/// `UInt32` byte count encoded separately, then the data), the data read per its `type`.
fn binary_values(e: &Element, path: &Path) -> Result<Vec<f64>, IoError> {
    use base64::Engine as _;
    let eng = &base64::engine::general_purpose::STANDARD;
    let name = e.attr("Name").unwrap_or("(unnamed)");
    let bad = |m: String| IoError::Malformed {
        path: path.to_path_buf(),
        line: e.text_line,
        message: format!("DataArray {name}: {m}"),
    };
    let text: String = e.text.split_whitespace().collect();
    // header: 8 bytes (12 base64 characters) or 4 bytes (8 characters), whichever states the
    // length of the rest
    let mut data = None;
    for (chars, size) in [(12usize, 8usize), (8, 4)] {
        if text.len() < chars {
            continue;
        }
        let (Ok(h), Ok(d)) = (eng.decode(&text[..chars]), eng.decode(&text[chars..])) else {
            continue;
        };
        if h.len() != size {
            continue;
        }
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(&h);
        if u64::from_le_bytes(b) == d.len() as u64 {
            data = Some(d);
            break;
        }
    }
    let d =
        data.ok_or_else(|| bad("binary data is not base64 of a byte count and the data".into()))?;
    let ty = e.attr("type").unwrap_or("");
    let width = match ty {
        "Float64" | "Int64" | "UInt64" => 8,
        "Float32" | "Int32" | "UInt32" => 4,
        "Int16" | "UInt16" => 2,
        "Int8" | "UInt8" => 1,
        other => return Err(bad(format!("unsupported binary type {other:?}"))),
    };
    if d.len() % width != 0 {
        return Err(bad(format!(
            "{} bytes is not a whole number of {ty}",
            d.len()
        )));
    }
    Ok(d.chunks_exact(width)
        .map(|c| {
            let mut b = [0u8; 8];
            b[..width].copy_from_slice(c);
            match ty {
                "Float64" => f64::from_le_bytes(b),
                "Float32" => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                "Int64" => i64::from_le_bytes(b) as f64,
                "Int32" => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                "Int16" => i16::from_le_bytes([b[0], b[1]]) as f64,
                "Int8" => b[0] as i8 as f64,
                _ => u64::from_le_bytes(b) as f64,
            }
        })
        .collect())
}

fn components(e: &Element, path: &Path) -> Result<usize, IoError> {
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

#[cfg(test)]
mod binary_tests {
    use super::*;

    #[test]
    fn a_large_grid_is_written_binary_and_reads_back_bit_for_bit() {
        // 120 × 100 nodes = 12 000 > threshold; irrational coordinates test every bit
        let g = StructuredGrid2::from_fn(120, 100, |i, j| {
            DVec2::new(
                (i as f64).sqrt() + 0.1 * j as f64,
                (j as f64) / 3.0 + 1e-7 * i as f64,
            )
        })
        .unwrap();
        let dir = std::env::temp_dir().join(format!("unamalla-vtkbin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cells: Vec<f64> = (0..g.num_cells()).map(|c| (c as f64).ln_1p()).collect();
        let data: &[(&str, &[f64])] = &[("q", &cells)];
        write_vts2(dir.join("g.vts"), &g, data).unwrap();
        let q = QuadMesh::from_grid(&g);
        write_vtu_quads(dir.join("g.vtu"), &q, data).unwrap();
        let vts = std::fs::read_to_string(dir.join("g.vts")).unwrap();
        assert!(vts.contains("format=\"binary\"") && !vts.contains("format=\"ascii\""));
        let back = read_vtk_xml(dir.join("g.vts")).unwrap();
        assert_eq!(back.mesh, VtkMesh::Structured2(g.clone()));
        assert_eq!(back.cell_array("q"), Some(&cells[..]));
        let back = read_vtk_xml(dir.join("g.vtu")).unwrap();
        assert_eq!(back.mesh, VtkMesh::Quads(q));
        // binary is smaller than ASCII of the same data: 8 bytes per value × 4/3 base64 vs
        // up to 20 decimal characters
        let small = StructuredGrid2::from_fn(120, 83, |i, j| g.node(i, j)).unwrap();
        assert!(small.num_nodes() <= BINARY_THRESHOLD_POINTS);
        let scells: Vec<f64> = (0..small.num_cells()).map(|c| (c as f64).ln_1p()).collect();
        write_vts2(dir.join("s.vts"), &small, &[("q", &scells)]).unwrap();
        let ascii_per_node =
            std::fs::metadata(dir.join("s.vts")).unwrap().len() as f64 / small.num_nodes() as f64;
        let bin_per_node = vts.len() as f64 / g.num_nodes() as f64;
        assert!(
            bin_per_node < 0.75 * ascii_per_node,
            "{bin_per_node} vs {ascii_per_node}"
        );
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn a_uint32_header_is_read_and_a_wrong_count_is_an_error() {
        use base64::Engine as _;
        let e = &base64::engine::general_purpose::STANDARD;
        let pts: Vec<u8> = [
            0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0,
        ]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
        let enc =
            |b: &[u8], header: u32| format!("{}{}", e.encode(header.to_le_bytes()), e.encode(b));
        let doc = |header: u32| {
            format!(
                r#"<?xml version="1.0"?><VTKFile type="StructuredGrid" version="1.0" byte_order="LittleEndian">
<StructuredGrid WholeExtent="0 1 0 1 0 0"><Piece Extent="0 1 0 1 0 0"><Points>
<DataArray type="Float64" NumberOfComponents="3" format="binary">{}</DataArray>
</Points></Piece></StructuredGrid></VTKFile>"#,
                enc(&pts, header)
            )
        };
        let f = parse_vtk_xml(&doc(96)).unwrap();
        assert_eq!(f.mesh.num_nodes(), 4);
        let err = parse_vtk_xml(&doc(95)).unwrap_err().to_string();
        assert!(err.contains("not base64 of a byte count"), "{err}");
    }
}
