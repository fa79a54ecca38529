//! The run report ([`HexRunReport`], written as `report.json`): the measures of the mesh at
//! each stage, the statistics of each algorithm, and the histograms of App. B.6 as data.

use serde::{Deserialize, Serialize};
use unamalla_mesh::hexgen::{CellClass, ClassCounts, PlanarityCounts};
use unamalla_mesh::quality::{hex_metrics_per_cell, HexMetrics, MetricSummary};
use unamalla_mesh::{HasHexCells, StructuredGrid3};
use unamalla_optim::SmoothReport;

use crate::HexRunOptions;

/// Mesh measures at one stage of a run (the convexity test of [Cortés Aguirre 2012, §3.2.1,
/// (3.35)], the planarity of §4.1 and the information panel of §B.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexMeasures {
    /// Cells failing the 10-tetrahedra test `V > ε·v̄` (ε of Algorithm A, `v̄` the mean of all
    /// tetrahedron values `V = 6·volume`).
    pub non_convex_cells: usize,
    /// The ε of that test.
    pub eps: f64,
    /// Interior cells with some face `|cos| ≥` the planarity tolerance (non-hexahedral).
    pub non_hex_interior_cells: usize,
    /// Faces of interior cells (counted once per cell) with `|cos| ≥` tolerance.
    pub non_planar_interior_faces: usize,
    /// Largest face `|cos|` over the interior cells (0 without interior cells).
    pub max_abs_cos: f64,
    /// Interior cells with some face whose tetrahedron volume is `|V_l| ≥ ε_v`
    /// (criterion 1 of §4.1, Table 4.1's "non-hex" column; `HexRunOptions::planarity_volume_tol`).
    #[serde(default)]
    pub non_hex_interior_cells_volume: usize,
    /// Largest face tetrahedron volume `|V_l|` over the interior cells (Table 4.1's "max Vol").
    #[serde(default)]
    pub max_face_volume: f64,
    /// Smallest face `|cos|` over the interior cells.
    pub min_abs_cos: f64,
    /// Largest face `|cos|` over all cells.
    pub max_abs_cos_all: f64,
    /// Smallest tetrahedron signed volume (of the 10 per cell).
    pub min_tet_volume: f64,
    /// Largest tetrahedron signed volume.
    pub max_tet_volume: f64,
    /// Verdict hex scaled Jacobian: minimum over the cells.
    pub min_scaled_jacobian: f64,
    /// Verdict hex scaled Jacobian: 5th percentile.
    pub p5_scaled_jacobian: f64,
}

/// Iterations and time of one algorithm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseStats {
    /// Solver iterations (all continuation steps and the refinement).
    pub iterations: usize,
    /// Continuation steps (ω values for A, μ values for B).
    pub continuation_steps: usize,
    /// Wall time of the algorithm in seconds.
    pub seconds: f64,
    /// The final status message (UNAMALLA wording).
    pub status: String,
    /// Final `ω` (absolute).
    pub omega: Option<f64>,
    /// Final `μ` (Algorithm B).
    pub mu: Option<f64>,
    /// Final functional value.
    pub f: f64,
    /// Final gradient norm.
    pub gnorm: f64,
}

/// A histogram over `[lo, hi]` in equal bins (the last bin closed).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Histogram {
    /// Bin edges (`bins + 1` values).
    pub edges: Vec<f64>,
    /// Counts per bin.
    pub counts: Vec<usize>,
}

impl Histogram {
    fn equal(values: &[f64], bins: usize) -> Self {
        let bins = bins.max(1);
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !(lo.is_finite() && hi.is_finite()) {
            return Self {
                edges: vec![0.0, 1.0],
                counts: vec![0],
            };
        }
        let w = (hi - lo) / bins as f64;
        let edges = (0..=bins).map(|k| lo + w * k as f64).collect();
        let mut counts = vec![0; bins];
        for &v in values {
            let k = if w > 0.0 {
                (((v - lo) / w) as usize).min(bins - 1)
            } else {
                0
            };
            counts[k] += 1;
        }
        Self { edges, counts }
    }
}

/// The histograms of App. B.6 as data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexHistograms {
    /// Tetrahedra (10 per cell) with `V > 0`.
    pub tets_positive: usize,
    /// Tetrahedra with `V = 0`.
    pub tets_zero: usize,
    /// Tetrahedra with `V < 0`.
    pub tets_negative: usize,
    /// Interior-cell faces (6 per cell) by `|cos|` decade: bin `k` holds
    /// `10^{k−7} ≤ |cos| < 10^{k−6}` for `k = 1..6`, bin 0 `|cos| < 10⁻⁶`, bin 7 `|cos| ≥ 0.1`.
    pub face_cos_decades: Vec<usize>,
    /// Decade labels of `face_cos_decades`.
    pub face_cos_labels: Vec<String>,
    /// Interior-cell faces with `|cos| <` tolerance.
    pub faces_planar: usize,
    /// Interior-cell faces with `|cos| ≥` tolerance.
    pub faces_non_planar: usize,
    /// Lengths of all mesh edges (each once).
    pub edge_lengths: Histogram,
    /// App. B.6 histogram (1): per interior-cell face (6 per cell), the smallest height of the
    /// tetrahedron on its four vertices ([`unamalla_mesh::quality::face_height_area`]); 0 for
    /// a planar face.
    #[serde(default)]
    pub face_min_heights: Histogram,
    /// App. B.6 histogram (1): per interior-cell face, the smallest triangle area of that
    /// tetrahedron.
    #[serde(default)]
    pub face_min_areas: Histogram,
}

/// The report of [`run_hex`](crate::run_hex), written as `report.json`. The flat fields
/// describe the final mesh; `start`, `after_a`, `after_b` each stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexRunReport {
    /// Region name (built-in case or directory).
    pub case: String,
    /// Nodes per direction.
    pub dims: (usize, usize, usize),
    /// Number of cells.
    pub cells: usize,
    /// Number of interior cells (no boundary node).
    pub interior_cells: usize,
    /// Final non-convex cells.
    pub non_convex_cells: usize,
    /// Final non-hexahedral interior cells.
    pub non_hex_interior_cells: usize,
    /// Final max face `|cos|` over the interior cells.
    pub max_abs_cos: f64,
    /// Final smallest tetrahedron volume.
    pub min_tet_volume: f64,
    /// Final largest tetrahedron volume.
    pub max_tet_volume: f64,
    /// Final minimum Verdict scaled Jacobian.
    pub min_scaled_jacobian: f64,
    /// Final 5th percentile of the scaled Jacobian.
    pub p5_scaled_jacobian: f64,
    /// Iterations of A and B together.
    pub iterations: usize,
    /// Wall time of A and B together, seconds.
    pub seconds: f64,
    /// Perturbation amplitude applied before the run (0 if none; informational, set by the
    /// caller).
    pub perturbation: f64,
    /// Seed of the perturbation.
    pub seed: u64,
    /// Corner / edge / face / interior cell counts.
    pub classes: ClassCounts,
    /// Number of fixed tetrahedra and the smallest `V` among them (admissibility, Def. 11).
    pub fixed_tets: (usize, f64),
    /// Appendix A counts (sizes ≥ 4 only).
    pub counting: Option<PlanarityCounts>,
    /// The start.
    pub start: HexMeasures,
    /// After Algorithm A.
    pub after_a: Option<HexMeasures>,
    /// After Algorithm B.
    pub after_b: Option<HexMeasures>,
    /// Algorithm A.
    pub algorithm_a: Option<PhaseStats>,
    /// Algorithm B (absent if not asked or A did not reach convexity).
    pub algorithm_b: Option<PhaseStats>,
    /// Histograms of the final mesh.
    pub histograms: HexHistograms,
    /// The harmonic energy of the final mesh under the readings of the thesis's
    /// normalisation ([`unamalla_functionals::energy_variants`], same Jacobian scaling as the
    /// run): `printed` is (3.27) at `ω → 0`, the value Algorithm A's `f` tends to;
    /// `per_decomposition = 2·printed` is the reading that matches the thesis's sphere
    /// (§3.4.3, `f = 2.26543`; see the "energy values" section of `docs/results.md`).
    #[serde(default)]
    pub energy: Option<unamalla_functionals::EnergyVariants>,
    /// Options used.
    pub options: HexRunOptions,
}

impl HexRunReport {
    /// Pretty JSON.
    pub fn to_json(&self) -> String {
        // plain numbers (all finite), strings, vectors: cannot fail
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

/// Per-cell metrics and the stage measures of a grid.
pub(crate) fn measure(
    grid: &StructuredGrid3,
    classes: &[CellClass],
    eps: f64,
    tol: f64,
    vol_tol: f64,
) -> (HexMeasures, Vec<HexMetrics>) {
    let per_cell = hex_metrics_per_cell(grid);
    let n = per_cell.len().max(1);
    let vbar = per_cell
        .iter()
        .map(|c| c.tet_dets.iter().sum::<f64>())
        .sum::<f64>()
        / (10 * n) as f64;
    let thr = eps * vbar;
    let mut m = HexMeasures {
        non_convex_cells: 0,
        eps,
        non_hex_interior_cells: 0,
        non_planar_interior_faces: 0,
        max_abs_cos: 0.0,
        non_hex_interior_cells_volume: 0,
        max_face_volume: 0.0,
        min_abs_cos: 0.0,
        max_abs_cos_all: 0.0,
        min_tet_volume: f64::INFINITY,
        max_tet_volume: f64::NEG_INFINITY,
        min_scaled_jacobian: 0.0,
        p5_scaled_jacobian: 0.0,
    };
    let mut min_cos = f64::INFINITY;
    for (c, cm) in per_cell.iter().enumerate() {
        if !cm.tet_dets.iter().all(|&v| v > thr) {
            m.non_convex_cells += 1;
        }
        for &v in &cm.tet_dets {
            m.min_tet_volume = m.min_tet_volume.min(v / 6.0);
            m.max_tet_volume = m.max_tet_volume.max(v / 6.0);
        }
        m.max_abs_cos_all = m.max_abs_cos_all.max(cm.max_face_cos());
        if classes[c] == CellClass::Interior {
            let bad = cm.face_cos.iter().filter(|&&k| k >= tol).count();
            m.non_planar_interior_faces += bad;
            m.non_hex_interior_cells += (bad > 0) as usize;
            for &k in &cm.face_cos {
                m.max_abs_cos = m.max_abs_cos.max(k);
                min_cos = min_cos.min(k);
            }
            m.non_hex_interior_cells_volume += cm.face_vol.iter().any(|&v| v >= vol_tol) as usize;
            m.max_face_volume = cm.face_vol.iter().fold(m.max_face_volume, |a, &v| a.max(v));
        }
    }
    if min_cos.is_finite() {
        m.min_abs_cos = min_cos;
    }
    if per_cell.is_empty() {
        (m.min_tet_volume, m.max_tet_volume) = (0.0, 0.0);
    }
    let sj: Vec<f64> = per_cell.iter().map(|c| c.scaled_jacobian).collect();
    if let Some(s) = MetricSummary::new("scaled_jacobian", &sj) {
        m.min_scaled_jacobian = s.min;
        m.p5_scaled_jacobian = s.p5;
    }
    (m, per_cell)
}

pub(crate) fn histograms(
    grid: &StructuredGrid3,
    classes: &[CellClass],
    per_cell: &[HexMetrics],
    tol: f64,
    bins: usize,
) -> HexHistograms {
    let (mut pos, mut zero, mut neg) = (0, 0, 0);
    let mut dec = [0usize; 8];
    let (mut planar, mut non_planar) = (0, 0);
    let (mut heights, mut areas) = (Vec::new(), Vec::new());
    for (c, cm) in per_cell.iter().enumerate() {
        for &v in &cm.tet_dets {
            if v > 0.0 {
                pos += 1;
            } else if v < 0.0 {
                neg += 1;
            } else {
                zero += 1;
            }
        }
        if classes[c] == CellClass::Interior {
            let h = grid.hex_points(c);
            for f in unamalla_mesh::quality::PLANARITY_FACES {
                let (fh, fa) =
                    unamalla_mesh::quality::face_height_area([h[f[0]], h[f[1]], h[f[2]], h[f[3]]]);
                heights.push(fh);
                areas.push(fa);
            }
            for &k in &cm.face_cos {
                let b = if k <= 0.0 {
                    0
                } else {
                    ((k.log10() + 7.0).floor().max(0.0) as usize).min(7)
                };
                dec[b] += 1;
                if k < tol {
                    planar += 1;
                } else {
                    non_planar += 1;
                }
            }
        }
    }
    let labels: Vec<String> = ["<1e-6", "1e-6", "1e-5", "1e-4", "1e-3", "1e-2", ">=1e-1"]
        .iter()
        .map(|l| l.to_string())
        .collect();
    // merge bins 6 and 7 (|cos| ≥ 0.1) into the last label
    let mut d7 = dec[..6].to_vec();
    d7.push(dec[6] + dec[7]);
    let (m, n, p) = grid.dims();
    let mut lens = Vec::with_capacity(3 * m * n * p);
    for k in 0..p {
        for j in 0..n {
            for i in 0..m {
                let q = grid.node(i, j, k);
                if i + 1 < m {
                    lens.push(q.distance(grid.node(i + 1, j, k)));
                }
                if j + 1 < n {
                    lens.push(q.distance(grid.node(i, j + 1, k)));
                }
                if k + 1 < p {
                    lens.push(q.distance(grid.node(i, j, k + 1)));
                }
            }
        }
    }
    HexHistograms {
        tets_positive: pos,
        tets_zero: zero,
        tets_negative: neg,
        face_cos_decades: d7,
        face_cos_labels: labels,
        faces_planar: planar,
        faces_non_planar: non_planar,
        edge_lengths: Histogram::equal(&lens, bins),
        face_min_heights: Histogram::equal(&heights, bins),
        face_min_areas: Histogram::equal(&areas, bins),
    }
}

pub(crate) fn phase(rep: &SmoothReport, iterations: usize, seconds: f64) -> PhaseStats {
    PhaseStats {
        iterations,
        continuation_steps: rep.continuation_steps,
        seconds,
        status: rep.status.to_string(),
        omega: rep.omega,
        mu: rep.mu,
        f: rep.f,
        gnorm: rep.gnorm,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{histograms_svg, run_hex, HexAlgorithm, HexCase};
    use unamalla_optim::NullObserver;

    #[test]
    fn histograms_count_every_tet_face_and_edge() {
        let mut g = HexCase::Box.initial_grid((5, 5, 5)).unwrap();
        let opts = HexRunOptions {
            algorithm: HexAlgorithm::A,
            ..HexRunOptions::default()
        };
        let r = run_hex(&mut g, &opts, &mut NullObserver).unwrap();
        let h = &r.histograms;
        assert_eq!(h.tets_positive + h.tets_zero + h.tets_negative, 10 * 64);
        // interior cells of 5³: 2³ = 8, 6 faces each
        assert_eq!(r.interior_cells, 8);
        assert_eq!(h.faces_planar + h.faces_non_planar, 48);
        assert_eq!(h.face_cos_decades.iter().sum::<usize>(), 48);
        // edges of a 5³ grid: 3·4·5·5
        assert_eq!(h.edge_lengths.counts.iter().sum::<usize>(), 300);
        let svg = histograms_svg(h, "box");
        assert!(svg.starts_with("<svg") && svg.contains("edge lengths"));
    }
}
