//! The `mesh` entry point (`unamalla_core::pipeline::Mesher`) on small regions built from
//! arbitrary data: the outer ring a star polygon (vertex `k` at angle `2πk/n`, radius from the
//! input, so always simple) or a raw integer lattice ring (usually rejected by `Region::new`),
//! with up to three star-shaped holes anywhere (often crossing the outer ring or each other:
//! rejected), 16 to 415 cells, with or without contour simplification.
//!
//! Oracle (docs/reliability.md, "The guarantee holds or the run fails"): no panic; a mesh returned
//! as `Ok` passed its own verification, and the independent check `verify_quads` against the meshed
//! region agrees (no non-convex cell, no centroid outside); an error is allowed (a valid region may
//! be unmeshable at the size), but its message is not empty. Hangs are found by libFuzzer's
//! `-timeout` (see `scripts/fuzz_all.sh`).
#![no_main]
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use unamalla_core::mesh::{DVec2, Region};
use unamalla_core::pipeline::Mesher;
use unamalla_core::verify::{verify_quads, VerifyOptions};

#[derive(Arbitrary, Debug)]
enum Ring {
    /// Radii of a star polygon around `centre`, scaled by `scale / 16`.
    Star {
        centre: (i8, i8),
        scale: u8,
        radii: Vec<u8>,
    },
    /// Raw lattice points.
    Lattice(Vec<(i8, i8)>),
}

#[derive(Arbitrary, Debug)]
struct Input {
    outer: Ring,
    holes: Vec<Ring>,
    cells: u16,
    simplify: bool,
}

fn points(r: &Ring, max: usize) -> Vec<DVec2> {
    match r {
        Ring::Star {
            centre,
            scale,
            radii,
        } => {
            let n = radii.len().min(max);
            let s = f64::from(*scale).max(1.0) / 16.0;
            let c = DVec2::new(f64::from(centre.0), f64::from(centre.1));
            (0..n)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / n as f64;
                    let r = s * (1.0 + f64::from(radii[k]));
                    c + r * DVec2::new(t.cos(), t.sin())
                })
                .collect()
        }
        Ring::Lattice(v) => v
            .iter()
            .take(max)
            .map(|&(x, y)| DVec2::new(f64::from(x), f64::from(y)))
            .collect(),
    }
}

fuzz_target!(|input: Input| {
    let outer = points(&input.outer, 48);
    let holes: Vec<Vec<DVec2>> = input.holes.iter().take(3).map(|h| points(h, 16)).collect();
    let Ok((region, _)) = Region::new_cleaned(outer, holes) else {
        return;
    };
    let cells = 16 + usize::from(input.cells % 400);
    let mut m = Mesher::new().cells(cells);
    if !input.simplify {
        m = m.simplify(None);
    }
    match m.mesh(&region) {
        Ok(r) => {
            assert!(
                r.report.verification.passed(),
                "Ok with a failed verification: {}",
                r.report.verification
            );
            let v = verify_quads(
                r.mesh.global(),
                Some(&r.simplified),
                &VerifyOptions::default(),
            );
            assert_eq!(v.non_convex_cells, 0, "{v}");
            assert_eq!(v.centroids_outside, Some(0), "{v}");
        }
        Err(e) => assert!(!e.to_string().is_empty()),
    }
});
