//! Writing a [`MeshResult`]: the files of `unamalla mesh`, from the library.
//!
//! [`MeshResult::write_all`] writes the whole set into a directory that appears at once (staged
//! beside the target and renamed into place by [`OutputDir`], so a failure leaves the target as
//! it was); [`MeshResult::write_files`] writes the same files into an existing directory, each
//! one atomically (what a caller staging several results in one directory uses — the CLI does
//! for the parts of a MultiPolygon).
//!
//! The set, with [`OutputOptions::default`]:
//!
//! | file | content |
//! |---|---|
//! | `mesh.vtu` | the conformal quad mesh (VTK XML), cell arrays μ, scaled Jacobian, … ([`quad_cell_metrics`]) |
//! | `block-K.vts`, `blocks.vtm` | one structured grid per block and their multiblock index |
//! | `mesh.msh` | Gmsh 4.1: one surface per block, a named physical curve per boundary patch |
//! | `mesh.su2` | SU2 native mesh, one marker per patch |
//! | `openfoam/` | OpenFOAM `polyMesh`: the mesh extruded one cell thick, front/back `empty` |
//! | `decomposition.json`, `decomposition.svg` | the blocks (readable by `--decomposition`) |
//! | `mesh.svg`, `mesh.png` | quality pictures (μ ≥ 0.8 blue, 0.4–0.8 orange, below red) |
//! | `report.json` | the [`MeshReport`] |
//!
//! Optional: `mesh.cgns` (structured multi-zone CGNS; feature `cgns`), `mesh-lonlat.msh` (the
//! nodes back-projected to longitude/latitude, [`OutputOptions::lonlat`]), `rectilinear.json`
//! ([`OutputOptions::rectilinear`]). Boundary patches are the outer ring and the holes
//! (`outer`, `hole-K`) unless names are given ([`OutputOptions::patches`]).
//!
//! ```no_run
//! use unamalla_core::prelude::*;
//!
//! let region = unamalla_core::io::read_region_geojson(
//!     "fixtures/regions/puget-sound.geojson", Default::default())?;
//! let result = Mesher::new().cells(20_000).mesh(&region)?;
//! result.write_all("out/puget-sound", &OutputOptions::default())?;
//! # Ok::<(), unamalla_core::CoreError>(())
//! ```

use std::path::{Path, PathBuf};

use unamalla_io::{self as io, BoundaryNames, LocalProjection};
use unamalla_mesh::quality::quad_cell_metrics;
use unamalla_mesh::{HasNodes, QuadMesh, Region};

use crate::output::OutputDir;
use crate::pipeline::{MeshReport, MeshResult};
use crate::{render, CoreError};

/// Which files [`MeshResult::write_all`] writes besides the VTK files, the decomposition, the
/// pictures and `report.json` (always written). Build it from [`OutputOptions::default`] and
/// the setters; new options may be added in minor releases.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct OutputOptions<'a> {
    /// `mesh.msh` (Gmsh 4.1). Default on.
    pub msh: bool,
    /// `mesh.su2`. Default on.
    pub su2: bool,
    /// `openfoam/` (a `polyMesh` case). Default on.
    pub openfoam: bool,
    /// `mesh.cgns`. Default off; needs the crate feature `cgns` (system CGNS library), else
    /// [`CoreError::CgnsNotBuilt`].
    pub cgns: bool,
    /// Thickness of the OpenFOAM extrusion; `None`: the mean cell size `√(area / cells)`.
    pub thickness: Option<f64>,
    /// Named boundary patches: the input region the names refer to and the names
    /// ([`unamalla_io::named_edge_groups`]); `None`: `outer` and `hole-K`.
    pub patches: Option<(&'a Region, &'a BoundaryNames)>,
    /// Also write `mesh-lonlat.msh` with the nodes mapped back by this projection's inverse.
    pub lonlat: Option<&'a LocalProjection>,
    /// Also write `rectilinear.json` ([`unamalla_mesh::rectilinear::develop`], or the reason
    /// there is none).
    pub rectilinear: bool,
}

impl Default for OutputOptions<'_> {
    /// msh, su2 and OpenFOAM on; CGNS, lon/lat and rectilinear off; patches `outer`/`hole-K`.
    fn default() -> Self {
        Self {
            msh: true,
            su2: true,
            openfoam: true,
            cgns: false,
            thickness: None,
            patches: None,
            lonlat: None,
            rectilinear: false,
        }
    }
}

impl<'a> OutputOptions<'a> {
    /// Only the files written always (VTK, decomposition, pictures, report): no solver format.
    pub fn minimal() -> Self {
        Self {
            msh: false,
            su2: false,
            openfoam: false,
            ..Self::default()
        }
    }

    /// Sets which solver formats are written.
    pub fn formats(mut self, msh: bool, su2: bool, openfoam: bool, cgns: bool) -> Self {
        (self.msh, self.su2, self.openfoam, self.cgns) = (msh, su2, openfoam, cgns);
        self
    }

    /// Sets the OpenFOAM extrusion thickness ([`OutputOptions::thickness`]).
    pub fn thickness(mut self, t: Option<f64>) -> Self {
        self.thickness = t;
        self
    }

    /// Names the boundary patches ([`OutputOptions::patches`]).
    pub fn patches(mut self, input: &'a Region, names: &'a BoundaryNames) -> Self {
        self.patches = Some((input, names));
        self
    }

    /// Also writes `mesh-lonlat.msh` ([`OutputOptions::lonlat`]).
    pub fn lonlat(mut self, projection: Option<&'a LocalProjection>) -> Self {
        self.lonlat = projection;
        self
    }

    /// Also writes `rectilinear.json` ([`OutputOptions::rectilinear`]).
    pub fn rectilinear(mut self, yes: bool) -> Self {
        self.rectilinear = yes;
        self
    }
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), CoreError> {
    Ok(io::atomic_write(path, |w| w.write_all(bytes))?)
}

impl MeshResult {
    /// Writes the file set (see the [module docs](mod@crate::write)) into the directory `dir`,
    /// which appears with all files at once: it must be new, empty, or a previous output
    /// (replaced as a whole); on an error it is left as it was. Returns the written files'
    /// names relative to `dir`.
    pub fn write_all(
        &self,
        dir: impl AsRef<Path>,
        opts: &OutputOptions<'_>,
    ) -> Result<Vec<PathBuf>, CoreError> {
        let out = OutputDir::create(dir.as_ref())?;
        let files = self.write_files(out.path(), opts)?;
        out.commit()?;
        Ok(files)
    }

    /// Writes the file set into the existing (or new) directory `dir`, each file atomically
    /// but not as a set (use [`MeshResult::write_all`] for that). `report.json` is written
    /// from [`MeshResult::report`]. Returns the written files' names relative to `dir`.
    pub fn write_files(
        &self,
        dir: impl AsRef<Path>,
        opts: &OutputOptions<'_>,
    ) -> Result<Vec<PathBuf>, CoreError> {
        let dir = dir.as_ref();
        std::fs::create_dir_all(dir).map_err(|source| io::IoError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let mesh = &self.mesh;
        let mut written = Vec::new();
        let mut note = |name: &str| written.push(PathBuf::from(name));

        // VTK: one structured grid per block, the multiblock index, the conformal mesh
        let arrays = quad_cell_metrics(mesh.global());
        let global: Vec<(&str, &[f64])> = arrays.iter().map(|(k, v)| (*k, v.as_slice())).collect();
        let block_arrays: Vec<Vec<(&'static str, Vec<f64>)>> =
            mesh.blocks().iter().map(quad_cell_metrics).collect();
        let block_refs: Vec<Vec<(&str, &[f64])>> = block_arrays
            .iter()
            .map(|b| b.iter().map(|(k, v)| (*k, v.as_slice())).collect())
            .collect();
        let block_slices: Vec<&[(&str, &[f64])]> =
            block_refs.iter().map(|v| v.as_slice()).collect();
        io::write_block_mesh(dir, mesh, &block_slices, &global)?;
        for k in 0..mesh.blocks().len() {
            note(&format!("block-{k}.vts"));
        }
        note("blocks.vtm");
        note("mesh.vtu");

        // solver formats, with the boundary patches
        let groups = match opts.patches {
            Some((input, names)) if !names.is_empty() => {
                io::named_edge_groups(mesh.global(), input, names)?
            }
            _ => io::msh::boundary_edge_groups(mesh.global()),
        };
        if opts.msh {
            io::write_msh_blocks(dir.join("mesh.msh"), mesh, "domain", &groups)?;
            note("mesh.msh");
        }
        if opts.su2 {
            io::write_su2(dir.join("mesh.su2"), mesh.global(), &groups)?;
            note("mesh.su2");
        }
        if opts.openfoam {
            let cell_size = (self.simplified.area() / self.report.cells.max(1) as f64).sqrt();
            let t = opts.thickness.unwrap_or(cell_size);
            io::write_openfoam(dir.join("openfoam"), mesh.global(), &groups, t)?;
            note("openfoam");
        }
        if opts.cgns {
            #[cfg(feature = "cgns")]
            {
                io::cgns::write_cgns(dir.join("mesh.cgns"), mesh, &groups)?;
                note("mesh.cgns");
            }
            #[cfg(not(feature = "cgns"))]
            return Err(CoreError::CgnsNotBuilt);
        }
        if let Some(p) = opts.lonlat {
            let g = mesh.global();
            let ll = g
                .nodes()
                .iter()
                .map(|&q| p.inverse(q))
                .collect::<Result<Vec<_>, _>>()?;
            let back = QuadMesh::new(ll, g.cells().to_vec())?;
            io::write_msh_quads(dir.join("mesh-lonlat.msh"), &back, "domain", &groups)?;
            note("mesh-lonlat.msh");
        }

        // the decomposition, the pictures, the report
        let texts = [
            ("decomposition.json", self.decomposition.to_json()),
            (
                "decomposition.svg",
                self.decomposition.to_svg(&self.simplified),
            ),
            (
                "mesh.svg",
                render::quality_svg(mesh.global(), Some(&self.simplified), 1200.0),
            ),
        ];
        for (name, text) in texts {
            write_bytes(&dir.join(name), text.as_bytes())?;
            note(name);
        }
        let png = render::quality_png(mesh.global(), Some(&self.simplified), 1600)?;
        write_bytes(&dir.join("mesh.png"), &png)?;
        note("mesh.png");
        write_bytes(
            &dir.join("report.json"),
            report_json(&self.report)?.as_bytes(),
        )?;
        note("report.json");
        if opts.rectilinear {
            let value = match unamalla_mesh::rectilinear::develop(mesh) {
                Ok(r) => serde_json::to_value(&r)?,
                Err(e) => serde_json::json!({ "error": e.to_string() }),
            };
            write_bytes(
                &dir.join("rectilinear.json"),
                serde_json::to_string(&value)?.as_bytes(),
            )?;
            note("rectilinear.json");
        }
        Ok(written)
    }
}

/// `report.json`: the report as pretty-printed JSON (what [`MeshResult::write_files`] writes
/// and `unamalla mesh --json` prints).
pub fn report_json(report: &MeshReport) -> Result<String, CoreError> {
    Ok(serde_json::to_string_pretty(report)?)
}
