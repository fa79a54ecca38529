//! The VTK XML writers: `.vts`, `.vtu`, `.vtm` and a whole block mesh.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use unamalla_mesh::{
    BlockMesh2, DVec2, DVec3, HasHexCells, HasNodes, HasQuadCells, StructuredGrid2, StructuredGrid3,
};

use super::binary::{binary_array, f64_bytes, points_array, BINARY_THRESHOLD_POINTS};
use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::vtk::{check_cell_data, CellData, VTK_HEXAHEDRON, VTK_QUAD};
use crate::xml;

/// Values per line in ASCII data arrays (points are written one per line).
pub(super) const PER_LINE: usize = 6;

pub(super) fn head(w: &mut dyn Write, kind: &str) -> io::Result<()> {
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )
}

pub(super) fn values_line(w: &mut dyn Write, values: &[String]) -> io::Result<()> {
    for chunk in values.chunks(PER_LINE) {
        writeln!(w, "          {}", chunk.join(" "))?;
    }
    Ok(())
}

pub(super) fn data_array(
    w: &mut dyn Write,
    ty: &str,
    name: &str,
    values: &[String],
) -> io::Result<()> {
    writeln!(
        w,
        "        <DataArray type=\"{ty}\" Name=\"{}\" format=\"ascii\">",
        xml::escape(name)
    )?;
    values_line(w, values)?;
    writeln!(w, "        </DataArray>")
}

pub(super) fn cell_data_section(
    w: &mut dyn Write,
    cell_data: &CellData<'_>,
    binary: bool,
) -> io::Result<()> {
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

pub(super) fn lift(p: &DVec2) -> DVec3 {
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

/// Writes any quad mesh (a [`QuadMesh`](unamalla_mesh::QuadMesh), a structured grid, a [`BlockMesh2`], …) as a `.vtu`
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
