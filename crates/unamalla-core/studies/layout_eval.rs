//! Layout evaluation harness (block layouts): meshes regions end to end with a chosen layout and
//! prints one JSON line per region (cells, blocks, μ ≥ 0.8 share, non-convex cells,
//! singularities, stage times).
//!
//! ```text
//! cargo run --release -p unamalla-core --example layout_eval -- \
//!     [--layout concavity|chords|best] [--aspect T] [--cells N] [--time-limit S] REGION.geojson…
//! ```
use unamalla_core::decompose::{DecomposeOptions, Layout};
use unamalla_core::pipeline::Mesher;

fn main() {
    let mut layout: Option<Layout> = None;
    let mut aspect = unamalla_core::decompose::chords::DEFAULT_ASPECT;
    let mut cells = 20_000usize;
    let mut budget: Option<f64> = None;
    let mut paths = Vec::new();
    let mut predict_only = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut val = || args.next().unwrap_or_default();
        match a.as_str() {
            "--layout" => {
                layout = match val().as_str() {
                    "concavity" => Some(Layout::Concavity),
                    "chords" => Some(Layout::Chords),
                    _ => None,
                }
            }
            "--aspect" => aspect = val().parse().unwrap_or(aspect),
            "--cells" => cells = val().parse().unwrap_or(cells),
            "--time-limit" => budget = val().parse().ok(),
            "--predict-only" => predict_only = true,
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
        let opts = DecomposeOptions::default().chord_aspect(aspect);
        let t = std::time::Instant::now();
        if predict_only {
            let mesher = Mesher::new().cells(cells).decompose_options(opts.clone());
            let Ok(prep) = mesher.prepare_region(&region) else {
                continue;
            };
            let r = &prep.mesh_region;
            let h = (r.area() / cells as f64).sqrt();
            let o = opts.cell_size(Some(h));
            match unamalla_core::pipeline::choose_layout(
                r,
                &o,
                unamalla_core::pipeline::MeshSize::Cells(cells),
            ) {
                Ok((d, c)) => println!(
                    "{{\"region\":\"{name}\",\"layout\":\"{}\",\"pred\":{:.2},\"resplit\":\"{}/{}\",\"blocks\":{},\"cands\":\"{:?}\",\"seconds\":{:.2}}}",
                    c.layout,
                    c.predicted_percent,
                    c.resplit_cuts,
                    c.resplit_tried,
                    d.blocks.len(),
                    c.candidates,
                    t.elapsed().as_secs_f64()
                ),
                Err(e) => println!("{{\"region\":\"{name}\",\"error\":\"{e}\"}}"),
            }
            continue;
        }
        let mut mesher = Mesher::new()
            .cells(cells)
            .time_limit(budget)
            .decompose_options(opts);
        if let Some(l) = layout {
            mesher = mesher.layout(l);
        }
        let r = mesher.mesh(&region);
        match r {
            Ok(r) => {
                let rep = &r.report;
                if std::env::var_os("LAYOUT_SING").is_some() {
                    use unamalla_core::mesh::quality::interior_singularities;
                    use unamalla_core::mesh::HasNodes;
                    let g = r.mesh.global();
                    for (i, v) in interior_singularities(g).singular {
                        eprintln!("singular node {i} valence {v} at {:?}", g.nodes()[i]);
                    }
                    for c in &r.decomposition.cuts {
                        eprintln!("cut {} {:?} {:?}", c.id, c.a, c.b);
                    }
                }
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
                let (pred, cands) = match &rep.layout {
                    Some(c) => (
                        c.predicted_percent,
                        format!(
                            "{} +{}/{} {:?}",
                            c.layout, c.resplit_cuts, c.resplit_tried, c.candidates
                        ),
                    ),
                    None => (f64::NAN, String::new()),
                };
                let corr = unamalla_core::predict::weighted_correlation(
                    &rep.block_quality
                        .iter()
                        .map(|b| (b.predicted, b.achieved, b.cells as f64))
                        .collect::<Vec<_>>(),
                );
                println!(
                    "{{\"region\":\"{name}\",\"pred\":{pred:.2},\"corr\":{corr:.3},\"cands\":\"{cands}\",\"chords\":{chords},\"blocks\":{},\"cells\":{},\"mu\":{:.2},\"nonconvex\":{},\"sing\":{},\"smoothing\":\"{}\",\"seconds\":{:.2},\"stages\":{{{}}}}}",
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
            Err(e) => println!(
                "{{\"region\":\"{name}\",\"error\":\"{}\"}}",
                e.to_string().replace('"', "'")
            ),
        }
    }
}
