//! Same input and options → byte-identical output files, at any thread count. The mesher runs twice
//! in the default thread pool and once each in pools of 1 and 2 threads (what
//! `RAYON_NUM_THREADS=1|2` gives the CLI); every run writes `mesh.msh` and the files must be equal
//! byte for byte. Before the time budget was removed the smoothing stopped after 15 s of wall-clock
//! time and two identical runs differed (hippo: μ ≥ 0.8 95.11 % vs 95.01 %); the parallel dot
//! product also summed its chunk partials in rayon's order.

use std::path::{Path, PathBuf};

use unamalla_core::io::{self, PartSelector};
use unamalla_core::pipeline::Mesher;

fn region(name: &str) -> unamalla_core::mesh::Region {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/regions")
        .join(name);
    io::read_region_geojson(p, PartSelector::Largest).unwrap()
}

/// Meshes `name` with about `cells` cells and writes `mesh.msh` to a fresh directory; returns
/// the file's bytes and the smoother's status.
fn run(name: &str, cells: usize, tag: &str) -> (Vec<u8>, String) {
    let r = Mesher::new().cells(cells).mesh(&region(name)).unwrap();
    let dir: PathBuf = std::env::temp_dir().join(format!(
        "unamalla-determinism-{}-{name}-{tag}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("mesh.msh");
    let groups = io::msh::boundary_edge_groups(r.mesh.global());
    io::write_msh_quads(&path, r.mesh.global(), "domain", &groups).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    (bytes, r.report.smoothing)
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn the_mesh_file_is_byte_identical_across_runs_and_thread_counts() {
    // hippo: the region whose two runs differed under the time budget; puget-sound: holes and
    // many blocks (the global vectors are long enough for the parallel dot products)
    for (name, cells) in [("hippo.geojson", 6000), ("puget-sound.geojson", 8000)] {
        let (a, status) = run(name, cells, "a");
        assert!(
            !status.contains("by user") && !status.contains("TIME LIMIT"),
            "{name}: the default smoothing must end on convergence or a cap: {status}"
        );
        let (b, _) = run(name, cells, "b");
        let (one, _) = in_pool(1, || run(name, cells, "t1"));
        let (two, _) = in_pool(2, || run(name, cells, "t2"));
        assert!(a.len() > 1000, "{name}: a real mesh file");
        assert!(a == b, "{name}: two runs differ");
        assert!(a == one, "{name}: 1 thread differs from the default pool");
        assert!(a == two, "{name}: 2 threads differ from the default pool");
    }
}
