//! # unamalla-io
//!
//! Region and mesh file formats of the unamalla crate family.
//!
//! | format | read | write | module |
//! |---|---|---|---|
//! | GeoJSON (RFC 7946) `Polygon` / `MultiPolygon` / `Feature` / `FeatureCollection` | regions | – | [`geojson`] |
//! | VTK legacy ASCII, `STRUCTURED_GRID` (2D and 3D) | yes | yes | [`vtk`] |
//! | VTK legacy ASCII, `UNSTRUCTURED_GRID` of quads (9) or hexahedra (12) | yes | yes | [`vtk`] |
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
//!   write → read reproduces every `f64` bit for bit.
//!
//! ## Errors
//!
//! Every function returns [`IoError`]. Errors caused by file content carry the file path (or
//! `<string>` for text parsed from memory) and a 1-based line number (text formats, malformed
//! JSON) or a JSON path (well-formed JSON with the wrong content). No function panics on any
//! input.
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

#![warn(missing_docs)]

pub mod atomic;
pub mod error;
pub mod geojson;
pub mod vtk;

pub use atomic::atomic_write;
pub use error::IoError;
pub use geojson::{
    parse_polygon_parts, parse_region_geojson, parse_region_geojson_cleaned, parse_region_rings,
    read_region_geojson, read_region_geojson_cleaned, read_region_rings, PartSelector,
    PolygonRings,
};
pub use vtk::{
    parse_vtk, read_vtk, write_vtk_hexes, write_vtk_quads, write_vtk_structured2,
    write_vtk_structured3, VtkFile, VtkMesh,
};
