//! Layout evaluation harness (issue #22): meshes regions end to end with a chosen layout and
//! prints one JSON line per region (cells, blocks, μ ≥ 0.8 share, non-convex cells,
//! singularities, stage times).
//!
//! ```text
//! cargo run --release -p unamalla-core --example layout_eval -- \
//!     [--layout concavity|chords|best] [--aspect T] [--cells N] [--budget S] REGION.geojson…
//! ```
use unamalla_core::decompose::{DecomposeOptions, Layout};
use unamalla_core::pipeline::Mesher;

fn main() {
    let mut layout = Layout::default();
    let mut aspect = unamalla_core::decompose::chords::DEFAULT_ASPECT;
    let mut cells = 20_000usize;
    let mut budget = 15.0f64;
    let mut paths = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut val = || args.next().unwrap_or_default();
        match a.as_str() {
            "--layout" => {
                layout = match val().as_str() {
                    "concavity" => Layout::Concavity,
                    _ => Layout::Chords,
                }
            }
            "--aspect" => aspect = val().parse().unwrap_or(aspect),
            "--cells" => cells = val().parse().unwrap_or(cells),
            "--budget" => budget = val().parse().unwrap_or(budget),
            _ => paths.push(a),
        }
    }
    for path in paths {
        let name = std::path::Path::new(&path)
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let region = match unamalla_core::io::read_region_geojson(&path, Default::default()) {
            Ok(r) => r,
            Err(e) => {
                println!("{{\"region\":\"{name}\",\"error\":\"{e}\"}}");
                continue;
            }
        };
        let opts = DecomposeOptions {
            layout,
            chord_aspect: aspect,
            ..DecomposeOptions::default()
        };
        let t = std::time::Instant::now();
        let r = Mesher::new()
            .cells(cells)
            .smooth_budget(budget)
            .decompose_options(opts)
            .mesh(&region);
        match r {
            Ok(r) => {
                let rep = &r.report;
                if let Some(dir) = std::env::var_os("LAYOUT_SVG") {
                    let file = std::path::Path::new(&dir).join(format!("{name}.svg"));
                    let _ = std::fs::write(file, r.decomposition.to_svg(&r.simplified));
                }
                let chords = r
                    .decomposition
                    .tree
                    .iter()
                    .any(|n| n.step == Some(unamalla_core::decompose::Step::Chord));
                let st: Vec<String> = rep
                    .stage_seconds
                    .iter()
                    .map(|(s, t)| format!("\"{s:?}\":{t:.2}"))
                    .collect();
                println!(
                    "{{\"region\":\"{name}\",\"chords\":{chords},\"blocks\":{},\"cells\":{},\"mu\":{:.2},\"nonconvex\":{},\"sing\":{},\"smoothing\":\"{}\",\"seconds\":{:.2},\"stages\":{{{}}}}}",
                    rep.blocks,
                    rep.cells,
                    rep.mu_ge_0_8_percent,
                    rep.non_convex_cells,
                    rep.interior_singularities,
                    rep.smoothing,
                    t.elapsed().as_secs_f64(),
                    st.join(",")
                );
            }
            Err(e) => println!("{{\"region\":\"{name}\",\"error\":\"{}\"}}", e.to_string().replace('"', "'")),
        }
    }
}
