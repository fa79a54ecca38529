//! Helpers shared by the integration tests.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use unamalla_mesh::{DVec2, DVec3, HexMesh, QuadMesh, StructuredGrid2, StructuredGrid3};

static N: AtomicUsize = AtomicUsize::new(0);

/// A fresh empty directory under the system temp dir, removed when dropped.
pub struct Scratch(pub PathBuf);

impl Scratch {
    pub fn new(tag: &str) -> Self {
        let d = std::env::temp_dir().join(format!(
            "unamalla-io-test-{tag}-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
    pub fn entries(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Deterministic pseudo-random numbers (SplitMix64) so that coordinates use all 53 bits.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [-0.5, 0.5).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// A 4 × 3-node structured grid with jittered interior coordinates of awkward magnitudes.
pub fn jittered_grid2() -> StructuredGrid2 {
    let mut r = Rng::new(7);
    StructuredGrid2::from_fn(4, 3, |i, j| {
        let base = DVec2::new(i as f64 * 0.1, j as f64 / 3.0);
        base + DVec2::new(r.unit(), r.unit()) * 1e-3
    })
    .unwrap()
}

/// A 3 × 4 × 2-node structured 3D grid with jittered coordinates.
pub fn jittered_grid3() -> StructuredGrid3 {
    let mut r = Rng::new(11);
    StructuredGrid3::from_fn(3, 4, 2, |i, j, k| {
        DVec3::new(i as f64, j as f64 * 0.7, k as f64 * 1e5)
            + DVec3::new(r.unit(), r.unit(), r.unit()) * 1e-2
    })
    .unwrap()
}

/// An L-shaped quad mesh of 3 cells (not a structured grid), listed counter-clockwise.
///
/// ```text
/// 6---7
/// |   |
/// 3---4---5
/// |   |   |
/// 0---1---2
/// ```
pub fn l_shaped_quads() -> QuadMesh {
    let nodes = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(2.0, 0.0),
        DVec2::new(0.0, 1.0),
        DVec2::new(1.0, 1.0),
        DVec2::new(2.0, 1.0 + 1e-12),
        DVec2::new(0.0, 2.0),
        DVec2::new(1.0 / 3.0, 2.0),
    ];
    let cells = vec![[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6]];
    QuadMesh::new(nodes, cells).unwrap()
}

/// Two hexahedra stacked in z (12 nodes), VTK order.
pub fn two_hexes() -> HexMesh {
    let mut nodes = Vec::new();
    for k in 0..3 {
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            nodes.push(DVec3::new(x + 0.01 * k as f64, y, k as f64 * 0.5));
        }
    }
    let cells = vec![[0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 8, 9, 10, 11]];
    HexMesh::new(nodes, cells).unwrap()
}

pub fn scripts_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts")
}
