//! The facade: the main job through the crate root and the prelude, `Mesher` handed to another
//! thread, and `MeshResult::write_all` writing the whole file set at once.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use unamalla_core::prelude::*;

/// A 4 × 2 rectangle with a 1 × 0.5 hole: two holes' worth of patches (`outer`, `hole-1`).
fn plate() -> Region {
    let outer = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(4.0, 0.0),
        DVec2::new(4.0, 2.0),
        DVec2::new(0.0, 2.0),
    ];
    let hole = vec![
        DVec2::new(1.5, 0.75),
        DVec2::new(1.5, 1.25),
        DVec2::new(2.5, 1.25),
        DVec2::new(2.5, 0.75),
    ];
    Region::new(outer, vec![hole]).expect("valid plate")
}

/// A fresh scratch directory under the target directory (removed first if a previous run left
/// it).
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

fn listing(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .expect("readable")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect()
}

#[test]
fn a_configured_mesher_runs_on_another_thread_and_shows_its_settings() {
    let stages = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let seen = stages.clone();
    let mesher = Mesher::new()
        .cells(400)
        .on_progress(move |s, _| seen.lock().expect("not poisoned").push(s));
    let shown = format!("{mesher:?}");
    assert!(shown.contains("Cells(400)"), "{shown}");
    assert!(shown.contains("progress: Some(\"callback\")"), "{shown}");
    let result = std::thread::spawn(move || mesher.mesh(&plate()))
        .join()
        .expect("no panic")
        .expect("the plate meshes");
    assert_eq!(result.report.non_convex_cells, 0);
    assert_eq!(result.report.interior_singularities, 0);
    let stages = stages.lock().expect("not poisoned");
    assert_eq!(stages.first(), Some(&Stage::Simplify));
    assert!(stages.contains(&Stage::Smooth), "{stages:?}");
}

#[test]
fn write_all_writes_the_documented_set_and_leaves_the_target_alone_on_failure() {
    let result = Mesher::new().cells(400).mesh(&plate()).expect("meshes");
    let root = scratch("facade-write-all");
    let out = root.join("plate");
    let written = result
        .write_all(&out, &OutputOptions::default())
        .expect("written");

    // the set of the module docs' table: one .vts per block, the solver formats of the
    // default options, the decomposition, the pictures and the report
    let mut expected: BTreeSet<String> = (0..result.report.blocks)
        .map(|k| format!("block-{k}.vts"))
        .collect();
    for f in [
        "blocks.vtm",
        "mesh.vtu",
        "mesh.msh",
        "mesh.su2",
        "openfoam",
        "decomposition.json",
        "decomposition.svg",
        "mesh.svg",
        "mesh.png",
        "report.json",
    ] {
        expected.insert(f.to_string());
    }
    let returned: BTreeSet<String> = written
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    assert_eq!(returned, expected);
    let mut on_disk = listing(&out);
    // the marker of a committed output directory (what lets a later run replace it)
    assert!(on_disk.remove(unamalla_core::output::MARKER));
    assert_eq!(on_disk, expected);

    // report.json is the report; the VTK mesh reads back with the report's cell count
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("read"))
            .expect("JSON");
    assert_eq!(json["cells"].as_u64(), Some(result.report.cells as u64));
    let msh = std::fs::read_to_string(out.join("mesh.msh")).expect("read");
    assert!(msh.contains("\"outer\"") && msh.contains("\"hole-1\""));

    // a failing write (CGNS asked for in a build without it) leaves the old set in place
    if !cfg!(feature = "cgns") {
        let before = listing(&out);
        let err = result
            .write_all(
                &out,
                &OutputOptions::default().formats(true, true, true, true),
            )
            .expect_err("no CGNS in this build");
        assert!(matches!(err, CoreError::CgnsNotBuilt), "{err}");
        assert_eq!(listing(&out), before);
        assert_eq!(listing(&root), BTreeSet::from(["plate".to_string()]));
    }

    // a directory holding someone else's files is refused, not replaced
    let foreign = root.join("foreign");
    std::fs::create_dir_all(&foreign).expect("dir");
    std::fs::write(foreign.join("notes.txt"), "mine").expect("file");
    let err = result
        .write_all(&foreign, &OutputOptions::minimal())
        .expect_err("foreign directory");
    assert!(matches!(err, CoreError::Output(_)), "{err}");
    assert_eq!(listing(&foreign), BTreeSet::from(["notes.txt".to_string()]));
}
