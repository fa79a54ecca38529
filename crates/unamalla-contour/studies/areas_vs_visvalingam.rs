//! Checks the thesis's statement that the modified area criterion removes more vertices than
//! scaled Visvalingam at the same threshold ([Méndez 2023, §3.3.4, Tables 3.1–3.3]:
//! octopus12 2015 vs 2011 at ε = 20, Presa La Amistad 8904 vs 8690 and Laguna Honda 2327 vs
//! 1609 at ε = 1) on every region of `fixtures/regions`, and prints the Markdown table of
//! docs/results.md ("Modified areas vs scaled Visvalingam").
//!
//! ```text
//! cargo run --release -p unamalla-contour --example areas_vs_visvalingam [-- fixtures/regions]
//! ```
//!
//! Both methods remove one vertex at a time, the one of smallest key, while the key is below
//! `ε·ā` with `ā` the mean triangle area of the input ring: Visvalingam's key is the triangle
//! area `a_i`, the modified criterion's is `ζ_i = α_i|sin θ_i| = 2a_i|sin θ_i|` (3.4)/(3.6).
//! So `ζ_i < a_i` exactly when `|sin θ_i| < ½` (θ within 30° of a straight angle or of a spike)
//! and `ζ_i > a_i` when `30° < θ_i < 150°`. The columns "V only" / "M only" count, on the input
//! rings, the vertices that only one of the two criteria puts below the threshold at the first
//! step (`a < εā ≤ ζ`, resp. `ζ < εā ≤ a`), which is where the two results part.

#[path = "common/load.rs"]
mod load;

use unamalla_contour::criteria::{mean_triangle_area, triangle_area, weighted_area};
use unamalla_contour::{detect_noise_region, simplify_region, Method, Preset, SimplifyOptions};
use unamalla_mesh::Region;

fn removed(region: &Region, method: Method, eps: f64) -> usize {
    let opts = SimplifyOptions::new(method, Preset::Clean).epsilon(Some(eps));
    let r = simplify_region(region, &opts).expect("simplify");
    r.vertices_before - r.vertices_after
}

/// (V only, M only) first-step candidates over all rings at threshold ε.
fn first_step(region: &Region, eps: f64) -> (usize, usize) {
    let (mut v, mut m) = (0, 0);
    for ring in std::iter::once(region.outer()).chain(region.holes().iter()) {
        let p = ring.points();
        let n = p.len();
        let t = eps * mean_triangle_area(p);
        for i in 0..n {
            let (a, b, c) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
            let (va, za) = (triangle_area(a, b, c) < t, weighted_area(a, b, c) < t);
            v += usize::from(va && !za);
            m += usize::from(za && !va);
        }
    }
    (v, m)
}

fn main() {
    let files = load::region_files();
    println!("| region | vertices | noisy | ε = 1: Visvalingam | modified areas | M − V | V only / M only (1st step) | ε = 20: Visvalingam | modified areas | M − V |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let (mut more1, mut more20, mut total) = (0, 0, 0);
    for path in &files {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let region = match load::load(path) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("skipping {e}");
                continue;
            }
        };
        let nv = region.outer().len() + region.holes().iter().map(|h| h.len()).sum::<usize>();
        let (noisy, _) = detect_noise_region(&region);
        let v1 = removed(&region, Method::Visvalingam, 1.0);
        let m1 = removed(&region, Method::ModifiedAreas, 1.0);
        let v20 = removed(&region, Method::Visvalingam, 20.0);
        let m20 = removed(&region, Method::ModifiedAreas, 20.0);
        let (vo, mo) = first_step(&region, 1.0);
        total += 1;
        more1 += usize::from(m1 > v1);
        more20 += usize::from(m20 > v20);
        println!(
            "| {name} | {nv} | {} | {v1} | {m1} | {:+} | {vo} / {mo} | {v20} | {m20} | {:+} |",
            if noisy { "yes" } else { "no" },
            m1 as i64 - v1 as i64,
            m20 as i64 - v20 as i64
        );
    }
    println!();
    println!(
        "modified areas removes more: {more1}/{total} regions at ε = 1, {more20}/{total} at ε = 20"
    );
}
