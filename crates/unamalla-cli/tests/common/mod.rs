//! Helpers shared by the CLI integration tests (each test file is its own crate and uses a
//! different subset, hence the `dead_code` allowance).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `unamalla` binary under test.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_unamalla"))
}

/// A bundled region file.
pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/regions")
        .join(name)
}

/// A fresh, empty scratch directory, unique per test file (`CARGO_CRATE_NAME` is the test
/// target's name), tag and process.
pub fn tmpdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "unamalla-{}-{tag}-{}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The `report.json` an output directory holds.
pub fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

/// Running a command that must succeed.
pub trait RunOk {
    /// Runs the command, asserts it exited successfully (its stderr in the failure message)
    /// and returns its output.
    fn run_ok(&mut self) -> Output;
}

impl RunOk for Command {
    fn run_ok(&mut self) -> Output {
        let out = self.output().unwrap();
        stdout_ok(&out);
        out
    }
}

/// Asserts that a finished command succeeded (its stderr in the failure message) and returns
/// its stdout.
pub fn stdout_ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}
