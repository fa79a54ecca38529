//! Compares the two corner choices — the corner score F ([`CornerChoice::Scoring`], the
//! default) and the thesis's convex-hull diametral heuristic ([`CornerChoice::Diametral`],
//! Méndez Cruz 2023 §5.1.1) — on every region of `fixtures/regions`, and prints the table of
//! docs/results.md ("Corner choice: scoring vs the diametral heuristic").
//!
//! ```text
//! cargo run --release -p unamalla-decompose --example corner_choice_table
//! ```
//!
//! Regions are simplified as the default mesher does (`tests/common/pipeline.rs`). Per region:
//! (1) on the quadrilateral blocks of the default decomposition, both choices applied to the same
//! block rings — how often they agree, the mean score F and the mean opposite-side imbalance of
//! each, and the worst corner angle (farthest from 90°) of each; (2) the whole decomposition
//! rerun with the diametral choice — blocks and the share of corners ≥ 150°.

use std::path::PathBuf;
use std::time::Instant;

use unamalla_decompose::{
    decompose, select_corners, CornerChoice, CornerWeights, DecomposeOptions,
};
use unamalla_io::geojson::{read_region_geojson_cleaned, PartSelector};
use unamalla_mesh::DVec2;

#[path = "../tests/common/pipeline.rs"]
mod pipeline;
use pipeline::pipeline_simplify;

/// Interior angle (degrees) at vertex `i` of a counter-clockwise ring.
fn angle(ring: &[DVec2], i: usize) -> f64 {
    let n = ring.len();
    let a = ring[(i + n - 1) % n] - ring[i];
    let b = ring[(i + 1) % n] - ring[i];
    let t = b.perp_dot(a).atan2(b.dot(a));
    (if t < 0.0 {
        t + std::f64::consts::TAU
    } else {
        t
    })
    .to_degrees()
}

/// `½(|L₀ − L₂|/(L₀ + L₂) + |L₁ − L₃|/(L₁ + L₃))` for ascending corners `c`.
fn imbalance(ring: &[DVec2], c: [usize; 4]) -> f64 {
    let n = ring.len();
    let mut l = [0.0; 4];
    for k in 0..4 {
        let mut i = c[k];
        while i != c[(k + 1) % 4] {
            l[k] += ring[i].distance(ring[(i + 1) % n]);
            i = (i + 1) % n;
        }
    }
    0.5 * ((l[0] - l[2]).abs() / (l[0] + l[2]) + (l[1] - l[3]).abs() / (l[1] + l[3]))
}

fn main() {
    let dir = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/regions"
    ));
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixtures/regions")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "geojson"))
        .collect();
    files.sort();
    let diam = CornerWeights {
        choice: CornerChoice::Diametral,
        ..CornerWeights::default()
    };
    println!("| region | quad blocks | same corners | mean F scoring / diametral | mean imbalance scoring / diametral | worst |θ − 90°| scoring / diametral | diametral decomposition: blocks (default) | corners ≥ 150° default / diametral | time default / diametral |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut tot = [0.0f64; 6];
    for f in files {
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        let (raw, _) = read_region_geojson_cleaned(&f, PartSelector::Largest).expect("region");
        let region = pipeline_simplify(&raw);
        let t0 = Instant::now();
        let d = decompose(&region, &DecomposeOptions::default());
        let t_def = t0.elapsed().as_secs_f64();
        let Ok(d) = d else {
            println!("| {name} | default decomposition failed | | | | | | | |");
            continue;
        };
        let (mut q, mut same, mut fs, mut fd, mut is, mut id) = (0, 0, 0.0, 0.0, 0.0, 0.0);
        let (mut ws, mut wd) = (0.0f64, 0.0f64);
        for b in d.blocks.iter().filter(|b| !b.triangle) {
            let (Some((cs, f1)), Some((cd, f2))) = (
                select_corners(&b.ring, &CornerWeights::default()),
                select_corners(&b.ring, &diam),
            ) else {
                continue;
            };
            q += 1;
            same += usize::from(cs == cd);
            fs += f1;
            fd += f2;
            is += imbalance(&b.ring, cs);
            id += imbalance(&b.ring, cd);
            for &c in &cs {
                ws = ws.max((angle(&b.ring, c) - 90.0).abs());
            }
            for &c in &cd {
                wd = wd.max((angle(&b.ring, c) - 90.0).abs());
            }
        }
        let qn = q.max(1) as f64;
        tot[0] += q as f64;
        tot[1] += same as f64;
        tot[2] += fs;
        tot[3] += fd;
        tot[4] += is;
        tot[5] += id;
        let t1 = Instant::now();
        let dd = decompose(&region, &DecomposeOptions::default().corner_weights(diam));
        let t_d = t1.elapsed().as_secs_f64();
        let wide = |d: &unamalla_decompose::Decomposition| {
            d.blocks
                .iter()
                .filter(|b| !b.triangle)
                .flat_map(|b| b.corner_angles())
                .filter(|a| a.to_degrees() >= 150.0)
                .count()
        };
        let (dd_blocks, dd_wide) = match &dd {
            Ok(x) => (x.blocks.len().to_string(), wide(x).to_string()),
            Err(e) => (format!("failed: {e}"), "–".into()),
        };
        println!(
            "| {name} | {q} | {same} | {:.3} / {:.3} | {:.3} / {:.3} | {:.1}° / {:.1}° | {dd_blocks} ({}) | {} / {dd_wide} | {:.2} / {:.2} s |",
            fs / qn,
            fd / qn,
            is / qn,
            id / qn,
            ws,
            wd,
            d.blocks.len(),
            wide(&d),
            t_def,
            t_d
        );
    }
    let n = tot[0].max(1.0);
    println!();
    println!(
        "all quad blocks: {} ; same corners {} ({:.1} %); mean F {:.3} / {:.3}; mean imbalance {:.3} / {:.3}",
        tot[0],
        tot[1],
        100.0 * tot[1] / n,
        tot[2] / n,
        tot[3] / n,
        tot[4] / n,
        tot[5] / n
    );
}
