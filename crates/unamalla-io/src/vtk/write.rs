//! VTK legacy ASCII writers.

use std::collections::HashSet;
use std::io::{self, Write};
use std::path::Path;

use unamalla_mesh::{
    DVec2, DVec3, HasHexCells, HasNodes, HasQuadCells, StructuredGrid2, StructuredGrid3,
};

use crate::atomic::atomic_write;
use crate::error::IoError;

/// VTK cell type of a 4-node quadrilateral.
pub const VTK_QUAD: u8 = 9;
/// VTK cell type of an 8-node hexahedron.
pub const VTK_HEXAHEDRON: u8 = 12;

/// The first line every writer emits.
pub(crate) const HEADER: &str = "# vtk DataFile Version 3.0";
/// The title line every writer emits.
pub(crate) const TITLE: &str = "written by unamalla-io";

/// Named per-cell arrays: `(name, one value per cell)`.
pub type CellData<'a> = [(&'a str, &'a [f64])];

/// Named per-node arrays: `(name, one value per node)`.
pub type PointData<'a> = [(&'a str, &'a [f64])];

/// Writes a structured 2D grid as `DATASET STRUCTURED_GRID` with `DIMENSIONS m n 1` and `z = 0`
/// (node order `j * m + i`, which is VTK's x-fastest order), followed by the cell arrays.
pub fn write_vtk_structured2(
    path: impl AsRef<Path>,
    grid: &StructuredGrid2,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    write_vtk_structured2_with_point_data(path, grid, cell_data, &[])
}

/// [`write_vtk_structured2`] plus per-node arrays in a `POINT_DATA` section (e.g. a PDE
/// solution as the array `u`). Each point array must have one finite value per node and a
/// valid name (the rules of the cell arrays; the two sections are separate name spaces).
pub fn write_vtk_structured2_with_point_data(
    path: impl AsRef<Path>,
    grid: &StructuredGrid2,
    cell_data: &CellData<'_>,
    point_data: &PointData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    check_cell_data(path, grid.num_cells(), cell_data)?;
    check_point_data(path, grid.num_nodes(), point_data)?;
    atomic_write(path, |w| {
        write_head(w, "STRUCTURED_GRID")?;
        writeln!(w, "DIMENSIONS {} {} 1", grid.m(), grid.n())?;
        write_points2(w, grid.nodes())?;
        write_cell_data(w, grid.num_cells(), cell_data)?;
        write_point_data(w, grid.num_nodes(), point_data)
    })
}

/// [`write_vtk_quads`] plus per-node arrays in a `POINT_DATA` section (see
/// [`write_vtk_structured2_with_point_data`]).
pub fn write_vtk_quads_with_point_data<M: HasQuadCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    cell_data: &CellData<'_>,
    point_data: &PointData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    let nc = mesh.num_quads();
    check_cell_data(path, nc, cell_data)?;
    check_point_data(path, mesh.num_nodes(), point_data)?;
    atomic_write(path, |w| {
        write_head(w, "UNSTRUCTURED_GRID")?;
        write_points2(w, mesh.nodes())?;
        writeln!(w, "CELLS {nc} {}", nc * 5)?;
        for c in 0..nc {
            let [a, b, cc, d] = mesh.quad(c);
            writeln!(w, "4 {a} {b} {cc} {d}")?;
        }
        write_cell_types(w, nc, VTK_QUAD)?;
        write_cell_data(w, nc, cell_data)?;
        write_point_data(w, mesh.num_nodes(), point_data)
    })
}

/// Writes a structured 3D grid as `DATASET STRUCTURED_GRID` with `DIMENSIONS m n p`
/// (node order `(k * n + j) * m + i`), followed by the cell arrays.
pub fn write_vtk_structured3(
    path: impl AsRef<Path>,
    grid: &StructuredGrid3,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    check_cell_data(path, grid.num_cells(), cell_data)?;
    let (m, n, p) = grid.dims();
    atomic_write(path, |w| {
        write_head(w, "STRUCTURED_GRID")?;
        writeln!(w, "DIMENSIONS {m} {n} {p}")?;
        write_points3(w, grid.nodes())?;
        write_cell_data(w, grid.num_cells(), cell_data)
    })
}

/// Writes any quad mesh (a [`QuadMesh`](unamalla_mesh::QuadMesh), a structured grid, …) as
/// `DATASET UNSTRUCTURED_GRID` with `z = 0` and cell type 9, cells in the mesh's order.
pub fn write_vtk_quads<M: HasQuadCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    write_vtk_quads_with_point_data(path, mesh, cell_data, &[])
}

/// Writes any hex mesh as `DATASET UNSTRUCTURED_GRID` with cell type 12 (VTK vertex order,
/// which is the crate family's order), cells in the mesh's order.
pub fn write_vtk_hexes<M: HasHexCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    let nc = mesh.num_hexes();
    check_cell_data(path, nc, cell_data)?;
    atomic_write(path, |w| {
        write_head(w, "UNSTRUCTURED_GRID")?;
        write_points3(w, mesh.nodes())?;
        writeln!(w, "CELLS {nc} {}", nc * 9)?;
        for c in 0..nc {
            let h = mesh.hex(c);
            write!(w, "8")?;
            for v in h {
                write!(w, " {v}")?;
            }
            writeln!(w)?;
        }
        write_cell_types(w, nc, VTK_HEXAHEDRON)?;
        write_cell_data(w, nc, cell_data)
    })
}

/// Checks the cell arrays: one finite value per cell, and valid, distinct names.
///
/// Names must be non-empty printable ASCII without whitespace (VTK legacy separates tokens by
/// whitespace, so a name with a blank cannot be read back); they are rejected, never changed.
pub(crate) fn check_cell_data(
    path: &Path,
    num_cells: usize,
    cell_data: &CellData<'_>,
) -> Result<(), IoError> {
    check_arrays(path, Section::Cell, num_cells, cell_data)
}

/// The two data sections of a VTK legacy file (separate name spaces).
#[derive(Clone, Copy)]
enum Section {
    Cell,
    Point,
}

impl Section {
    fn keyword(self) -> &'static str {
        match self {
            Section::Cell => "CELL_DATA",
            Section::Point => "POINT_DATA",
        }
    }
}

/// One finite value per cell / node, and valid, distinct names (errors name the array and the
/// offending cell or node).
fn check_arrays(
    path: &Path,
    section: Section,
    len: usize,
    arrays: &[(&str, &[f64])],
) -> Result<(), IoError> {
    check_names(path, arrays)?;
    for &(name, values) in arrays {
        let (path, name) = (path.to_path_buf(), name.to_string());
        if values.len() != len {
            let (expected, found) = (len, values.len());
            return Err(match section {
                Section::Cell => IoError::CellDataLength {
                    path,
                    name,
                    expected,
                    found,
                },
                Section::Point => IoError::PointDataLength {
                    path,
                    name,
                    expected,
                    found,
                },
            });
        }
        if let Some((k, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(match section {
                Section::Cell => IoError::NonFiniteValue {
                    path,
                    name,
                    cell: k,
                    value,
                },
                Section::Point => IoError::NonFinitePointValue {
                    path,
                    name,
                    node: k,
                    value,
                },
            });
        }
    }
    Ok(())
}

/// Array names must be non-empty printable ASCII without whitespace and distinct.
fn check_names(path: &Path, arrays: &[(&str, &[f64])]) -> Result<(), IoError> {
    let mut seen = HashSet::new();
    for &(name, _) in arrays {
        let bad_name = |reason| IoError::InvalidArrayName {
            path: path.to_path_buf(),
            name: name.to_string(),
            reason,
        };
        if name.is_empty() {
            return Err(bad_name("it is empty"));
        }
        if !name.bytes().all(|b| b.is_ascii_graphic()) {
            return Err(bad_name(
                "it must be printable ASCII without whitespace (VTK legacy splits tokens on whitespace)",
            ));
        }
        if !seen.insert(name) {
            return Err(bad_name(
                "another array of the same section has the same name",
            ));
        }
    }
    Ok(())
}

/// Checks the point arrays: one finite value per node, valid and distinct names.
pub(crate) fn check_point_data(
    path: &Path,
    num_nodes: usize,
    point_data: &PointData<'_>,
) -> Result<(), IoError> {
    check_arrays(path, Section::Point, num_nodes, point_data)
}

fn write_point_data(w: &mut dyn Write, np: usize, point_data: &PointData<'_>) -> io::Result<()> {
    write_arrays(w, Section::Point, np, point_data)
}

fn write_head(w: &mut dyn Write, dataset: &str) -> io::Result<()> {
    writeln!(w, "{HEADER}")?;
    writeln!(w, "{TITLE}")?;
    writeln!(w, "ASCII")?;
    writeln!(w, "DATASET {dataset}")
}

/// Coordinates use Rust's `{:?}` formatting of `f64`: the shortest decimal string that parses
/// back to the same bits (e.g. `0.1`, `1e-7`, `-0.0`), which C `strtod` and numpy read exactly.
fn write_points2(w: &mut dyn Write, nodes: &[DVec2]) -> io::Result<()> {
    writeln!(w, "POINTS {} double", nodes.len())?;
    for p in nodes {
        writeln!(w, "{:?} {:?} 0", p.x, p.y)?;
    }
    Ok(())
}

fn write_points3(w: &mut dyn Write, nodes: &[DVec3]) -> io::Result<()> {
    writeln!(w, "POINTS {} double", nodes.len())?;
    for p in nodes {
        writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    Ok(())
}

fn write_cell_types(w: &mut dyn Write, nc: usize, ty: u8) -> io::Result<()> {
    writeln!(w, "CELL_TYPES {nc}")?;
    for _ in 0..nc {
        writeln!(w, "{ty}")?;
    }
    Ok(())
}

fn write_cell_data(w: &mut dyn Write, nc: usize, cell_data: &CellData<'_>) -> io::Result<()> {
    write_arrays(w, Section::Cell, nc, cell_data)
}

/// A `CELL_DATA` / `POINT_DATA` section of `double` scalars (nothing when there are none).
fn write_arrays(
    w: &mut dyn Write,
    section: Section,
    len: usize,
    arrays: &[(&str, &[f64])],
) -> io::Result<()> {
    if arrays.is_empty() {
        return Ok(());
    }
    writeln!(w, "{} {len}", section.keyword())?;
    for &(name, values) in arrays {
        writeln!(w, "SCALARS {name} double 1")?;
        writeln!(w, "LOOKUP_TABLE default")?;
        for v in values {
            writeln!(w, "{v:?}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::QuadMesh;

    use super::*;
    use crate::vtk::{read_vtk, VtkMesh};

    fn tmp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("unamalla-io-pd-{}-{name}", std::process::id()))
    }

    #[test]
    fn point_data_round_trips_on_structured_and_quads() {
        let g =
            StructuredGrid2::from_fn(3, 2, |i, j| DVec2::new(i as f64, 0.5 * j as f64)).unwrap();
        // u = x + 10 y at the nodes, in node order j·m + i
        let u: Vec<f64> = g.nodes().iter().map(|p| p.x + 10.0 * p.y).collect();
        let mu = [1.0, 0.5];
        let p = tmp("s.vtk");
        write_vtk_structured2_with_point_data(&p, &g, &[("mu", &mu)], &[("u", &u)]).unwrap();
        let f = read_vtk(&p).unwrap();
        assert_eq!(f.mesh, VtkMesh::Structured2(g.clone()));
        assert_eq!(f.point_array("u"), Some(&u[..]));
        assert_eq!(f.cell_array("mu"), Some(&mu[..]));
        std::fs::remove_file(&p).unwrap();

        let q = QuadMesh::from_grid(&g);
        let p = tmp("q.vtk");
        write_vtk_quads_with_point_data(&p, &q, &[], &[("u", &u)]).unwrap();
        let f = read_vtk(&p).unwrap();
        assert_eq!(f.point_array("u"), Some(&u[..]));
        std::fs::remove_file(&p).unwrap();
    }

    #[test]
    fn bad_point_data_is_rejected_before_writing() {
        let g = StructuredGrid2::from_fn(2, 2, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
        let p = tmp("bad.vtk");
        let e = write_vtk_structured2_with_point_data(&p, &g, &[], &[("u", &[1.0, 2.0])]);
        assert!(matches!(
            e,
            Err(IoError::PointDataLength {
                expected: 4,
                found: 2,
                ..
            })
        ));
        let e = write_vtk_structured2_with_point_data(
            &p,
            &g,
            &[],
            &[("u", &[1.0, f64::NAN, 0.0, 0.0])],
        );
        assert!(matches!(
            e,
            Err(IoError::NonFinitePointValue { node: 1, .. })
        ));
        let e = write_vtk_structured2_with_point_data(&p, &g, &[], &[("a b", &[0.0; 4])]);
        assert!(matches!(e, Err(IoError::InvalidArrayName { .. })));
        assert!(!p.exists());
    }
}
