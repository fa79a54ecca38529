//! Decomposes every region in `fixtures/regions/*.geojson` automatically and prints the
//! results table of `docs/results.md (section "Decomposition results")`; with `--svg DIR` also writes
//! `DIR/decomposition-<name>.svg` and `DIR/decomposition-<name>.json`.
//!
//! ```text
//! cargo run --release -p unamalla-decompose --example fixtures_table -- [--svg DIR] [--eps 1e-3] [--no-merge] [--only NAME]
//! ```
//!
//! The regions are first simplified by a **stand-in** topology-safe scaled Visvalingam
//! reduction written here (the contour crate is the project's simplifier; this one only keeps
//! the example self-contained): vertices whose triangle area is below `eps · area(region)` are
//! removed in passes, never two neighbours in one pass, never when the new edge would hit
//! another edge or swallow a vertex of another ring.

use std::path::{Path, PathBuf};
use std::time::Instant;

use unamalla_decompose::{decompose, DecomposeOptions, Decomposition, Tolerances};
use unamalla_io::geojson::{read_region_geojson_cleaned, PartSelector};

#[path = "../tests/common/simplify.rs"]
mod simplify;
use simplify::simplify;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut svg_dir: Option<PathBuf> = None;
    let mut eps = 2e-4;
    let mut only: Option<String> = None;
    let mut merge = true;
    let mut k = 1;
    while k < args.len() {
        match args[k].as_str() {
            "--svg" => {
                svg_dir = args.get(k + 1).map(PathBuf::from);
                k += 1;
            }
            "--eps" => {
                eps = args.get(k + 1).and_then(|s| s.parse().ok()).unwrap_or(eps);
                k += 1;
            }
            "--no-merge" => merge = false,
            "--only" => {
                only = args.get(k + 1).cloned();
                k += 1;
            }
            _ => {}
        }
        k += 1;
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/regions");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixtures/regions")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "geojson"))
        .collect();
    files.sort();
    let opts = DecomposeOptions {
        merge_blocks: merge,
        ..DecomposeOptions::default()
    };
    let tol = Tolerances::default();
    println!("| region | vertices (raw → simplified) | holes (handled) | blocks | triangles | cuts | admissible blocks | min corner angle / max (quad blocks) | cut joints | time |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for f in files {
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        if only.as_ref().is_some_and(|o| o != &name) {
            continue;
        }
        let (raw, _) = read_region_geojson_cleaned(&f, PartSelector::Largest).expect("region");
        let region = simplify(&raw, eps);
        let t0 = Instant::now();
        let res = decompose(&region, &opts);
        let dt = t0.elapsed();
        match res {
            Ok(d) => {
                let adm = (0..d.blocks.len())
                    .filter(|&b| d.block_admissible(b, &tol))
                    .count();
                let tri = d.blocks.iter().filter(|b| b.triangle).count();
                // cut endpoints off the region boundary (joints of split cuts)
                let joints = {
                    let mut pts: Vec<(u64, u64)> = d
                        .cuts
                        .iter()
                        .flat_map(|c| [c.a, c.b])
                        .filter(|p| {
                            region
                                .rings()
                                .flat_map(|r| {
                                    let q = r.points();
                                    (0..q.len()).map(move |k| (q[k], q[(k + 1) % q.len()]))
                                })
                                .all(|(a, b)| {
                                    unamalla_mesh::geometry::point_segment_distance(*p, a, b) > 1e-9
                                })
                        })
                        .map(|p| (p.x.to_bits(), p.y.to_bits()))
                        .collect();
                    pts.sort_unstable();
                    pts.dedup();
                    pts.len()
                };
                if std::env::var("DECOMP_DEBUG").is_ok() {
                    for b in &d.blocks {
                        if !d.block_admissible(b.id, &tol) {
                            let c = unamalla_decompose::concavity(&b.ring);
                            eprintln!(
                                "  {name} block {}: n={} area={:.3e} k1={:.3} k2={:.3} k3={:.3} critical={:?} triangle={}",
                                b.id,
                                b.ring.len(),
                                b.area(),
                                c.kappa1,
                                c.kappa2,
                                c.kappa3,
                                unamalla_decompose::critical_angles(&b.ring, tol.theta_minus).len(),
                                b.triangle
                            );
                            for v in unamalla_decompose::critical_angles(&b.ring, tol.theta_minus) {
                                let n = b.ring.len();
                                eprintln!(
                                    "     vertex {v}: in {:?} out {:?}",
                                    b.edges[(v + n - 1) % n],
                                    b.edges[v]
                                );
                            }
                        }
                    }
                }
                let back = Decomposition::from_json(&d.to_json(), &region).expect("round trip");
                assert_eq!(back.blocks.len(), d.blocks.len());
                println!(
                    "| {name} | {} → {} | {} ({}) | {} | {tri} | {} | {adm}/{} | {:.1}° / {:.1}° | {joints} | {:.3} s |",
                    raw.num_vertices(),
                    region.num_vertices(),
                    region.holes().len(),
                    d.graph_cycles(),
                    d.blocks.len(),
                    d.cuts.len(),
                    d.blocks.len(),
                    d.min_corner_angle().to_degrees(),
                    d.blocks
                        .iter()
                        .filter(|b| !b.triangle)
                        .flat_map(|b| b.corner_angles())
                        .fold(0.0f64, f64::max)
                        .to_degrees(),
                    dt.as_secs_f64()
                );
                if let Some(dir) = &svg_dir {
                    std::fs::write(
                        dir.join(format!("decomposition-{name}.svg")),
                        d.to_svg(&region),
                    )
                    .unwrap();
                    std::fs::write(dir.join(format!("decomposition-{name}.json")), d.to_json())
                        .unwrap();
                }
            }
            Err(e) => println!(
                "| {name} | {} → {} | {} | error: {e} | | | | | {:.3} s |",
                raw.num_vertices(),
                region.num_vertices(),
                region.holes().len(),
                dt.as_secs_f64()
            ),
        }
    }
}
