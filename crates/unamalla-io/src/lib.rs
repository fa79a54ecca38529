//! # unamalla-io
//!
//! Region and mesh file formats of the unamalla crate family.
//!
//! | format | read | write | module |
//! |---|---|---|---|
//! | GeoJSON (RFC 7946) `Polygon` / `MultiPolygon` / `Feature` / `FeatureCollection` | regions | – | [`geojson`] |
//! | ESRI Shapefile, polygon shapes (5, 15, 25) | regions | regions (`.shp` + `.shx`) | [`shp`] |
//! | dBASE `.dbf` attribute tables (the shapefile's `--feature` selector) | records | – | [`dbf`] |
//! | UNAMALLA contour `.con` (`ibflag` 0/1/13/24, side counts) | contours, regions | contours | [`legacy`] |
//! | plain text rings (`x y` per line, blank line between rings) | regions | regions | [`rings`] |
//! | Gmsh MSH 4.1 ASCII: quads (3) / hexahedra (5), `$Entities`, `$PhysicalNames`, named boundary groups | yes | yes | [`msh`] |
//! | VTK XML `.vts` (one structured block, 2D or 3D) | yes | yes | [`vtk_xml`] |
//! | VTK XML `.vtu` (quads or hexahedra) | yes | yes | [`vtk_xml`] |
//! | VTK XML `.vtm` multiblock index; whole block meshes ([`write_block_mesh`]) | index | yes | [`vtk_xml`] |
//! | VTK legacy ASCII, `STRUCTURED_GRID` (2D and 3D) | yes | yes | [`vtk`] |
//! | VTK legacy ASCII, `UNSTRUCTURED_GRID` of quads (9) or hexahedra (12) | yes | yes | [`vtk`] |
//! | Plot3D multi-block grids, 2D and 3D, ASCII and Fortran-unformatted binary | yes | yes | [`plot3d`] |
//! | UNAMALLA XY and RED meshes | yes | yes | [`legacy`] |
//! | Geomview `MESH` surface | yes | yes | [`legacy`] |
//! | SU2 native `.su2` (quads, markers = boundary patches) | – | yes | [`solver`] |
//! | OpenFOAM `constant/polyMesh` (extruded one cell, `frontAndBack` empty, named patches) | – | yes | [`solver`] |
//! | CGNS structured multi-zone (zone per block, 1-to-1 connectivity, BCs by patch; feature `cgns`) | – | yes | `cgns` |
//! | OFF / Wavefront OBJ (quad meshes; hex meshes as boundary surfaces) | polygon surfaces | yes | [`surface`] |
//!
//! Every mesh writer takes per-cell arrays where the format has them (VTK legacy and XML: e.g.
//! quality metrics as `CellData`). Formats that store boundary groups (MSH) take them named;
//! [`boundary_edge_groups`] and [`hex_boundary_faces`] compute the boundary of a mesh.
//!
//! Independent checks with real readers live in `scripts/` and run from the tests when Python
//! has the package (otherwise the test prints "skipped: …" and passes): Gmsh's own API
//! (`check_msh_gmsh.py`, PyPI `gmsh`), meshio (`check_vtk_meshio.py`, `.vtk` and `.vtu`) and
//! VTK's XML readers (`check_vtk_xml_vtk.py`, PyPI `vtk`, `.vts`/`.vtu`/`.vtm`; meshio has no
//! `.vts` reader).
//!
//! Boundary-condition names ([`patches`]) come from GeoJSON properties or the library API and
//! are carried to every mesh output; longitude/latitude input is projected to a local
//! transverse Mercator in km ([`geo`]).
//!
//! ## Conventions
//!
//! * Regions come out as validated [`unamalla_mesh::Region`]s: outer ring counter-clockwise,
//!   holes clockwise, rings open. GeoJSON input may use either orientation; ring 0 of each
//!   polygon is the exterior, the others are holes; a 3rd coordinate is ignored. Which polygon
//!   of a multi-part document is used is chosen by a [`PartSelector`] (default: the largest).
//! * Meshes use the conventions of `unamalla-mesh`: 2D grids store node `(i, j)` at `j * m + i`,
//!   3D grids `(i, j, k)` at `(k * n + j) * m + i` (both are VTK's x-fastest order), quads are
//!   counter-clockwise, hexahedra are in VTK order. 2D meshes are written with `z = 0` and
//!   read back only if every `z` is 0.
//! * Numbers are written with the shortest decimal representation that round-trips, so
//!   write → read reproduces every `f64` bit for bit (binary Plot3D stores the bits).
//!
//! ## Errors
//!
//! Every function returns [`IoError`]. Errors caused by file content carry the file path (or
//! `<string>` for text parsed from memory) and a 1-based line number (text formats, malformed
//! JSON), a byte offset (binary Plot3D, Shapefile) or a JSON path (well-formed JSON with the wrong
//! content). No function panics on any input.
//!
//! ## Atomic writes
//!
//! Every writer goes through [`atomic_write`]: the data is written to a temporary file in the
//! target's directory, flushed and synced, then renamed over the target. On any error the
//! temporary file is removed and the target is untouched, so a target is never half-written.
//! Writers validate their input (e.g. one value per cell in every cell array) before touching
//! the file system.

//! ## Example
//!
//! ```
//! use unamalla_io::{parse_region_geojson, read_vtk, write_vtk_quads, PartSelector, VtkMesh};
//! use unamalla_mesh::{DVec2, QuadMesh};
//!
//! // A region: the outer ring may be clockwise, it is normalised.
//! let region = parse_region_geojson(
//!     r#"{"type": "Polygon", "coordinates": [[[0, 0], [0, 1], [2, 1], [2, 0], [0, 0]]]}"#,
//!     PartSelector::Largest,
//! )?;
//! assert_eq!(region.area(), 2.0);
//!
//! // A two-cell quad mesh with a cell array, written atomically and read back exactly.
//! let nodes = (0..6).map(|k| DVec2::new((k % 3) as f64, (k / 3) as f64)).collect();
//! let mesh = QuadMesh::new(nodes, vec![[0, 1, 4, 3], [1, 2, 5, 4]])?;
//! let path = std::env::temp_dir().join(format!("unamalla-io-doc-{}.vtk", std::process::id()));
//! write_vtk_quads(&path, &mesh, &[("quality", &[1.0, 0.5])])?;
//! let file = read_vtk(&path)?;
//! assert_eq!(file.mesh, VtkMesh::Quads(mesh));
//! assert_eq!(file.cell_array("quality"), Some(&[1.0, 0.5][..]));
//! # std::fs::remove_file(&path)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

// No unwrap/expect in library code: user input must give an error, never a panic (see
// docs/reliability.md). Tests may use them; a local `#[allow]` needs a comment naming the invariant.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod atomic;
#[cfg(feature = "cgns")]
pub mod cgns;
pub mod dbf;
pub mod error;
pub mod geo;
pub mod geojson;
pub mod input;
pub mod legacy;
pub mod msh;
pub mod patches;
pub mod plot3d;
pub mod rings;
pub mod shp;
pub mod solver;
pub mod surface;
pub mod vtk;
pub mod vtk_xml;

mod lex;
mod xml;

pub use atomic::atomic_write;
pub use error::IoError;
pub use geo::{looks_geographic, CrsChoice, LocalProjection};
pub use geojson::{
    parse_annotated_region_geojson, parse_polygon_parts, parse_region_geojson,
    parse_region_geojson_cleaned, parse_region_rings, read_annotated_region_geojson,
    read_region_geojson, read_region_geojson_cleaned, read_region_rings, region_to_geojson,
    write_region_geojson, PartSelector, PolygonRings, RegionAnnotations,
};
pub use input::{load_region, LoadOptions, LoadedRegion};
pub use legacy::{
    parse_con, parse_geomview_mesh, parse_red, parse_xy, read_con, read_geomview_mesh, read_red,
    read_region_con, read_xy, write_con, write_geomview_mesh, write_red, write_xy, Contour,
    GeomviewMesh, Ibflag, LegacyMesh,
};
pub use msh::{
    boundary_edge_groups, boundary_loops, hex_boundary_faces, parse_msh, read_msh,
    write_msh_blocks, write_msh_hexes, write_msh_quads, BoundaryLoop, EdgeGroup, FaceGroup,
    MshFile, MshMesh,
};
pub use patches::{named_edge_groups, BoundaryNames, Stretch};
pub use plot3d::{
    parse_plot3d_ascii, parse_plot3d_binary, read_plot3d, write_plot3d2, write_plot3d3,
    Plot3dBlocks, Plot3dDim, Plot3dFormat,
};
pub use rings::{
    parse_region_text, parse_rings_text, read_region_text, read_rings_text, write_region_text,
};
pub use shp::{
    encode_region_shapefile, parse_shapefile_parts, read_region_shapefile, read_shapefile_parts,
    write_region_shapefile,
};
pub use solver::{foam_mesh, su2_text, write_openfoam, write_su2, FoamMesh};
pub use surface::{
    parse_obj, parse_off, read_obj, read_off, write_obj_hexes, write_obj_quads, write_off_hexes,
    write_off_quads, SurfaceMesh,
};
pub use vtk::{
    parse_vtk, read_vtk, write_vtk_hexes, write_vtk_quads, write_vtk_quads_with_point_data,
    write_vtk_structured2, write_vtk_structured2_with_point_data, write_vtk_structured3, VtkFile,
    VtkMesh,
};
pub use vtk_xml::{
    parse_vtk_xml, read_vtk_xml, read_vtm, write_block_mesh, write_vtm, write_vts2, write_vts3,
    write_vtu_hexes, write_vtu_quads, BlockMeshFiles, VtmEntry,
};
