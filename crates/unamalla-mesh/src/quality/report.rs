//! [`QualityReport`]: one serialisable summary of a quad or hex mesh's quality, with a readable
//! multi-line table as its `Display`.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::hex::HexMetrics;
use super::mesh::{
    hex_metrics_per_cell, hex_non_convex_from, hex_tet_mean, interior_singularities,
    is_high_quality, quad_metrics_per_cell, AlphaStats, MuBands, MuHistogram,
};
use super::quad::{QuadMetrics, DBL_MAX};
use crate::traits::{HasHexCells, HasQuadCells};

/// Options of [`QualityReport::for_quads_with`] / [`QualityReport::for_hexes_with`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct ReportOptions {
    /// Number of μ histogram bins over `[0, 1]` (default 20, bins of 0.05 as in the thesis's
    /// "0.95 ≤ μ ≤ 1" example).
    pub histogram_bins: usize,
    /// ε of the 2D ε-convexity test `α₋ > ε·ᾱ` (default 0.01, the target of
    /// [González Flores, (4.36)]).
    pub epsilon: f64,
    /// ε of the hex 10-tetrahedra test `V > ε·v̄` (default 0: plain positivity).
    pub tet_epsilon: f64,
    /// Face-planarity tolerance on `|cos θ|` (default `1e-2`, [Cortés Aguirre 2012, §4.2]).
    pub planarity_tolerance: f64,
}

impl Default for ReportOptions {
    fn default() -> Self {
        Self {
            histogram_bins: 20,
            epsilon: 0.01,
            tet_epsilon: 0.0,
            planarity_tolerance: 1e-2,
        }
    }
}

impl ReportOptions {
    /// Sets [`histogram_bins`](Self::histogram_bins).
    #[must_use]
    pub fn histogram_bins(mut self, histogram_bins: usize) -> Self {
        self.histogram_bins = histogram_bins;
        self
    }

    /// Sets [`epsilon`](Self::epsilon).
    #[must_use]
    pub fn epsilon(mut self, epsilon: f64) -> Self {
        self.epsilon = epsilon;
        self
    }

    /// Sets [`tet_epsilon`](Self::tet_epsilon).
    #[must_use]
    pub fn tet_epsilon(mut self, tet_epsilon: f64) -> Self {
        self.tet_epsilon = tet_epsilon;
        self
    }

    /// Sets [`planarity_tolerance`](Self::planarity_tolerance).
    #[must_use]
    pub fn planarity_tolerance(mut self, planarity_tolerance: f64) -> Self {
        self.planarity_tolerance = planarity_tolerance;
        self
    }
}

/// Which cells a report describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CellKind {
    /// Planar quadrilaterals.
    Quad,
    /// Hexahedra.
    Hex,
}

/// Summary statistics of one per-cell metric.
///
/// `p5` / `p95` are nearest-rank percentiles of the sorted finite values (`p5` = value of
/// rank `⌈0.05·n⌉`). NaN values (only from non-finite coordinates) are skipped and counted in
/// `nan`. Infinite metric values are stored as `f64::MAX` (Verdict's `DBL_MAX`); the mean is
/// clamped to `f64::MAX`, so it stays finite and JSON-serialisable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MetricSummary {
    /// Metric name (same names as the per-cell arrays).
    pub name: String,
    /// Smallest value.
    pub min: f64,
    /// 5th percentile.
    pub p5: f64,
    /// Mean.
    pub mean: f64,
    /// 95th percentile.
    pub p95: f64,
    /// Largest value.
    pub max: f64,
    /// Number of NaN values skipped.
    pub nan: usize,
}

impl MetricSummary {
    /// Summary of `values`; `None` if there is no non-NaN value.
    pub fn new(name: &str, values: &[f64]) -> Option<Self> {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
        if v.is_empty() {
            return None;
        }
        let n = v.len();
        let rank = |p: f64| ((p * n as f64).ceil() as usize).clamp(1, n) - 1;
        let mean = v.iter().map(|x| x / n as f64).sum::<f64>();
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // order statistics by selection (O(n)) instead of a full sort
        let p95 = *v.select_nth_unstable_by(rank(0.95), f64::total_cmp).1;
        let p5 = *v.select_nth_unstable_by(rank(0.05), f64::total_cmp).1;
        Some(Self {
            name: name.to_string(),
            min,
            p5,
            mean: mean.clamp(-DBL_MAX, DBL_MAX),
            p95,
            max,
            nan: values.len() - n,
        })
    }
}

/// Quad-only part of a [`QualityReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QuadSummary {
    /// ᾱ = 4·area(Ω)/N ([González Flores, (4.31)]).
    pub alpha_mean: f64,
    /// α₋ = min α ("Alfamin").
    pub alpha_min: f64,
    /// α₋ / ᾱ (0 if ᾱ = 0).
    pub alpha_min_ratio: f64,
    /// ε used for the ε-convexity test.
    pub epsilon: f64,
    /// `α₋ > ε·ᾱ`.
    pub eps_convex: bool,
    /// Interior nodes (from connectivity: in some cell, on no boundary edge).
    pub interior_nodes: usize,
    /// Interior nodes with valence ≠ 4.
    pub interior_singularities: usize,
    /// μ bands in % ([Méndez 2023, §2.2]).
    pub mu_bands: MuBands,
    /// μ histogram over [0, 1]; μ ≤ 0 counted separately.
    pub mu_histogram: MuHistogram,
    /// High-quality verdict: ≥ 85 % of the cells with μ ≥ 0.8 ([Méndez 2023, §2.2]).
    pub high_quality: bool,
}

/// Hex-only part of a [`QualityReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexSummary {
    /// Smallest tetrahedron value `V = 6 × volume` over the 10 tets of every cell.
    pub tet_min: f64,
    /// Largest tetrahedron value.
    pub tet_max: f64,
    /// Mean tetrahedron value `v̄`.
    pub tet_mean: f64,
    /// ε of the test `V > ε·v̄`.
    pub tet_epsilon: f64,
    /// Largest face `|cos θ|` over all faces of all cells ([Cortés Aguirre 2012, §4.1]).
    pub max_face_cos: f64,
    /// Tolerance on `|cos θ|`.
    pub planarity_tolerance: f64,
    /// Cells with some face `|cos θ| >` tolerance ("non-hexahedral" cells in the thesis).
    pub non_planar_cells: usize,
}

/// A quality report of a quad or hex mesh.
///
/// Build it with [`for_quads`](Self::for_quads) or [`for_hexes`](Self::for_hexes); print it with
/// `Display` (a table) or serialise it with serde. Every number is finite, so JSON
/// round-trips; note that `serde_json` without its `float_roundtrip` feature may parse a
/// float back 1 ulp away from the written value.
///
/// Quad metrics summarised: `mu`, `min_alpha`, `jacobian`, `scaled_jacobian`, `condition`,
/// `shape`, `skew`, `taper`, `aspect_ratio`, `edge_ratio`, `min_angle`, `max_angle`, `oddy`.
/// Hex metrics: `jacobian`, `scaled_jacobian`, `condition`, `shape`, `skew`, `taper`, `oddy`,
/// `min_tet_det`, `max_face_cos`. Each row has min / p5 / mean / p95 / max.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QualityReport {
    /// Quad or hex.
    pub cell_kind: CellKind,
    /// Number of cells.
    pub num_cells: usize,
    /// Number of nodes.
    pub num_nodes: usize,
    /// One summary row per metric (empty for a mesh without cells).
    pub metrics: Vec<MetricSummary>,
    /// Non-convex cells: some corner `α ≤ 0` (quads) or some of the 10 tets `V ≤ ε·v̄` (hexes).
    pub non_convex_cells: usize,
    /// Quad-specific results.
    pub quad: Option<QuadSummary>,
    /// Hex-specific results.
    pub hex: Option<HexSummary>,
}

fn summaries(cols: &[(&'static str, Vec<f64>)]) -> Vec<MetricSummary> {
    cols.iter()
        .filter_map(|(name, v)| MetricSummary::new(name, v))
        .collect()
}

impl QualityReport {
    /// Report of a quad mesh with [`ReportOptions::default`]. Interior singularities are
    /// computed from the connectivity (see [`interior_singularities`]).
    pub fn for_quads<M: HasQuadCells + ?Sized>(mesh: &M) -> Self {
        Self::for_quads_with(mesh, &ReportOptions::default())
    }

    /// Report of a quad mesh with explicit options.
    pub fn for_quads_with<M: HasQuadCells + ?Sized>(mesh: &M, opts: &ReportOptions) -> Self {
        let per_cell: Vec<QuadMetrics> = quad_metrics_per_cell(mesh);
        let cols: Vec<(&'static str, Vec<f64>)> = super::mesh::quad_arrays(&per_cell)
            .into_iter()
            .filter(|(n, _)| *n != "convex")
            .collect();
        let alpha = AlphaStats::from_metrics(&per_cell);
        let mu: Vec<f64> = per_cell.iter().map(|m| m.mu).collect();
        let val = interior_singularities(mesh);
        Self {
            cell_kind: CellKind::Quad,
            num_cells: mesh.num_quads(),
            num_nodes: mesh.num_nodes(),
            metrics: summaries(&cols),
            non_convex_cells: alpha.non_convex_cells,
            quad: Some(QuadSummary {
                alpha_mean: alpha.mean,
                alpha_min: alpha.min,
                alpha_min_ratio: alpha.min_over_mean(),
                epsilon: opts.epsilon,
                eps_convex: alpha.is_eps_convex(opts.epsilon),
                interior_nodes: val.interior_nodes,
                interior_singularities: val.count(),
                mu_bands: MuBands::new(&mu),
                mu_histogram: MuHistogram::new(&mu, opts.histogram_bins),
                high_quality: is_high_quality(&mu),
            }),
            hex: None,
        }
    }

    /// Report of a hex mesh with [`ReportOptions::default`]: Verdict hex metrics, the
    /// 10-tetrahedra non-convex count and the face-planarity maximum `|cos θ|`.
    pub fn for_hexes<M: HasHexCells + ?Sized>(mesh: &M) -> Self {
        Self::for_hexes_with(mesh, &ReportOptions::default())
    }

    /// Report of a hex mesh with explicit options.
    pub fn for_hexes_with<M: HasHexCells + ?Sized>(mesh: &M, opts: &ReportOptions) -> Self {
        let per_cell: Vec<HexMetrics> = hex_metrics_per_cell(mesh);
        let cols: Vec<(&'static str, Vec<f64>)> = super::mesh::hex_arrays(&per_cell)
            .into_iter()
            .filter(|(n, _)| *n != "convex_10tet")
            .collect();
        let (mut tmin, mut tmax) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut max_cos: f64 = 0.0;
        let mut non_planar = 0;
        for m in &per_cell {
            for &v in &m.tet_dets {
                tmin = tmin.min(v);
                tmax = tmax.max(v);
            }
            let c = m.max_face_cos();
            max_cos = max_cos.max(c);
            if c > opts.planarity_tolerance {
                non_planar += 1;
            }
        }
        if per_cell.is_empty() {
            (tmin, tmax) = (0.0, 0.0);
        }
        Self {
            cell_kind: CellKind::Hex,
            num_cells: mesh.num_hexes(),
            num_nodes: mesh.num_nodes(),
            metrics: summaries(&cols),
            non_convex_cells: hex_non_convex_from(&per_cell, opts.tet_epsilon),
            quad: None,
            hex: Some(HexSummary {
                tet_min: tmin,
                tet_max: tmax,
                tet_mean: hex_tet_mean(&per_cell),
                tet_epsilon: opts.tet_epsilon,
                max_face_cos: max_cos,
                planarity_tolerance: opts.planarity_tolerance,
                non_planar_cells: non_planar,
            }),
        }
    }

    /// The summary row of metric `name`, if present.
    pub fn metric(&self, name: &str) -> Option<&MetricSummary> {
        self.metrics.iter().find(|m| m.name == name)
    }

    /// Pretty JSON (`serde_json::to_string_pretty`).
    pub fn to_json(&self) -> String {
        // Serialising plain numbers, strings, vectors and enums cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

/// Formats a metric value: `DBL_MAX` for Verdict's infinity, fixed or scientific notation.
fn num(v: f64) -> String {
    if v >= DBL_MAX {
        "DBL_MAX".to_string()
    } else if v <= -DBL_MAX {
        "-DBL_MAX".to_string()
    } else if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

impl fmt::Display for QualityReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.cell_kind {
            CellKind::Quad => "quad",
            CellKind::Hex => "hex",
        };
        writeln!(f, "Mesh quality report ({kind} mesh)")?;
        writeln!(f, "  cells: {}   nodes: {}", self.num_cells, self.num_nodes)?;
        writeln!(
            f,
            "  {:<16} {:>12} {:>12} {:>12} {:>12} {:>12}",
            "metric", "min", "p5", "mean", "p95", "max"
        )?;
        for m in &self.metrics {
            write!(
                f,
                "  {:<16} {:>12} {:>12} {:>12} {:>12} {:>12}",
                m.name,
                num(m.min),
                num(m.p5),
                num(m.mean),
                num(m.p95),
                num(m.max)
            )?;
            if m.nan > 0 {
                write!(f, "   ({} NaN skipped)", m.nan)?;
            }
            writeln!(f)?;
        }
        writeln!(f, "  non-convex cells: {}", self.non_convex_cells)?;
        if let Some(q) = &self.quad {
            writeln!(
                f,
                "  alpha: mean {}   min {}   min/mean {}   {}-convex: {}",
                num(q.alpha_mean),
                num(q.alpha_min),
                num(q.alpha_min_ratio),
                q.epsilon,
                if q.eps_convex { "yes" } else { "no" }
            )?;
            writeln!(
                f,
                "  interior nodes: {}   interior singularities (valence != 4): {}",
                q.interior_nodes, q.interior_singularities
            )?;
            writeln!(
                f,
                "  mu bands: >= 0.8: {:.1} %   0.4-0.8: {:.1} %   < 0.4: {:.1} %",
                q.mu_bands.good, q.mu_bands.fair, q.mu_bands.poor
            )?;
            let b = q.mu_histogram.counts.len();
            writeln!(
                f,
                "  mu histogram ({b} bins over [0, 1]; mu <= 0: {}):",
                q.mu_histogram.non_positive
            )?;
            let edges = q.mu_histogram.bin_edges();
            for (k, c) in q.mu_histogram.counts.iter().enumerate() {
                let close = if k + 1 == b { ']' } else { ')' };
                writeln!(
                    f,
                    "    [{:.3}, {:.3}{close} {c:>10}",
                    edges[k],
                    edges[k + 1]
                )?;
            }
            writeln!(
                f,
                "  verdict: {} (>= 85 % of cells with mu >= 0.8: {:.1} %)",
                if q.high_quality {
                    "HIGH QUALITY"
                } else {
                    "not high quality"
                },
                q.mu_bands.good
            )?;
        }
        if let Some(h) = &self.hex {
            writeln!(
                f,
                "  10-tet V = 6 vol: min {}   mean {}   max {}   (non-convex if V <= {} * mean)",
                num(h.tet_min),
                num(h.tet_mean),
                num(h.tet_max),
                h.tet_epsilon
            )?;
            writeln!(
                f,
                "  face planarity: max |cos| {}   cells with |cos| > {}: {}",
                num(h.max_face_cos),
                h.planarity_tolerance,
                h.non_planar_cells
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{StructuredGrid2, StructuredGrid3};
    use crate::unstructured::QuadMesh;
    use glam::{DVec2, DVec3};

    fn grid() -> StructuredGrid2 {
        StructuredGrid2::from_fn(7, 5, |i, j| {
            let (x, y) = (i as f64, j as f64);
            DVec2::new(x + 0.15 * y, y + 0.1 * (x * 0.7).sin())
        })
        .unwrap()
    }

    #[test]
    fn quad_report_contents() {
        let g = grid();
        let r = QualityReport::for_quads(&g);
        assert_eq!(r.cell_kind, CellKind::Quad);
        assert_eq!(r.num_cells, 24);
        assert_eq!(r.num_nodes, 35);
        assert_eq!(r.non_convex_cells, 0);
        let q = r.quad.as_ref().unwrap();
        assert_eq!(q.interior_nodes, 15);
        assert_eq!(q.interior_singularities, 0);
        assert_eq!(
            q.mu_histogram.counts.iter().sum::<usize>() + q.mu_histogram.non_positive,
            24
        );
        assert!(q.eps_convex);
        // each summary row is ordered
        for m in &r.metrics {
            assert!(m.min <= m.p5 && m.p5 <= m.p95 && m.p95 <= m.max, "{m:?}");
            assert!(m.min <= m.mean && m.mean <= m.max, "{m:?}");
        }
        assert!(r.metric("scaled_jacobian").is_some());
        assert!(r.metric("mu").is_some());
        assert!(r.hex.is_none());
    }

    #[test]
    fn metric_summary_percentiles() {
        // values 1..=20: p5 = rank ⌈1⌉ = 1, p95 = rank ⌈19⌉ = 19, mean 10.5
        let v: Vec<f64> = (1..=20).rev().map(f64::from).collect();
        let s = MetricSummary::new("x", &v).unwrap();
        assert_eq!((s.min, s.p5, s.p95, s.max), (1.0, 1.0, 19.0, 20.0));
        assert!((s.mean - 10.5).abs() < 1e-12);
        // DBL_MAX values keep the mean finite; NaN is skipped
        let s = MetricSummary::new("c", &[DBL_MAX, DBL_MAX, 1.0, f64::NAN]).unwrap();
        assert!(s.mean.is_finite());
        assert_eq!(s.nan, 1);
        assert_eq!(s.max, DBL_MAX);
        assert!(MetricSummary::new("e", &[]).is_none());
    }

    #[test]
    fn display_is_a_readable_table() {
        let r = QualityReport::for_quads(&grid());
        let s = r.to_string();
        println!("{s}");
        assert!(s.contains("Mesh quality report (quad mesh)"));
        assert!(s.contains("cells: 24   nodes: 35"));
        assert!(s.contains("scaled_jacobian"));
        assert!(s.contains("interior singularities (valence != 4): 0"));
        assert!(s.contains("mu histogram (20 bins"));
        assert!(s.contains("verdict:"));
        // one line per metric, per bin, plus headers
        assert!(s.lines().count() > r.metrics.len() + 20);
    }

    /// Compares two JSON trees: same shape, same strings/integers/bools, floats within a few
    /// ulps (serde_json's default float parser is not always correctly rounded).
    fn same_json(a: &serde_json::Value, b: &serde_json::Value) -> bool {
        use serde_json::Value as V;
        match (a, b) {
            (V::Number(x), V::Number(y)) => match (x.as_u64(), y.as_u64()) {
                (Some(p), Some(q)) => p == q,
                _ => {
                    let (p, q) = (x.as_f64().unwrap(), y.as_f64().unwrap());
                    p == q || (p - q).abs() <= 4.0 * f64::EPSILON * p.abs().max(q.abs())
                }
            },
            (V::Array(x), V::Array(y)) => {
                x.len() == y.len() && x.iter().zip(y).all(|(p, q)| same_json(p, q))
            }
            (V::Object(x), V::Object(y)) => {
                x.len() == y.len()
                    && x.iter()
                        .all(|(k, v)| y.get(k).is_some_and(|w| same_json(v, w)))
            }
            _ => a == b,
        }
    }

    fn assert_round_trip(r: &QualityReport) {
        let js = r.to_json();
        let back: QualityReport = serde_json::from_str(&js).unwrap();
        let (va, vb) = (
            serde_json::to_value(r).unwrap(),
            serde_json::to_value(&back).unwrap(),
        );
        assert!(same_json(&va, &vb), "{js}");
        // integers, flags, names and structure are exact
        assert_eq!(back.num_cells, r.num_cells);
        assert_eq!(back.non_convex_cells, r.non_convex_cells);
        assert_eq!(
            back.quad.as_ref().map(|q| &q.mu_histogram),
            r.quad.as_ref().map(|q| &q.mu_histogram)
        );
        assert_eq!(
            back.metrics.iter().map(|m| &m.name).collect::<Vec<_>>(),
            r.metrics.iter().map(|m| &m.name).collect::<Vec<_>>()
        );
        // and the text form is stable
        assert_eq!(
            back.to_string().lines().count(),
            r.to_string().lines().count()
        );
    }

    #[test]
    fn json_round_trip() {
        // include a degenerate cell so DBL_MAX values and non-positive μ are serialised
        let mut nodes: Vec<DVec2> = grid().into_nodes();
        nodes.push(DVec2::new(50.0, 50.0));
        let mut cells: Vec<[usize; 4]> = (0..24).map(|c| grid().quad(c)).collect();
        cells.push([35, 35, 35, 35]);
        let m = QuadMesh::new(nodes, cells).unwrap();
        let r = QualityReport::for_quads(&m);
        assert_eq!(r.non_convex_cells, 1);
        assert_eq!(r.metric("condition").unwrap().max, DBL_MAX);
        assert_round_trip(&r);
        let back: QualityReport = serde_json::from_str(&r.to_json()).unwrap();
        assert_eq!(back.metric("condition").unwrap().max, DBL_MAX);

        let g3 = StructuredGrid3::from_fn(3, 2, 2, |i, j, k| {
            DVec3::new(i as f64, j as f64 + 0.1 * (k * i) as f64, k as f64)
        })
        .unwrap();
        let rh = QualityReport::for_hexes(&g3);
        assert_round_trip(&rh);
        println!("{rh}");
        assert!(rh.to_string().contains("face planarity"));
    }

    #[test]
    fn hex_report_contents() {
        let g =
            StructuredGrid3::from_fn(3, 3, 3, |i, j, k| DVec3::new(i as f64, j as f64, k as f64))
                .unwrap();
        let r = QualityReport::for_hexes(&g);
        assert_eq!(r.cell_kind, CellKind::Hex);
        assert_eq!(r.num_cells, 8);
        assert_eq!(r.non_convex_cells, 0);
        let h = r.hex.as_ref().unwrap();
        assert_eq!(h.tet_min, 1.0);
        assert_eq!(h.tet_max, 2.0);
        assert_eq!(h.max_face_cos, 0.0);
        assert_eq!(h.non_planar_cells, 0);
        let sj = r.metric("scaled_jacobian").unwrap();
        assert_eq!((sj.min, sj.max), (1.0, 1.0));
    }

    #[test]
    fn empty_mesh_report() {
        let m = QuadMesh::new(vec![], vec![]).unwrap();
        let r = QualityReport::for_quads(&m);
        assert_eq!(r.num_cells, 0);
        assert!(r.metrics.is_empty());
        let q = r.quad.as_ref().unwrap();
        assert!(!q.high_quality);
        assert!(!q.eps_convex);
        assert_round_trip(&r);
        assert!(r.to_string().contains("cells: 0"));
    }
}
