//! The hostile-input catalogue (`docs/reliability.md`, "The hostile catalogue"), run through the
//! `unamalla` binary (and, at the end, the library API).
//!
//! Every case asserts: the exit code (0 ok, 1 input, 2 usage, 3 guarantee not met, 4 other),
//! a message naming the problem, no panic/abort text, and the file-system state: a failed run
//! creates no output and leaves no temporary files beside the target; an accepted mesh is
//! checked independently — `/work/shared/tools/quadcheck.py` (if python3 with meshio is
//! available; skipped with a message otherwise) and the centroid-inside-region check of
//! `unamalla_core::verify` on the file read back.
//!
//! Fast cases run in CI (`cargo test -p unamalla-cli --test hostile`). Slow cases are
//! `#[ignore]`d: `cargo test -p unamalla-cli --test hostile -- --ignored`.
//!
//! The fast catalogue has one file per kind of hostile input (`malformed`, `rings`, `geometry`,
//! `options`, `mesh_files`, run in that order); `output_sets`, `library` and `large` hold the
//! other tests, and `harness` the case table entry, the checks and the runner.

#[path = "../common/mod.rs"]
mod common;
mod harness;

mod geometry;
mod malformed;
mod mesh_files;
mod options;
mod rings;

mod large;
mod library;
mod output_sets;

use harness::{run_all, Case};

/// The fast catalogue: CLI cases of every subcommand.
fn fast_cases() -> Vec<Case> {
    let mut v = Vec::new();
    malformed::cases(&mut v);
    rings::cases(&mut v);
    geometry::cases(&mut v);
    options::cases(&mut v);
    mesh_files::cases(&mut v);
    v
}

#[test]
fn fast_catalogue() {
    let n = run_all(fast_cases(), "fast");
    assert!(n >= 60, "{n} cases");
}
