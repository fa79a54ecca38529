//! Decomposes every region in `fixtures/regions/*.geojson` automatically and prints the
//! results table of `docs/results.md (section "Decomposition results")`; with `--svg DIR` also writes
//! `DIR/decomposition-<name>.svg` and `DIR/decomposition-<name>.json`.
//!
//! ```text
//! cargo run --release -p unamalla-decompose --example fixtures_table -- [--svg DIR] [--eps 1e-3] [--no-merge] [--only NAME]
//! ```
//!
//! By default the regions are simplified **exactly as the default mesher does** before it
//! decomposes (`tests/common/pipeline.rs`: the contour crate's default simplification, then the
//! removal of boundary features below 5·h² for about 20,000 cells). With `--eps X` the older
//! **stand-in** topology-safe scaled Visvalingam reduction is used instead (vertices whose
//! triangle area is below `X · area(region)` are removed in passes, never two neighbours in one
//! pass, never when the new edge would hit another edge or swallow a vertex of another ring).

use std::path::{Path, PathBuf};
use std::time::Instant;

use unamalla_decompose::{decompose, DecomposeOptions, Decomposition, Tolerances};
use unamalla_io::geojson::{read_region_geojson_cleaned, PartSelector};

#[path = "../tests/common/simplify.rs"]
mod simplify;
use simplify::simplify;
#[path = "../tests/common/pipeline.rs"]
mod pipeline;
use pipeline::pipeline_simplify;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut svg_dir: Option<PathBuf> = None;
    let mut eps: Option<f64> = None;
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
                eps = args.get(k + 1).and_then(|s| s.parse().ok());
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
    let opts = DecomposeOptions::default().merge_blocks(merge);
    let tol = Tolerances::default();
    println!("| region | vertices (raw → simplified) | holes (handled) | blocks | triangles | cuts | admissible blocks | convex blocks | min / max corner angle (quad blocks) | corners ≥ 170° | cut joints | time |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for f in files {
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        if only.as_ref().is_some_and(|o| o != &name) {
            continue;
        }
        let (raw, _) = read_region_geojson_cleaned(&f, PartSelector::Largest).expect("region");
        let region = match eps {
            Some(eps) => simplify(&raw, eps),
            None => pipeline_simplify(&raw),
        };
        let t0 = Instant::now();
        let res = decompose(&region, &opts);
        let dt = t0.elapsed();
        match res {
            Ok(d) => {
                let adm = (0..d.blocks.len())
                    .filter(|&b| d.block_admissible(b, &tol))
                    .count();
                let tri = d.blocks.iter().filter(|b| b.triangle).count();
                let convex = d
                    .blocks
                    .iter()
                    .filter(|b| unamalla_decompose::concavity(&b.ring).approximately_convex(&tol))
                    .count();
                let quad_angles: Vec<f64> = d
                    .blocks
                    .iter()
                    .filter(|b| !b.triangle)
                    .flat_map(|b| b.corner_angles())
                    .map(f64::to_degrees)
                    .collect();
                let straight = quad_angles.iter().filter(|a| **a >= 170.0).count();
                let pct = |k: usize| 100.0 * k as f64 / d.blocks.len().max(1) as f64;
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
                    "| {name} | {} → {} | {} ({}) | {} | {tri} | {} | {adm}/{} ({:.1} %) | {convex} ({:.1} %) | {:.1}° / {:.1}° | {straight} | {joints} | {:.3} s |",
                    raw.num_vertices(),
                    region.num_vertices(),
                    region.holes().len(),
                    d.graph_cycles(),
                    d.blocks.len(),
                    d.cuts.len(),
                    d.blocks.len(),
                    pct(adm),
                    pct(convex),
                    quad_angles.iter().copied().fold(f64::INFINITY, f64::min),
                    quad_angles.iter().copied().fold(0.0f64, f64::max),
                    dt.as_secs_f64()
                );
                if let Some(dir) = &svg_dir {
                    let svg = d.to_svg(&region);
                    let json = d.to_json();
                    unamalla_io::atomic_write(
                        &dir.join(format!("decomposition-{name}.svg")),
                        |w| w.write_all(svg.as_bytes()),
                    )
                    .expect("write svg");
                    unamalla_io::atomic_write(
                        &dir.join(format!("decomposition-{name}.json")),
                        |w| w.write_all(json.as_bytes()),
                    )
                    .expect("write json");
                }
            }
            Err(e) => println!(
                "| {name} | {} → {} | {} | error: {e} | | | | | | | {:.3} s |",
                raw.num_vertices(),
                region.num_vertices(),
                region.holes().len(),
                dt.as_secs_f64()
            ),
        }
    }
}
