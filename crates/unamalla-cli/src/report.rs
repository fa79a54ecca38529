//! `report.html`: one self-contained page (no external file, script or font) about a
//! `unamalla mesh` run — the μ picture with a legend, block outlines and cut lines (zoom with
//! the mouse wheel or the buttons, pan by dragging), μ and scaled-Jacobian histograms, a
//! per-block table, the boundary patches and the run's settings.

use std::fmt::Write as _;

use unamalla_core::io::{EdgeGroup, LoadedRegion};
use unamalla_core::mesh::quality::quad_cell_metrics;
use unamalla_core::mesh::{DVec2, HasNodes, HasQuadCells};
use unamalla_core::pipeline::{MeshReport, MeshResult};
use unamalla_core::render::{mu_color, BLUE, ORANGE, RED};

/// The run's settings as shown in the report (label, value).
pub struct Settings {
    /// Rows of the settings table.
    pub rows: Vec<(String, String)>,
    /// Patches: name and number of boundary edges.
    pub patches: Vec<(String, usize)>,
}

impl Settings {
    /// The settings of a `unamalla mesh` run.
    pub fn of_run(a: &crate::commands::MeshArgs, l: &LoadedRegion, groups: &[EdgeGroup]) -> Self {
        let mut rows = vec![
            ("region file".to_string(), a.region.display().to_string()),
            ("strategy".into(), a.strategy.clone()),
        ];
        let size = match (a.cells, a.density, a.cell_size) {
            (_, _, Some(h)) => format!("cell size {h}"),
            (_, Some(d), _) => format!("density {d}"),
            (Some(n), _, _) => format!("about {n} cells"),
            _ => "about 20000 cells (default)".into(),
        };
        rows.push(("size".into(), size));
        rows.push(("boundary density w".into(), a.boundary_density.to_string()));
        rows.push((
            "simplification".into(),
            if a.no_simplify { "off" } else { "on" }.into(),
        ));
        rows.push(("feature factor".into(), a.feature_factor.to_string()));
        rows.push(("neck factor".into(), a.neck_factor.to_string()));
        if let Some(f) = &a.gis.feature {
            rows.push(("feature".into(), f.clone()));
        }
        rows.push((
            "coordinates".into(),
            match &l.projection {
                Some(p) => format!("{} (lengths in km)", p.proj_string()),
                None => "planar, as given".into(),
            },
        ));
        rows.push(("exports".into(), a.gis.export.clone()));
        Self {
            rows,
            patches: groups
                .iter()
                .map(|g| (g.name.clone(), g.edges.len()))
                .collect(),
        }
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// Counts of `values` in `bins` equal bins over `[lo, hi]` (values outside go to the end bins).
pub fn histogram(values: &[f64], lo: f64, hi: f64, bins: usize) -> Vec<usize> {
    let mut h = vec![0; bins];
    for &v in values.iter().filter(|v| v.is_finite()) {
        let t = ((v - lo) / (hi - lo) * bins as f64).floor();
        let k = (t.max(0.0) as usize).min(bins - 1);
        h[k] += 1;
    }
    h
}

/// A bar chart of a histogram as inline SVG.
fn histogram_svg(
    title: &str,
    counts: &[usize],
    lo: f64,
    hi: f64,
    color: &dyn Fn(f64) -> String,
) -> String {
    let (w, h, pad) = (420.0, 180.0, 30.0);
    let max = counts.iter().copied().max().unwrap_or(1).max(1) as f64;
    let bw = (w - 2.0 * pad) / counts.len() as f64;
    let mut s = format!(
        "<svg class=\"hist\" role=\"img\" aria-label=\"{t}\" viewBox=\"0 0 {w} {h}\" width=\"{w}\" height=\"{h}\"><title>{t}</title>",
        t = esc(title)
    );
    for (k, &c) in counts.iter().enumerate() {
        let bh = (h - 2.0 * pad) * c as f64 / max;
        let x = pad + k as f64 * bw;
        let mid = lo + (k as f64 + 0.5) * (hi - lo) / counts.len() as f64;
        let _ = write!(
            s,
            "<rect x=\"{x:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bh:.1}\" fill=\"{}\"><title>{:.3}–{:.3}: {c}</title></rect>",
            h - pad - bh,
            bw - 1.0,
            color(mid),
            lo + k as f64 * (hi - lo) / counts.len() as f64,
            lo + (k + 1) as f64 * (hi - lo) / counts.len() as f64,
        );
    }
    let _ = write!(
        s,
        "<line x1=\"{pad}\" y1=\"{y}\" x2=\"{x2}\" y2=\"{y}\" stroke=\"#333\"/>\
         <text x=\"{pad}\" y=\"{ty}\" font-size=\"11\">{lo}</text>\
         <text x=\"{x2}\" y=\"{ty}\" font-size=\"11\" text-anchor=\"end\">{hi}</text>\
         <text x=\"{pad}\" y=\"14\" font-size=\"12\">{t} (max bin {max})</text></svg>",
        y = h - pad,
        x2 = w - pad,
        ty = h - pad + 14.0,
        t = esc(title),
    );
    s
}

/// The mesh picture: cells coloured by μ band, block outlines (which include the cuts) drawn
/// over them, the region boundary in black. SVG user units are the mesh's (y flipped).
fn mesh_svg(result: &MeshResult, mu: &[f64]) -> String {
    let g = result.mesh.global();
    let (lo, hi) = g.nodes().iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let d = (hi - lo).max(DVec2::splat(1e-12));
    let m = 0.02 * d.x.max(d.y);
    let stroke = 0.0015 * d.x.max(d.y);
    let mut s = format!(
        "<svg id=\"mesh\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" preserveAspectRatio=\"xMidYMid meet\">",
        lo.x - m,
        -hi.y - m,
        d.x + 2.0 * m,
        d.y + 2.0 * m
    );
    let pt = |p: DVec2| format!("{:.6},{:.6}", p.x, -p.y);
    // one path per band keeps the page small
    let mut bands: [String; 3] = Default::default();
    for (c, &m) in mu.iter().enumerate().take(g.num_quads()) {
        let q = g.quad(c);
        let b = if m >= 0.8 {
            0
        } else if m >= 0.4 {
            1
        } else {
            2
        };
        let _ = write!(
            bands[b],
            "M{}L{}L{}L{}Z",
            pt(g.nodes()[q[0]]),
            pt(g.nodes()[q[1]]),
            pt(g.nodes()[q[2]]),
            pt(g.nodes()[q[3]])
        );
    }
    let edge_stroke = if g.num_quads() < 40_000 {
        format!(
            " stroke=\"#ffffff\" stroke-opacity=\"0.5\" stroke-width=\"{:.6}\"",
            stroke * 0.3
        )
    } else {
        String::new()
    };
    for (b, c) in bands.iter().zip([BLUE, ORANGE, RED]) {
        if !b.is_empty() {
            let _ = write!(
                s,
                "<path class=\"cells\" d=\"{b}\" fill=\"{}\"{edge_stroke}/>",
                hex(c)
            );
        }
    }
    for (k, b) in result.mesh.blocks().iter().enumerate() {
        let lp = b.boundary_loop();
        let map = result.mesh.block_node_map(k);
        let mut d = String::new();
        for (i, &v) in lp.iter().enumerate() {
            let p = g.nodes()[map[v]];
            let _ = write!(d, "{}{}", if i == 0 { "M" } else { "L" }, pt(p));
        }
        d.push('Z');
        let _ = write!(
            s,
            "<path class=\"block\" d=\"{d}\" fill=\"none\" stroke=\"#222\" stroke-width=\"{stroke:.6}\"><title>block {k}: {}×{} nodes</title></path>",
            b.m(),
            b.n()
        );
    }
    for ring in result.simplified.rings() {
        let mut d = String::new();
        for (i, &p) in ring.points().iter().enumerate() {
            let _ = write!(d, "{}{}", if i == 0 { "M" } else { "L" }, pt(p));
        }
        d.push('Z');
        let _ = write!(
            s,
            "<path class=\"ring\" d=\"{d}\" fill=\"none\" stroke=\"#000\" stroke-width=\"{:.6}\"/>",
            stroke * 1.5
        );
    }
    s.push_str("</svg>");
    s
}

const SCRIPT: &str = r#"
(function () {
  var svg = document.getElementById('mesh');
  var vb0 = svg.getAttribute('viewBox').split(' ').map(Number);
  var vb = vb0.slice();
  function set() { svg.setAttribute('viewBox', vb.join(' ')); }
  function zoom(f, cx, cy) {
    var r = svg.getBoundingClientRect();
    var px = vb[0] + vb[2] * (cx === undefined ? 0.5 : (cx - r.left) / r.width);
    var py = vb[1] + vb[3] * (cy === undefined ? 0.5 : (cy - r.top) / r.height);
    vb = [px - (px - vb[0]) * f, py - (py - vb[1]) * f, vb[2] * f, vb[3] * f];
    set();
  }
  svg.addEventListener('wheel', function (e) {
    e.preventDefault(); zoom(e.deltaY > 0 ? 1.25 : 0.8, e.clientX, e.clientY);
  }, { passive: false });
  var drag = null;
  svg.addEventListener('mousedown', function (e) { drag = [e.clientX, e.clientY]; });
  window.addEventListener('mouseup', function () { drag = null; });
  window.addEventListener('mousemove', function (e) {
    if (!drag) return;
    var r = svg.getBoundingClientRect();
    vb[0] -= (e.clientX - drag[0]) * vb[2] / r.width;
    vb[1] -= (e.clientY - drag[1]) * vb[3] / r.height;
    drag = [e.clientX, e.clientY]; set();
  });
  document.getElementById('zin').onclick = function () { zoom(0.5); };
  document.getElementById('zout').onclick = function () { zoom(2); };
  document.getElementById('zreset').onclick = function () { vb = vb0.slice(); set(); };
  document.body.setAttribute('data-ready', 'yes');
})();
"#;

/// The HTML page of a run.
pub fn report_html(result: &MeshResult, report: &MeshReport, settings: &Settings) -> String {
    let arrays = quad_cell_metrics(result.mesh.global());
    let col = |name: &str| {
        arrays
            .iter()
            .find(|(k, _)| *k == name)
            .map(|(_, v)| v.clone())
            .unwrap_or_default()
    };
    let mu = col("mu");
    let sj = col("scaled_jacobian");
    let title = if report.region.is_empty() {
        "unamalla mesh".to_string()
    } else {
        format!("unamalla mesh — {}", report.region)
    };
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{t}</title>\
<style>body{{font-family:sans-serif;margin:1.5em;color:#222;max-width:1300px}}\
#view{{border:1px solid #ccc;height:640px;width:100%;cursor:grab}}#mesh{{width:100%;height:100%}}\
table{{border-collapse:collapse;font-size:13px}}td,th{{border:1px solid #ccc;padding:2px 8px;text-align:right}}\
th{{background:#f3f3f3}}td.l,th.l{{text-align:left}}.legend span{{display:inline-block;width:14px;height:14px;vertical-align:middle;margin:0 4px 0 12px}}\
.row{{display:flex;gap:2em;flex-wrap:wrap}}.scroll{{max-height:420px;overflow:auto}}</style></head><body>\
<h1>{t}</h1>",
        t = esc(&title)
    );
    let _ = write!(
        h,
        "<p id=\"summary\">{} cells, {} nodes, {} blocks ({}); non-convex cells {}; interior singularities {}; \
μ ≥ 0.8: {:.1} %; min scaled Jacobian {:.3}; area change {:.3} %; Hausdorff {:.4}; {:.2} s.</p>",
        report.cells,
        report.nodes,
        report.blocks,
        esc(&format!("{:?}", report.strategy).to_lowercase()),
        report.non_convex_cells,
        report.interior_singularities,
        report.mu_ge_0_8_percent,
        report.min_scaled_jacobian,
        report.area_change_percent,
        report.hausdorff,
        report.seconds
    );
    let _ = write!(
        h,
        "<h2>Mesh quality μ</h2><div class=\"legend\">μ (rectangles 2015):\
<span style=\"background:{}\"></span>μ ≥ 0.8 ({:.1} %)<span style=\"background:{}\"></span>0.4 ≤ μ &lt; 0.8 ({:.1} %)\
<span style=\"background:{}\"></span>μ &lt; 0.4 ({:.1} %)<span style=\"background:none;border:2px solid #222;box-sizing:border-box\"></span>block outline / cut\
 &nbsp; <button id=\"zin\">zoom in</button> <button id=\"zout\">zoom out</button> <button id=\"zreset\">reset</button>\
 <small>(mouse wheel zooms, drag pans)</small></div><div id=\"view\">{}</div>",
        hex(BLUE),
        report.mu_bands[0],
        hex(ORANGE),
        report.mu_bands[1],
        hex(RED),
        report.mu_bands[2],
        mesh_svg(result, &mu)
    );
    let bins = 20;
    let _ = write!(
        h,
        "<h2>Histograms</h2><div class=\"row\">{}{}</div>",
        histogram_svg("μ", &histogram(&mu, 0.0, 1.0, bins), 0.0, 1.0, &|m| hex(
            mu_color(m)
        )),
        histogram_svg(
            "scaled Jacobian",
            &histogram(&sj, 0.0, 1.0, bins),
            0.0,
            1.0,
            &|_| "#4c72b0".to_string()
        )
    );
    // per-block table
    let _ = write!(
        h,
        "<h2>Blocks</h2><div class=\"scroll\"><table id=\"blocks\"><tr><th>block</th><th>nodes m×n</th><th>cells</th>\
<th>min μ</th><th>mean μ</th><th>min scaled Jacobian</th><th>μ ≥ 0.8 %</th></tr>"
    );
    let mut start = 0;
    for (k, b) in result.mesh.blocks().iter().enumerate() {
        let nc = b.num_quads();
        let bm = &mu[start..(start + nc).min(mu.len())];
        let bs = &sj[start..(start + nc).min(sj.len())];
        start += nc;
        let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = bm.iter().sum::<f64>() / bm.len().max(1) as f64;
        let good = 100.0 * bm.iter().filter(|&&m| m >= 0.8).count() as f64 / bm.len().max(1) as f64;
        let _ = write!(
            h,
            "<tr><td>{k}</td><td>{}×{}</td><td>{nc}</td><td>{:.3}</td><td>{mean:.3}</td><td>{:.3}</td><td>{good:.1}</td></tr>",
            b.m(),
            b.n(),
            min(bm),
            min(bs)
        );
    }
    h.push_str("</table></div>");
    let _ = write!(
        h,
        "<h2>Boundary patches</h2><table id=\"patches\"><tr><th class=\"l\">name</th><th>edges</th></tr>"
    );
    for (n, c) in &settings.patches {
        let _ = write!(h, "<tr><td class=\"l\">{}</td><td>{c}</td></tr>", esc(n));
    }
    h.push_str("</table><h2>Run settings</h2><table id=\"settings\">");
    for (k, v) in &settings.rows {
        let _ = write!(
            h,
            "<tr><th class=\"l\">{}</th><td class=\"l\">{}</td></tr>",
            esc(k),
            esc(v)
        );
    }
    let _ = write!(
        h,
        "<tr><th class=\"l\">smoothing</th><td class=\"l\">{}</td></tr></table>\
<h2>Stage times</h2><table>",
        esc(&report.smoothing)
    );
    for (st, sec) in &report.stage_seconds {
        let _ = write!(
            h,
            "<tr><th class=\"l\">{}</th><td>{sec:.2} s</td></tr>",
            esc(&format!("{st:?}").to_lowercase())
        );
    }
    let _ = writeln!(h, "</table><script>{SCRIPT}</script></body></html>");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_bins_are_half_open_with_the_top_value_in_the_last_bin() {
        // bins of width 0.25 on [0, 1]: 0 and 0.1 → bin 0; 0.25 → bin 1; 0.99 and 1 → bin 3;
        // −1 clamps to bin 0, NaN is skipped
        let h = histogram(&[0.0, 0.1, 0.25, 0.99, 1.0, -1.0, f64::NAN], 0.0, 1.0, 4);
        assert_eq!(h, vec![3, 1, 0, 2]);
    }

    #[test]
    fn text_is_escaped() {
        assert_eq!(esc("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    }
}
