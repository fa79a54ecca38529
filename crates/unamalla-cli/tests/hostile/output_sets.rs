//! Output-set faults: stale files, a foreign directory, a file in the way, concurrent runs,
//! `kill -9` during writing, read-only and full disks.

use unamalla_core::io;

use crate::common;
use crate::common::{fixture, tmpdir};
use crate::harness::{bin, check_mesh_dir, hostile, names};

/// Output-set faults: stale files, a foreign directory, a file in the way, read-only and full
/// disks, concurrent runs, kill -9 during writing.
#[test]
fn output_sets_are_whole_or_absent() {
    let d = tmpdir("sets");
    let out = d.join("out");
    let tx = fixture("texas.geojson");
    // 1. a run with many blocks, then one with fewer: no stale block files
    let r = bin()
        .arg("mesh")
        .arg(&tx)
        .args(["--cells", "3000", "--crs", "planar", "--quiet", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let first = names(&out);
    let sq = hostile("square.geojson");
    let r = bin()
        .arg("mesh")
        .arg(&sq)
        .args(["--cells", "100", "--crs", "planar", "--quiet", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let second = names(&out);
    assert!(first.len() > second.len(), "{first:?} vs {second:?}");
    check_mesh_dir(&out, &sq, false).unwrap();
    assert_eq!(names(&d), vec!["out"]);
    // 2. a failing run leaves the previous set untouched
    let before = std::fs::read(out.join("report.json")).unwrap();
    let r = bin()
        .arg("mesh")
        .arg(hostile("hole-1e-9.geojson"))
        .args(["--cells", "100", "--crs", "planar", "--quiet", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(1));
    assert_eq!(std::fs::read(out.join("report.json")).unwrap(), before);
    assert_eq!(names(&out), second);
    // 3. a directory with foreign files is refused and kept
    let foreign = d.join("mine");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join("thesis.tex"), "x").unwrap();
    let r = bin()
        .arg("mesh")
        .arg(&sq)
        .args(["--cells", "100", "--crs", "planar", "-o"])
        .arg(&foreign)
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(4));
    assert!(String::from_utf8_lossy(&r.stderr).contains("thesis.tex"));
    assert_eq!(names(&foreign), vec!["thesis.tex"]);
    // 4. a file where the directory should go
    let file = d.join("file");
    std::fs::write(&file, "x").unwrap();
    let r = bin()
        .arg("mesh")
        .arg(&sq)
        .args(["--cells", "100", "--crs", "planar", "-o"])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(4));
    assert!(String::from_utf8_lossy(&r.stderr).contains("not a directory"));
    // 5. concurrent runs into one directory: one whole set
    let conc = d.join("conc");
    let kids: Vec<_> = [("600", &tx), ("150", &sq), ("300", &tx), ("80", &sq)]
        .iter()
        .map(|(cells, r)| {
            bin()
                .arg("mesh")
                .arg(r)
                .args(["--cells", cells, "--crs", "planar", "--quiet", "-o"])
                .arg(&conc)
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    for mut k in kids {
        assert!(k.wait().unwrap().success());
    }
    let rep = common::report(&conc);
    let cells = rep["cells"].as_u64().unwrap() as usize;
    let f = io::read_vtk_xml(conc.join("mesh.vtu")).unwrap();
    assert_eq!(
        f.mesh.num_cells(),
        cells,
        "report.json and mesh.vtu of one run"
    );
    let vtm = std::fs::read_to_string(conc.join("blocks.vtm")).unwrap();
    for b in names(&conc).iter().filter(|f| f.starts_with("block-")) {
        assert!(vtm.contains(b.as_str()), "{b} stale");
    }
    let leftovers: Vec<_> = names(&d)
        .into_iter()
        .filter(|n| n.contains(".unamalla-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let _ = std::fs::remove_dir_all(&d);
}

/// kill -9 at several moments of a run that replaces an existing set: the target is always the
/// old set or the new one, whole; the next run removes the dead run's staging directory.
#[test]
fn kill_during_writing_leaves_a_whole_set() {
    let d = tmpdir("kill");
    let out = d.join("out");
    let sq = hostile("square.geojson");
    let tx = fixture("texas.geojson");
    let r = bin()
        .arg("mesh")
        .arg(&sq)
        .args(["--cells", "100", "--crs", "planar", "--quiet", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(r.status.success());
    let old = names(&out);
    let old_report = std::fs::read(out.join("report.json")).unwrap();
    for ms in [50u64, 200, 500, 900, 1400, 2000, 3000] {
        let mut k = bin()
            .arg("mesh")
            .arg(&tx)
            .args(["--cells", "2000", "--crs", "planar", "--quiet", "-o"])
            .arg(&out)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(ms));
        let _ = k.kill(); // SIGKILL
        let _ = k.wait();
        let now = names(&out);
        if now == old {
            assert_eq!(std::fs::read(out.join("report.json")).unwrap(), old_report);
        } else {
            // the new set, whole
            if let Err(e) = check_mesh_dir(&out, &tx, false) {
                panic!("after {ms} ms: {now:?}: {e}");
            }
            let rep = common::report(&out);
            let f = io::read_vtk_xml(out.join("mesh.vtu")).unwrap();
            assert_eq!(f.mesh.num_cells() as u64, rep["cells"].as_u64().unwrap());
        }
    }
    // the next run cleans up the orphans of the killed runs
    let r = bin()
        .arg("mesh")
        .arg(&sq)
        .args(["--cells", "100", "--crs", "planar", "--quiet", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(r.status.success());
    let leftovers: Vec<_> = names(&d)
        .into_iter()
        .filter(|n| n.contains(".unamalla-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A full disk (a 256 KiB tmpfs) and a read-only directory (a read-only tmpfs): exit 4, the
/// error names the target, nothing partial. Needs permission to mount; skipped with a message
/// otherwise.
#[test]
fn full_and_read_only_disks() {
    let d = tmpdir("disk");
    let full = d.join("full");
    std::fs::create_dir(&full).unwrap();
    let mounted = std::process::Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=256k", "tmpfs"])
        .arg(&full)
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !mounted {
        eprintln!("note: cannot mount a tmpfs here (not permitted); disk-full case skipped");
        return;
    }
    let out = full.join("out");
    let r = bin()
        .arg("mesh")
        .arg(fixture("texas.geojson"))
        .args(["--cells", "3000", "--crs", "planar", "--quiet", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    let listing = names(&full);
    let _ = std::process::Command::new("umount").arg(&full).status();
    assert_eq!(r.status.code(), Some(4), "{err}");
    assert!(
        err.contains("No space left") || err.contains("space"),
        "{err}"
    );
    assert!(err.contains("/full/out"), "{err}");
    assert!(listing.is_empty(), "{listing:?}");

    let ro = d.join("ro");
    std::fs::create_dir(&ro).unwrap();
    let ok = std::process::Command::new("mount")
        .args(["-t", "tmpfs", "-o", "ro,size=64k", "tmpfs"])
        .arg(&ro)
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if ok {
        let r = bin()
            .arg("tfi")
            .arg(fixture("colorado.geojson"))
            .args(["--size", "10x10", "-o"])
            .arg(ro.join("g.vtk"))
            .output()
            .unwrap();
        let _ = std::process::Command::new("umount").arg(&ro).status();
        assert_eq!(r.status.code(), Some(4));
        assert!(String::from_utf8_lossy(&r.stderr).contains("g.vtk"));
    }
    let _ = std::fs::remove_dir_all(&d);
}
