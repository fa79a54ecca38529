//! One run of the product: the perturbation of the start, the options, and [`run_hex`]
//! (admissibility, Algorithm A, Algorithm B, the measures of every stage).

use std::sync::Arc;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use unamalla_functionals::{HexTopology, Scaling3};
use unamalla_mesh::hexgen::{
    admissibility, class_counts, classify_cells, perturb_interior, perturb_until_nonconvex,
    planarity_counts, CellClass,
};
use unamalla_mesh::{DVec3, HasHexCells, HasNodes, StructuredGrid3};
use unamalla_optim::drivers::{
    coplanarity_continuation, omega_continuation_hex, CoplanarityOptions, OmegaOptions,
};
use unamalla_optim::monitor::Session;
use unamalla_optim::{Observer, SolverOptions};

use crate::report::{histograms, measure, phase};
use crate::{HexError, HexRunReport};

/// How the start is perturbed ([`perturb_interior`]: each free node moves by
/// `s·h_v·u`, `h_v` its shortest edge, `u` uniform in the unit ball).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Perturbation {
    /// No perturbation.
    None,
    /// A fixed amplitude `s`.
    Amplitude(f64),
    /// The smallest amplitude `0.02·1.1^t` (t = 0, 1, …, ≤ 80 tries) giving at least this
    /// many non-convex cells.
    AtLeast {
        /// Target number of non-convex cells.
        cells: usize,
    },
}

impl Perturbation {
    /// Applies the perturbation with `seed`; returns `(amplitude used, non-convex cells)`.
    pub fn apply(&self, grid: &mut StructuredGrid3, seed: u64) -> Result<(f64, usize), HexError> {
        match *self {
            Perturbation::None => {
                Ok((0.0, unamalla_mesh::quality::hex_non_convex_count(grid, 0.0)))
            }
            Perturbation::Amplitude(s) => {
                perturb_interior(grid, s, seed)?;
                Ok((s, unamalla_mesh::quality::hex_non_convex_count(grid, 0.0)))
            }
            Perturbation::AtLeast { cells } => {
                Ok(perturb_until_nonconvex(grid, cells, 0.02, seed, 80)?)
            }
        }
    }
}

/// Which algorithms to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum HexAlgorithm {
    /// Algorithm A only.
    A,
    /// Algorithm A, then Algorithm B.
    #[default]
    AB,
}

/// The tetrahedron Jacobian scaling: [Cortés Aguirre 2012, §3.2] prints raw vertex differences,
/// but its reported values fit only unit-parametric Jacobians (our reading; see
/// `unamalla_functionals::hex`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum HexScaling {
    /// Raw vertex differences, as printed in the thesis.
    Index,
    /// Unit-parametric (`r_ξ ≈ (m−1)(r₂ − r₁)`), which fits the thesis's reported values.
    #[default]
    Parametric,
}

/// Options of [`run_hex`]. Build them from [`HexRunOptions::default`] and the setters (or
/// assign the fields of a default value); new options may be added in minor releases.
///
/// ```
/// use unamalla_hex::{HexAlgorithm, HexRunOptions, HexScaling};
///
/// let mut opts = HexRunOptions::default()
///     .algorithm(HexAlgorithm::A)
///     .scaling(HexScaling::Index)
///     .planarity_tol(0.05)
///     .planarity_volume_tol(1e-5)
///     .histogram_bins(10);
/// opts.omega.solver.max_iter = 20;
/// assert_eq!(opts.algorithm, HexAlgorithm::A);
/// assert_eq!(opts.scaling, HexScaling::Index);
/// assert_eq!((opts.planarity_tol, opts.planarity_volume_tol), (0.05, 1e-5));
/// assert_eq!((opts.histogram_bins, opts.omega.solver.max_iter), (10, 20));
/// let defaults = HexRunOptions::default();
/// assert_eq!(opts.coplanarity, defaults.coplanarity);
/// let opts = opts.omega(defaults.omega.clone()).coplanarity(defaults.coplanarity.clone());
/// assert_eq!(opts.omega, defaults.omega);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct HexRunOptions {
    /// A or A + B.
    pub algorithm: HexAlgorithm,
    /// Jacobian scaling of `H_ω`.
    pub scaling: HexScaling,
    /// Algorithm A (ε = 10⁻⁴ of Tables 3.1–3.2; ω₀ = 0.1 relative to the mean tetrahedron
    /// Jacobian; the thesis's absolute ω₀ = 200 has no scale-free meaning).
    pub omega: OmegaOptions,
    /// Algorithm B (`μ₀ = 500`, `μ ← 0.1μ` while `μ > 10⁻¹²` and some interior face has
    /// `|cos| > 10⁻³`, ≤ 50 iterations per step; `ε_n = 10⁻²`).
    pub coplanarity: CoplanarityOptions,
    /// Planarity tolerance on `|cos|` for "non-hexahedral" cells (criterion 2: 10⁻²).
    pub planarity_tol: f64,
    /// Tolerance `ε_v` of the volume criterion (criterion 1 of Cortés Aguirre 2012 §4.1,
    /// eq. (4.1): a face is planar iff the tetrahedron on its four vertices has
    /// `|V_l| < ε_v`; thesis value 10⁻⁶). Reported beside criterion 2 (Table 4.1), never
    /// used to steer Algorithm B.
    #[serde(default = "default_volume_tol")]
    pub planarity_volume_tol: f64,
    /// Bins of the edge-length histogram.
    pub histogram_bins: usize,
}

impl Default for HexRunOptions {
    fn default() -> Self {
        let solver = SolverOptions::default().max_iter(100).ftol(1e-8).gtol(1e-4);
        Self {
            algorithm: HexAlgorithm::AB,
            scaling: HexScaling::Parametric,
            omega: OmegaOptions::default()
                .eps(1e-4)
                // ω₀ = 0.1·(mean tetrahedron Jacobian): on the perturbed sphere 20³ this took
                // 11 iterations and left 1892 non-hexahedral interior cells, against 14 and
                // 2216 with ω₀ = v̄ (measured; docs/results.md)
                .omega0_rel(0.1)
                .solver(solver.clone()),
            coplanarity: CoplanarityOptions::default().solver(solver.max_iter(50)),
            planarity_tol: 1e-2,
            planarity_volume_tol: default_volume_tol(),
            histogram_bins: 20,
        }
    }
}

impl HexRunOptions {
    /// Sets [`algorithm`](Self::algorithm): A or A + B.
    #[must_use]
    pub fn algorithm(mut self, algorithm: HexAlgorithm) -> Self {
        self.algorithm = algorithm;
        self
    }

    /// Sets [`scaling`](Self::scaling): Jacobian scaling of `H_ω`.
    #[must_use]
    pub fn scaling(mut self, scaling: HexScaling) -> Self {
        self.scaling = scaling;
        self
    }

    /// Sets [`omega`](Self::omega).
    #[must_use]
    pub fn omega(mut self, omega: OmegaOptions) -> Self {
        self.omega = omega;
        self
    }

    /// Sets [`coplanarity`](Self::coplanarity).
    #[must_use]
    pub fn coplanarity(mut self, coplanarity: CoplanarityOptions) -> Self {
        self.coplanarity = coplanarity;
        self
    }

    /// Sets [`planarity_tol`](Self::planarity_tol).
    #[must_use]
    pub fn planarity_tol(mut self, planarity_tol: f64) -> Self {
        self.planarity_tol = planarity_tol;
        self
    }

    /// Sets [`planarity_volume_tol`](Self::planarity_volume_tol).
    #[must_use]
    pub fn planarity_volume_tol(mut self, planarity_volume_tol: f64) -> Self {
        self.planarity_volume_tol = planarity_volume_tol;
        self
    }

    /// Sets [`histogram_bins`](Self::histogram_bins): bins of the edge-length histogram.
    #[must_use]
    pub fn histogram_bins(mut self, histogram_bins: usize) -> Self {
        self.histogram_bins = histogram_bins;
        self
    }
}

fn default_volume_tol() -> f64 {
    1e-6
}

/// Runs Algorithm A (and B if asked and A reached convexity) on `grid` in place, with the
/// boundary nodes fixed, and returns the report. The start must be admissible.
pub fn run_hex(
    grid: &mut StructuredGrid3,
    opts: &HexRunOptions,
    observer: &mut dyn Observer,
) -> Result<HexRunReport, HexError> {
    let dims = grid.dims();
    let classes = classify_cells(grid);
    let adm = admissibility(grid);
    if let Some(v) = adm.violations.first() {
        return Err(HexError::Inadmissible {
            cell: v.cell,
            tet: v.tet,
            v: v.v,
            count: adm.violations.len(),
        });
    }
    let eps = opts.omega.eps;
    let tol = opts.planarity_tol;
    let vol_tol = opts.planarity_volume_tol;
    let (start, _) = measure(grid, &classes, eps, tol, vol_tol);
    let scaling = match opts.scaling {
        HexScaling::Index => Scaling3::Index,
        HexScaling::Parametric => Scaling3::Parametric {
            m: dims.0,
            n: dims.1,
            p: dims.2,
        },
    };
    let topo = Arc::new(HexTopology::from_mesh(&*grid)?);
    let mut x = topo.initial_x();
    let probe = unamalla_functionals::HexFunctional::h_omega(topo.clone(), 1.0, scaling)?;
    let mut session = Session::new(&probe, &x, observer);
    let t0 = Instant::now();
    let ra = omega_continuation_hex(&topo, scaling, &mut x, &opts.omega, &mut session)?;
    let ta = t0.elapsed().as_secs_f64();
    let it_a = ra.iterations();
    topo.scatter(&x, grid.nodes_mut());
    let (after_a, _) = measure(grid, &classes, eps, tol, vol_tol);
    let mut algorithm_b = None;
    let mut after_b = None;
    let mut seconds = ta;
    let mut iterations = it_a;
    if opts.algorithm == HexAlgorithm::AB && ra.convex && ra.status.convex() == Some(true) {
        let t1 = Instant::now();
        let rb = coplanarity_continuation(&topo, scaling, &mut x, &opts.coplanarity, &mut session)?;
        let tb = t1.elapsed().as_secs_f64();
        let it_b = rb.iterations().saturating_sub(it_a);
        topo.scatter(&x, grid.nodes_mut());
        after_b = Some(measure(grid, &classes, eps, tol, vol_tol).0);
        algorithm_b = Some(phase(&rb, it_b, tb));
        seconds += tb;
        iterations += it_b;
    }
    let (fin, per_cell) = measure(grid, &classes, eps, tol, vol_tol);
    let hist = histograms(grid, &classes, &per_cell, tol, opts.histogram_bins);
    let cells: Vec<[DVec3; 8]> = (0..grid.num_hexes()).map(|c| grid.hex_points(c)).collect();
    let energy = unamalla_functionals::energy_variants(&cells, scaling).ok();
    Ok(HexRunReport {
        case: String::new(),
        dims,
        cells: grid.num_cells(),
        interior_cells: classes
            .iter()
            .filter(|c| **c == CellClass::Interior)
            .count(),
        non_convex_cells: fin.non_convex_cells,
        non_hex_interior_cells: fin.non_hex_interior_cells,
        max_abs_cos: fin.max_abs_cos,
        min_tet_volume: fin.min_tet_volume,
        max_tet_volume: fin.max_tet_volume,
        min_scaled_jacobian: fin.min_scaled_jacobian,
        p5_scaled_jacobian: fin.p5_scaled_jacobian,
        iterations,
        seconds,
        perturbation: 0.0,
        seed: 0,
        classes: class_counts(&classes),
        fixed_tets: (
            adm.fixed_tets,
            if adm.fixed_tets > 0 {
                adm.min_fixed_v
            } else {
                0.0
            },
        ),
        counting: planarity_counts(dims.0, dims.1, dims.2).ok(),
        start,
        after_a: Some(after_a),
        after_b,
        algorithm_a: Some(phase(&ra, it_a, ta)),
        algorithm_b,
        histograms: hist,
        energy,
        options: opts.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HexCase;
    use unamalla_optim::NullObserver;

    #[test]
    fn algorithm_a_turns_the_perturbed_sphere_20_convex() {
        // the thesis's Esfera: 20³, perturbed to ≥ 22 non-convex cells
        // ([Cortés Aguirre 2012, §3.4.3])
        let case = HexCase::Sphere;
        let dims = case.default_size();
        let mut g = case.initial_grid(dims).unwrap();
        let (_, nc0) = case.default_perturbation(dims).apply(&mut g, 1).unwrap();
        assert!(nc0 >= 22, "{nc0}");
        let opts = HexRunOptions {
            algorithm: HexAlgorithm::A,
            ..HexRunOptions::default()
        };
        let r = run_hex(&mut g, &opts, &mut NullObserver).unwrap();
        assert!(r.start.non_convex_cells >= 22);
        assert_eq!(r.non_convex_cells, 0);
        assert!(r.min_tet_volume > 0.0);
        assert!(r.after_b.is_none());
        // the energy values (Cortés Aguirre 2012 §3.4.3: the sphere starts at f = 0.0261538
        // with ω = 200 and ends "harmonic and convex" at ω = 10⁻⁸ with f = 2.26543)
        let e = r.energy.expect("energy of the final mesh");
        let fa = r.algorithm_a.as_ref().expect("A ran").f;
        assert_eq!(e.non_positive, 0);
        // E ≥ 1 per tetrahedron (AM–GM), and A's f is H_ω at its last ω, below the energy
        // (the tangent continuation lies under 1/V): the two numbers must not be confused
        assert!(e.printed > 1.0 && fa < e.printed, "{fa} {e:?}");
        assert!((e.per_decomposition - 2.0 * e.printed).abs() < 1e-12);
        // E is scale-free and the parametric factors are equal for m = n = p: the Jacobian
        // scaling cannot explain a different value on the sphere
        let cells: Vec<[DVec3; 8]> = (0..g.num_hexes()).map(|c| g.hex_points(c)).collect();
        let idx = unamalla_functionals::energy_variants(&cells, Scaling3::Index).unwrap();
        assert!((idx.printed - e.printed).abs() < 1e-9 * e.printed);
        // none of the readings of the normalisation reaches the thesis's value (docs/results.md,
        // "energy values": the closest, volume weights and the per-decomposition sum, are 8–10 %
        // above it, the printed (3.27) 45 % below)
        let thesis = 2.26543;
        for v in [
            e.printed,
            e.per_decomposition,
            e.volume_weighted,
            e.interior_raw,
        ] {
            assert!((v - thesis).abs() > 0.05 * thesis, "{v} vs {thesis}");
        }
        // the thesis's start value is below what (3.27) allows at ω = 200 with parametric
        // scaling: λ ≥ V per tetrahedron (Hadamard + AM–GM), so
        // H_200 ≥ (1/10N_c) Σ V(2ω − V)/ω², V = (m−1)³·(the thesis's tet Jacobian)
        let mut g0 = case.initial_grid(dims).unwrap();
        case.default_perturbation(dims).apply(&mut g0, 1).unwrap();
        let scale = 19f64.powi(3);
        let (w, mut bound) = (200.0, 0.0);
        for c in 0..g0.num_hexes() {
            for v in unamalla_mesh::quality::hex_tet_jacobians(&g0.hex_points(c)) {
                let v = v * scale;
                bound += v * (2.0 * w - v) / (w * w);
            }
        }
        bound /= 10.0 * g0.num_hexes() as f64;
        assert!(bound > 1.5 * 0.0261538, "bound {bound}");
        // boundary nodes did not move: still on the unit sphere
        for k in [0, 19] {
            for j in 0..20 {
                for i in 0..20 {
                    assert!((g.node(i, j, k).length() - 1.0).abs() < 1e-14);
                }
            }
        }
    }
    #[test]
    fn the_ellipsoid_20_start_has_at_least_20_non_convex_cells() {
        let case = HexCase::Ellipsoid;
        let dims = case.default_size();
        let mut g = case.initial_grid(dims).unwrap();
        let (amp, nc0) = case.default_perturbation(dims).apply(&mut g, 1).unwrap();
        assert!(nc0 >= 45 && amp > 0.0, "{amp} {nc0}");
        assert!(admissibility(&g).is_admissible());
    }
    #[test]
    fn algorithm_b_makes_every_interior_face_of_the_box_planar() {
        // chapter 4: the 5³ harmonic convex mesh has non-planar cells; B fixes the interior ones
        let mut g = HexCase::Box.initial_grid((5, 5, 5)).unwrap();
        let r = run_hex(&mut g, &HexRunOptions::default(), &mut NullObserver).unwrap();
        let a = r.after_a.as_ref().unwrap();
        assert_eq!(a.non_convex_cells, 0);
        assert_eq!(
            a.non_hex_interior_cells, 8,
            "A alone leaves the interior cells non-planar"
        );
        assert!(r.algorithm_b.is_some());
        assert_eq!(r.non_convex_cells, 0);
        assert_eq!(r.non_hex_interior_cells, 0);
        // every face of every interior cell, checked directly
        let cls = classify_cells(&g);
        for (c, cl) in cls.iter().enumerate() {
            if *cl == CellClass::Interior {
                let h = g.hex_points(c);
                assert!(
                    unamalla_mesh::quality::max_face_cosine(&h) < 1e-2,
                    "cell {c}"
                );
            }
        }
        assert!(r.max_abs_cos < 1e-2);
    }
    #[test]
    fn default_b_schedule_stops_once_planar_and_beats_the_thesis_schedule() {
        // Pico-like 10³ (seed 1): the default schedule (μ₀ = 500, planarity stop at
        // |cos| ≤ 10⁻³) must end with every interior face planar and convex, and stop after
        // at most 6 μ steps (measured: 5, μ = 500 … 0.05), while the thesis's schedule always
        // runs its 12 steps (0.1 → 10⁻¹²: floating-point 0.1¹² is just above 10⁻¹²).
        let dims = (10, 10, 10);
        let run = |co: CoplanarityOptions| {
            let mut g = HexCase::Pico.initial_grid(dims).unwrap();
            HexCase::Pico
                .default_perturbation(dims)
                .apply(&mut g, 1)
                .unwrap();
            let mut o = HexRunOptions::default();
            o.coplanarity = co.solver(o.coplanarity.solver.clone());
            run_hex(&mut g, &o, &mut NullObserver).unwrap()
        };
        let d = run(HexRunOptions::default().coplanarity);
        let b = d.algorithm_b.as_ref().unwrap();
        assert_eq!(d.non_convex_cells, 0);
        assert_eq!(d.non_hex_interior_cells, 0);
        assert!(d.max_abs_cos <= 1e-3, "max|cos| {}", d.max_abs_cos);
        assert!(b.continuation_steps <= 6, "{} steps", b.continuation_steps);
        // the run says why it ended (it used to read "STOP by MAXITER condition")
        assert_eq!(b.status, "Convex grid, STOP by PLANARITY condition");
        let t = run(CoplanarityOptions::thesis());
        assert_ne!(
            t.algorithm_b.as_ref().unwrap().status,
            "Convex grid, STOP by PLANARITY condition"
        );
        assert_eq!(t.algorithm_b.as_ref().unwrap().continuation_steps, 12);
        assert!(b.iterations < t.algorithm_b.as_ref().unwrap().iterations);
    }
    /// Regression: the Pico-like 21³ case (seed 1) stalled with the thesis's
    /// schedule (every μ step at its 50-iteration limit, 12 non-hexahedral and 16
    /// non-ε-convex cells left); the default schedule must finish it (measured: 172 B
    /// iterations, 6 μ steps). ≈ 1 min: `cargo test -p unamalla-hex --release --lib --
    /// --ignored pico_21`.
    #[test]
    #[ignore]
    fn default_b_schedule_finishes_pico_21() {
        let dims = (21, 21, 21);
        let mut g = HexCase::Pico.initial_grid(dims).unwrap();
        HexCase::Pico
            .default_perturbation(dims)
            .apply(&mut g, 1)
            .unwrap();
        let r = run_hex(&mut g, &HexRunOptions::default(), &mut NullObserver).unwrap();
        assert_eq!(r.non_convex_cells, 0);
        assert_eq!(r.non_hex_interior_cells, 0);
    }
    /// Slow under load: `cargo test -p unamalla-hex --release --lib -- --ignored`.
    /// Every built-in case at its thesis size (Pico at 10³; Pico 21³ is
    /// `default_b_schedule_finishes_pico_21`) ends convex and, with the default B schedule,
    /// with every interior face planar — except `sydney`, a known failure (Algorithm A
    /// stops at once with 114 non-convex cells: its rim layers are 0.007 thick against 0.9 at
    /// the centre; docs/results.md).
    #[test]
    #[ignore]
    fn every_case_at_its_thesis_size_ends_convex() {
        for case in HexCase::ALL.into_iter().filter(|c| *c != HexCase::Sydney) {
            let dims = case.default_size();
            let mut g = case.initial_grid(dims).unwrap();
            case.default_perturbation(dims).apply(&mut g, 1).unwrap();
            let r = run_hex(&mut g, &HexRunOptions::default(), &mut NullObserver).unwrap();
            assert_eq!(r.non_convex_cells, 0, "{case}");
            assert_eq!(r.non_hex_interior_cells, 0, "{case}");
        }
    }
}
