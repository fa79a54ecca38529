//! Prints the markdown tables of `docs/results.md (section "Results: unamalla-contour")`: every method at its default
//! (clean-preset) thresholds on every region of `fixtures/regions/*.geojson`, plus `geo`'s
//! Visvalingam–Whyatt (`SimplifyVw`, `SimplifyVwPreserve`) at the area threshold that gives
//! the closest point count not above the modified-areas result.
//!
//! ```text
//! cargo run --release -p unamalla-contour --example simplify_table [-- fixtures/regions]
//! ```
//!
//! The fixture GeoJSON (one Feature with a Polygon geometry in a FeatureCollection, ring 0
//! exterior, closed rings) is parsed here with `serde_json` to stay independent of
//! `unamalla-io`.

use std::time::Instant;

use geo::{Coord, LineString, Polygon, SimplifyVw, SimplifyVwPreserve};
use unamalla_contour::{
    detect_noise_region, hausdorff, simplify_region, Method, Preset, SimplifyOptions,
};
use unamalla_mesh::{DVec2, Region};

#[path = "common/load.rs"]
mod load;
use load::load;

fn to_geo(r: &Region) -> Polygon<f64> {
    let ls = |p: &[DVec2]| {
        let mut c: Vec<Coord<f64>> = p.iter().map(|q| Coord { x: q.x, y: q.y }).collect();
        c.push(c[0]);
        LineString::new(c)
    };
    Polygon::new(
        ls(r.outer().points()),
        r.holes().iter().map(|h| ls(h.points())).collect(),
    )
}

fn open_ring(ls: &LineString<f64>) -> Vec<DVec2> {
    let mut v: Vec<DVec2> = ls.coords().map(|c| DVec2::new(c.x, c.y)).collect();
    if v.len() > 1 && v.first() == v.last() {
        v.pop();
    }
    v
}

fn count(p: &Polygon<f64>) -> usize {
    open_ring(p.exterior()).len()
        + p.interiors()
            .iter()
            .map(|h| open_ring(h).len())
            .sum::<usize>()
}

struct Row {
    label: String,
    worst: String,
    after: usize,
    area_change: f64,
    hausdorff: f64,
    ms: f64,
    valid: bool,
}

/// Runs a geo simplifier at the smallest tolerance whose point count is ≤ `target` (bisection
/// in log scale; the count is non-increasing in the tolerance).
fn geo_row(
    label: &str,
    region: &Region,
    target: usize,
    f: impl Fn(&Polygon<f64>, f64) -> Polygon<f64>,
) -> Row {
    let poly = to_geo(region);
    let (lo_b, hi_b) = region.bounding_box();
    let d2 = (hi_b - lo_b).length_squared();
    let (mut lo, mut hi) = ((d2 * 1e-16).ln(), d2.ln());
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if count(&f(&poly, mid.exp())) <= target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let eps = hi.exp();
    let t = Instant::now();
    let out = f(&poly, eps);
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let ext = open_ring(out.exterior());
    let holes: Vec<Vec<DVec2>> = out.interiors().iter().map(open_ring).collect();
    let shoelace = |p: &[DVec2]| unamalla_mesh::region::signed_area(p).abs();
    let area = shoelace(&ext) - holes.iter().map(|h| shoelace(h)).sum::<f64>();
    let mut hd = hausdorff(region.outer().points(), &ext);
    for (h, o) in holes.iter().zip(region.holes()) {
        hd = hd.max(hausdorff(o.points(), h));
    }
    let valid = Region::new(ext, holes).is_ok();
    Row {
        label: format!("{label} (tol {eps:.3e})"),
        worst: String::from("–"),
        after: count(&out),
        area_change: (area - region.area()) / region.area(),
        hausdorff: hd,
        ms,
        valid,
    }
}

fn main() {
    let files = load::region_files();
    let mut summary = String::from(
        "| region | rings | vertices | noise (gap, staircase) | visvalingam | areas | radii | modified-areas | modified-radii | three-step | modified-three-step | geo VW | geo VW-preserve |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut detail = String::from(
        "| region | method | vertices after | ΔA/A | Hausdorff | Hausdorff / bbox diagonal | ring with the largest Hausdorff (vertices) | time (ms) | valid region |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for path in &files {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let region = match load(path) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("skipping {e}");
                continue;
            }
        };
        let (lo, hi) = region.bounding_box();
        let diag = (hi - lo).length();
        let (noisy, reports) = detect_noise_region(&region);
        let outer_rep = &reports[0];
        let mut rows = Vec::new();
        let mut mod_areas_count = 0;
        for m in Method::ALL {
            let res = simplify_region(&region, &SimplifyOptions::new(m, Preset::Clean))
                .unwrap_or_else(|e| panic!("{name} {m}: {e}"));
            if m == Method::ModifiedAreas {
                mod_areas_count = res.vertices_after;
            }
            let params = match res.delta {
                Some(d) => format!("{m} (ε {}, δ {d:e})", res.epsilon),
                None => format!("{m} (ε {})", res.epsilon),
            };
            let worst = res
                .rings
                .iter()
                .max_by(|a, b| a.hausdorff.total_cmp(&b.hausdorff))
                .map(|r| format!("{} ({} → {})", r.ring, r.before, r.after))
                .unwrap_or_default();
            rows.push(Row {
                label: params,
                worst,
                after: res.vertices_after,
                area_change: res.relative_area_change,
                hausdorff: res.hausdorff,
                ms: res.elapsed.as_secs_f64() * 1e3,
                valid: true,
            });
        }
        rows.push(geo_row(
            "geo SimplifyVw",
            &region,
            mod_areas_count,
            |p, e| p.simplify_vw(e),
        ));
        rows.push(geo_row(
            "geo SimplifyVwPreserve",
            &region,
            mod_areas_count,
            |p, e| p.simplify_vw_preserve(e),
        ));
        summary.push_str(&format!(
            "| {name} | {} | {} | {} ({:.2}, {:.2}) |",
            region.holes().len() + 1,
            region.num_vertices(),
            if noisy { "noisy" } else { "clean" },
            outer_rep.largest_gap,
            outer_rep.staircase_fraction
        ));
        for r in &rows {
            summary.push_str(&format!(
                " {}{} |",
                r.after,
                if r.valid { "" } else { " ✗" }
            ));
        }
        summary.push('\n');
        for r in &rows {
            detail.push_str(&format!(
                "| {name} ({}) | {} | {} | {:+.2e} | {:.3e} | {:.2e} | {} | {:.2} | {} |\n",
                region.num_vertices(),
                r.label,
                r.after,
                r.area_change,
                r.hausdorff,
                r.hausdorff / diag,
                r.worst,
                r.ms,
                if r.valid { "yes" } else { "**no**" }
            ));
        }
    }
    println!("### Vertices after simplification (defaults, clean preset)\n");
    println!("{summary}");
    println!("### Details\n");
    println!("{detail}");
}
