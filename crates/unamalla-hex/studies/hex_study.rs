//! Measurements behind the structured hexahedral meshes of [Cortés Aguirre 2012] (the references
//! are listed in `docs/references.md` of the repository): Algorithm A speed and its variants, and
//! Algorithm B's μ schedule. Every number in the hex sections of
//! `docs/benchmarks.md` / `docs/results.md` that is not a plain `unamalla hex` run comes from here.
//!
//! ```sh
//! cargo run --release -p unamalla-hex --example hex_study -- a-time [case] [runs]
//! cargo run --release -p unamalla-hex --example hex_study -- a-variants [case]
//! cargo run --release -p unamalla-hex --example hex_study -- hessian [cells] [runs]
//! cargo run --release -p unamalla-hex --example hex_study -- b-study <case> <mu0> <mu_min> <iters> [m,n,p]
//! cargo run --release -p unamalla-hex --example hex_study -- b-trace <case> <m,n,p|-> <mu0> <factor> <iters> <bj|mg|jacobi|none> <cg_max> [mu_min]
//! cargo run --release -p unamalla-hex --example hex_study -- energy [case ...]
//! ```
//!
//! * `a-time`: best-of-`runs` wall time of Algorithm A alone (the `run_hex` driver with the
//!   default options, perturbation seed 1) and of the Hessian refreshes inside it.
//! * `a-variants`: the ω loop of Algorithm A re-run with (i) the Hessian refreshed only every
//!   k-th outer iteration, (ii) other ω₀ and ω factors; prints iterations, Hessian refreshes,
//!   non-convex cells and seconds per variant.
//! * `b-study`: Algorithm A then B with the given μ₀, μ_min and iterations per μ step, then an
//!   analysis of the interior faces still at `|cos| ≥ 10⁻²`: their position in the interior
//!   block (distance in cells to the block's surface) and the ratio of the reported measure
//!   (max over the four relabellings) to the penalized cosine (first vertex only).
//! * `b-trace`: Algorithm A (defaults), then a hand-run Algorithm B loop with the given μ₀,
//!   μ factor, iterations per step, CG preconditioner and CG iteration cap; prints per μ step
//!   the solver iterations, inner CG iterations, evaluations, stop reason, wall/CPU seconds
//!   and the non-hexahedral count (where B's time goes).
//! * `energy`: the thesis's energy values (Cortés Aguirre 2012 §3.4.2–§3.4.3): per case,
//!   `H_ω` of the perturbed start at the thesis's absolute `ω = 200` (parametric and index
//!   scaling; the thesis's sphere starts at `f = 0.0261538`), then Algorithm A (defaults) and
//!   the final mesh's [`energy_variants`](unamalla_functionals::energy_variants)
//!   (the thesis's sphere ends at `f = 2.26543`); for the sphere also the same with a
//!   different cube → ball map (Nowell's, see `nowell_ball`) to show how much the radial map
//!   itself moves the optimum.
//! * `hessian`: one Hessian refresh of `H_ω` on a folded `cells³` grid (node-block assembly,
//!   best of `runs`).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

use unamalla_functionals::prelude::*;
use unamalla_functionals::{Csr, HexFunctional, HexTopology, Scaling3, WithHessian};
use unamalla_hex::{run_hex, HexAlgorithm, HexCase, HexRunOptions};
use unamalla_optim::monitor::Session;
use unamalla_optim::solver::minimize_with;
use unamalla_optim::{NullObserver, Phase, SolverOptions};

/// User + system CPU seconds of this process (all threads), from `/proc/self/stat`
/// (clock ticks of 10 ms); NaN where unavailable.
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // fields after the ")" of the command name: state is field 3, utime 14, stime 15
    let Some(rest) = s.rsplit(')').next() else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| {
        f.get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    (tick(11) + tick(12)) / 100.0
}

/// The Hessian of `H_ω` refreshed only every `every`-th time the solver asks (in between
/// the previous values stay: a lagged model Hessian), counting refreshes and their time. It
/// implements [`Hessian`] alone; the solver sees `WithHessian::new(&v.f, &v)`, which takes
/// every other capability from the functional.
struct Variant {
    f: HexFunctional,
    every: usize,
    calls: AtomicUsize,
    refreshes: Arc<AtomicUsize>,
    hess_seconds: Arc<std::sync::Mutex<f64>>,
}

impl Hessian for Variant {
    fn hessian_pattern(&self) -> Csr {
        self.f.hessian_pattern()
    }
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        let n = self.calls.fetch_add(1, Ordering::Relaxed);
        if !n.is_multiple_of(self.every) {
            return; // keep the previous values (lagged Hessian)
        }
        let t = Instant::now();
        self.f.hessian(x, h);
        if let Ok(mut s) = self.hess_seconds.lock() {
            *s += t.elapsed().as_secs_f64();
        }
        self.refreshes.fetch_add(1, Ordering::Relaxed);
    }
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        self.f.hess_vec(x, v, out)
    }
}

struct AOutcome {
    iterations: usize,
    steps: usize,
    refreshes: usize,
    hess_seconds: f64,
    non_convex: usize,
    seconds: f64,
    cpu: f64,
}

/// Algorithm A's ω loop (the same steps as `omega_continuation_hex`: minimize, stop when
/// ε-convex, else ω ← factor·ω; then one refinement run with the ε guard).
fn algorithm_a(case: HexCase, every: usize, omega0_rel: f64, factor: f64) -> AOutcome {
    let dims = case.default_size();
    let mut g = case.initial_grid(dims).expect("grid");
    case.default_perturbation(dims)
        .apply(&mut g, 1)
        .expect("perturbation");
    let defaults = HexRunOptions::default();
    let opts = &defaults.omega;
    let scaling = Scaling3::Parametric {
        m: dims.0,
        n: dims.1,
        p: dims.2,
    };
    let t0 = Instant::now();
    let cpu0 = cpu_seconds();
    let topo = Arc::new(HexTopology::from_mesh(&g).expect("topology"));
    let mut x = topo.initial_x();
    let probe = HexFunctional::h_omega(topo.clone(), 1.0, scaling).expect("probe");
    let mut obs = NullObserver;
    let mut session = Session::new(&probe, &x, &mut obs);
    let c0 = session.convexity(&probe, &x);
    let vbar = c0.mean;
    let refreshes = Arc::new(AtomicUsize::new(0));
    let hess_seconds = Arc::new(std::sync::Mutex::new(0.0));
    let make = |w: f64| Variant {
        f: HexFunctional::h_omega(topo.clone(), w, scaling).expect("functional"),
        every,
        calls: AtomicUsize::new(0),
        refreshes: refreshes.clone(),
        hess_seconds: hess_seconds.clone(),
    };
    let solver: SolverOptions = opts.solver.clone();
    let mut omega = omega0_rel * vbar;
    let floor = opts.omega_floor_rel * vbar;
    let mut iterations = 0;
    let mut steps = 0;
    session.set_phase(Phase::Homotopic);
    let mut ok = false;
    loop {
        let v = make(omega);
        let p = WithHessian::new(&v.f, &v);
        let r = minimize_with(&p, &mut x, &solver, &mut session, None).expect("minimize");
        iterations += r.iterations;
        steps += 1;
        if session.convexity(&probe, &x).eps_convex(opts.eps) {
            ok = true;
            break;
        }
        if omega * factor < floor {
            break;
        }
        omega *= factor;
    }
    if ok && opts.refinement {
        session.set_phase(Phase::Classic);
        session.guard_threshold = opts.eps * vbar;
        let v = make(omega);
        let p = WithHessian::new(&v.f, &v);
        let r = minimize_with(&p, &mut x, &solver, &mut session, None).expect("refine");
        iterations += r.iterations;
        session.guard_threshold = 0.0;
    }
    let seconds = t0.elapsed().as_secs_f64();
    let c = session.convexity(&probe, &x);
    let hs = hess_seconds.lock().map(|s| *s).unwrap_or(f64::NAN);
    AOutcome {
        iterations,
        steps,
        refreshes: refreshes.load(Ordering::Relaxed),
        hess_seconds: hs,
        non_convex: c.nonconvex_cells,
        seconds,
        cpu: cpu_seconds() - cpu0,
    }
}

fn a_time(case: HexCase, runs: usize) {
    let dims = case.default_size();
    let mut best = f64::INFINITY;
    let mut it = 0;
    for _ in 0..runs {
        let mut g = case.initial_grid(dims).expect("grid");
        case.default_perturbation(dims)
            .apply(&mut g, 1)
            .expect("perturbation");
        let opts = HexRunOptions::default().algorithm(HexAlgorithm::A);
        let r = run_hex(&mut g, &opts, &mut NullObserver).expect("run");
        let st = r.algorithm_a.expect("A ran");
        best = best.min(st.seconds);
        it = st.iterations;
        assert_eq!(r.non_convex_cells, 0, "A must end convex");
    }
    println!(
        "{} {}x{}x{} Algorithm A: {it} iterations, best of {runs}: {best:.3} s wall",
        case.name(),
        dims.0,
        dims.1,
        dims.2
    );
}

fn a_variants(case: HexCase) {
    println!(
        "{:<34} {:>5} {:>5} {:>9} {:>9} {:>4} {:>8} {:>8}",
        "variant", "it", "steps", "H-refresh", "H-seconds", "NC", "wall s", "CPU s"
    );
    let d = HexRunOptions::default().omega.omega0_rel;
    let variants: Vec<(String, usize, f64, f64)> = vec![
        ("Hessian every iteration (default)".into(), 1, d, 0.5),
        ("Hessian every 2nd iteration".into(), 2, d, 0.5),
        ("Hessian every 3rd iteration".into(), 3, d, 0.5),
        ("ω₀ = 1·v̄".into(), 1, 1.0, 0.5),
        ("ω₀ = 0.01·v̄".into(), 1, 0.01, 0.5),
        ("ω₀ = 0.001·v̄".into(), 1, 0.001, 0.5),
        ("ω ← 0.1·ω".into(), 1, d, 0.1),
        ("ω₀ = 0.01·v̄, ω ← 0.1·ω".into(), 1, 0.01, 0.1),
    ];
    for (name, every, w0, factor) in variants {
        let o = algorithm_a(case, every, w0, factor);
        println!(
            "{:<34} {:>5} {:>5} {:>9} {:>9.3} {:>4} {:>8.3} {:>8.2}",
            name,
            o.iterations,
            o.steps,
            o.refreshes,
            o.hess_seconds,
            o.non_convex,
            o.seconds,
            o.cpu
        );
    }
}

fn hessian(cells: usize, runs: usize) {
    let case = HexCase::Sphere;
    let dims = (cells + 1, cells + 1, cells + 1);
    let mut g = case.initial_grid(dims).expect("grid");
    case.default_perturbation(dims)
        .apply(&mut g, 1)
        .expect("perturbation");
    let topo = Arc::new(HexTopology::from_mesh(&g).expect("topology"));
    let f = HexFunctional::h_omega(
        topo.clone(),
        1e-3,
        Scaling3::Parametric {
            m: dims.0,
            n: dims.1,
            p: dims.2,
        },
    )
    .expect("functional");
    let x = topo.initial_x();
    let mut h = f.hessian_pattern();
    let t = Instant::now();
    f.hessian(&x, &mut h);
    println!(
        "first refresh (builds the slot table): {:.1} ms",
        1e3 * t.elapsed().as_secs_f64()
    );
    let mut best = f64::INFINITY;
    for _ in 0..runs {
        let t = Instant::now();
        f.hessian(&x, &mut h);
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!(
        "sphere {cells}³ cells, Hessian refresh (node-block): best of {runs} {:.2} ms",
        1e3 * best
    );
}

fn b_study(
    case: HexCase,
    mu0: f64,
    mu_min: f64,
    iters: usize,
    dims: Option<(usize, usize, usize)>,
) {
    use unamalla_functionals::{face_coplanarity_cos, face_planarity_max_cos, HEX_QUAD_FACES};
    use unamalla_mesh::hexgen::{classify_cells, CellClass};
    use unamalla_mesh::HasHexCells;
    let dims = dims.unwrap_or_else(|| case.default_size());
    let mut g = case.initial_grid(dims).expect("grid");
    case.default_perturbation(dims)
        .apply(&mut g, 1)
        .expect("perturbation");
    let mut opts = HexRunOptions::default();
    opts.coplanarity.mu0 = mu0;
    opts.coplanarity.mu_min = mu_min;
    opts.coplanarity.solver.max_iter = iters;
    let r = run_hex(&mut g, &opts, &mut NullObserver).expect("run");
    let a = r.after_a.as_ref().expect("A");
    let (sa, sb) = (r.algorithm_a.as_ref().expect("A"), r.algorithm_b.as_ref());
    println!(
        "{} {}x{}x{} μ₀ {mu0:e} μ_min {mu_min:e} iters/step {iters}: A {} it {:.2} s, NH after A {} → after B {} (max|cos| {:.2e}), NC {}, B {} it {} steps {:.2} s",
        case.name(), dims.0, dims.1, dims.2, sa.iterations, sa.seconds, a.non_hex_interior_cells,
        r.non_hex_interior_cells, r.max_abs_cos, r.non_convex_cells,
        sb.map_or(0, |b| b.iterations), sb.map_or(0, |b| b.continuation_steps), sb.map_or(0.0, |b| b.seconds)
    );
    // where are the remaining non-planar faces?
    let cls = classify_cells(&g);
    let (m, n, p) = dims;
    let mut by_depth = std::collections::BTreeMap::<usize, usize>::new();
    let mut by_place = [0usize; 4];
    let mut ratios = Vec::new();
    for (c, cl) in cls.iter().enumerate() {
        if *cl != CellClass::Interior {
            continue;
        }
        let (i, j, k) = (
            c % (m - 1),
            (c / (m - 1)) % (n - 1),
            c / ((m - 1) * (n - 1)),
        );
        // interior cells have i in 1..=m-4: depth 0 = on the block surface
        let depth = [i - 1, m - 4 - i, j - 1, n - 4 - j, k - 1, p - 4 - k]
            .into_iter()
            .min()
            .unwrap_or(0);
        let h = g.hex_points(c);
        let mut bad = false;
        for f in HEX_QUAD_FACES {
            let q = f.map(|v| h[v]);
            let mx = face_planarity_max_cos(q);
            if mx >= 1e-2 {
                bad = true;
                let k0 = face_coplanarity_cos(q).abs();
                ratios.push(mx / k0.max(1e-300));
            }
        }
        if bad {
            *by_depth.entry(depth).or_default() += 1;
            // 0 = inside the block, 1 = on a face, 2 = on an edge, 3 = at a corner of it
            let ext = [(i, m), (j, n), (k, p)]
                .into_iter()
                .filter(|&(x, d)| x == 1 || x == d - 4)
                .count();
            by_place[ext] += 1;
        }
    }
    println!("  non-hex interior cells by depth in the interior block: {by_depth:?}");
    println!(
        "  … by place in the block: inside {}, on a block face {}, on a block edge {}, at a block corner {}",
        by_place[0], by_place[1], by_place[2], by_place[3]
    );
    if !ratios.is_empty() {
        ratios.sort_by(f64::total_cmp);
        println!(
            "  bad faces {}: max|cos| / penalized |k| min {:.2} median {:.2} max {:.2}",
            ratios.len(),
            ratios[0],
            ratios[ratios.len() / 2],
            ratios[ratios.len() - 1]
        );
    }
}

/// Options of one `b-trace` run.
struct BTrace {
    mu0: f64,
    factor: f64,
    iters: usize,
    pre: unamalla_optim::Preconditioner,
    cg_max: usize,
    mu_min: f64,
}

/// Algorithm A (defaults) on `case`, then a hand-run Algorithm B loop printing, per μ step,
/// the solver iterations, inner CG iterations, function evaluations, stop reason, seconds
/// and the non-hexahedral count; the totals at the end.
fn b_trace(case: HexCase, dims: Option<(usize, usize, usize)>, o: &BTrace) {
    let dims = dims.unwrap_or_else(|| case.default_size());
    let mut g = case.initial_grid(dims).expect("grid");
    case.default_perturbation(dims)
        .apply(&mut g, 1)
        .expect("perturbation");
    let opts = HexRunOptions::default().algorithm(HexAlgorithm::A);
    let r = run_hex(&mut g, &opts, &mut NullObserver).expect("A");
    let scaling = Scaling3::Parametric {
        m: dims.0,
        n: dims.1,
        p: dims.2,
    };
    let topo = Arc::new(HexTopology::from_mesh(&g).expect("topology"));
    let mut x = topo.initial_x();
    let probe = HexFunctional::h_omega(topo.clone(), 1.0, scaling).expect("probe");
    let mut obs = NullObserver;
    let mut session = Session::new(&probe, &x, &mut obs);
    let c0 = session.convexity(&probe, &x);
    let omega = 1e-8 * c0.mean;
    session.set_phase(Phase::Homotopic);
    session.monitor.omega = Some(omega);
    let mut p = HexFunctional::h_omega(topo.clone(), omega, scaling).expect("functional");
    let solver = SolverOptions::default()
        .max_iter(o.iters)
        .ftol(1e-8)
        .gtol(1e-4)
        .preconditioner(o.pre)
        .cg_max_iter(o.cg_max);
    println!(
        "{} {}x{}x{}: A {} it, NH after A {}; B μ₀ {:e} ×{} ≤{} it/step, {:?}, cg_max {}",
        case.name(),
        dims.0,
        dims.1,
        dims.2,
        r.iterations,
        r.non_hex_interior_cells,
        o.mu0,
        o.factor,
        o.iters,
        o.pre,
        o.cg_max
    );
    println!(
        "{:>10} {:>5} {:>6} {:>6} {:>8} {:>8} {:>6} {:>10}  reason",
        "μ", "it", "CG", "fevals", "wall s", "CPU s", "NH", "max|k|"
    );
    let (t0, cpu0) = (Instant::now(), cpu_seconds());
    let (mut it, mut cg, mut fe) = (0, 0, 0);
    let mut mu = o.mu0;
    while mu > o.mu_min {
        session.monitor.mu = Some(mu);
        p.set_coplanarity(Some(1.0 / (2.0 * mu))).expect("C");
        let (t1, c1) = (Instant::now(), cpu_seconds());
        let s = minimize_with(&p, &mut x, &solver, &mut session, None).expect("B step");
        let (mx, nh) = topo.planarity_report(&x, 1e-2);
        println!(
            "{:>10.1e} {:>5} {:>6} {:>6} {:>8.3} {:>8.2} {:>6} {:>10.2e}  {:?}",
            mu,
            s.iterations,
            s.cg_iterations,
            s.fevals,
            t1.elapsed().as_secs_f64(),
            cpu_seconds() - c1,
            nh,
            mx,
            s.reason
        );
        it += s.iterations;
        cg += s.cg_iterations;
        fe += s.fevals;
        mu *= o.factor;
    }
    let c = session.convexity(&probe, &x);
    let (mx, nh) = topo.planarity_report(&x, 1e-2);
    println!(
        "total: {it} it, {cg} CG, {fe} fevals, {:.2} s wall, {:.2} s CPU; NH {nh}, max|k| {mx:.2e}, V>0 everywhere: {}",
        t0.elapsed().as_secs_f64(),
        cpu_seconds() - cpu0,
        c.min > 0.0
    );
}

/// Nowell's cube → ball map `x·√(1 − y²/2 − z²/2 + y²z²/3)` (and cyclic), a smooth
/// alternative to the radial map with a different boundary node distribution.
fn nowell_ball(q: unamalla_mesh::DVec3) -> unamalla_mesh::DVec3 {
    let (x2, y2, z2) = (q.x * q.x, q.y * q.y, q.z * q.z);
    unamalla_mesh::DVec3::new(
        q.x * (1.0 - y2 / 2.0 - z2 / 2.0 + y2 * z2 / 3.0).sqrt(),
        q.y * (1.0 - z2 / 2.0 - x2 / 2.0 + x2 * z2 / 3.0).sqrt(),
        q.z * (1.0 - x2 / 2.0 - y2 / 2.0 + x2 * y2 / 3.0).sqrt(),
    )
}

fn energy(name: &str) {
    use unamalla_functionals::energy_variants;
    use unamalla_mesh::{HasHexCells, StructuredGrid3};
    let (case, nowell) = match name {
        "sphere-nowell" => (HexCase::Sphere, true),
        n => (n.parse::<HexCase>().expect("case"), false),
    };
    let dims = case.default_size();
    let mut g = if nowell {
        let t = |i: usize, k: usize| -1.0 + 2.0 * i as f64 / (k - 1) as f64;
        StructuredGrid3::from_fn(dims.0, dims.1, dims.2, |i, j, k| {
            nowell_ball(unamalla_mesh::DVec3::new(
                t(i, dims.0),
                t(j, dims.1),
                t(k, dims.2),
            ))
        })
        .expect("grid")
    } else {
        case.initial_grid(dims).expect("grid")
    };
    let cells = |g: &StructuredGrid3| -> Vec<[unamalla_mesh::DVec3; 8]> {
        (0..g.num_hexes()).map(|c| g.hex_points(c)).collect()
    };
    let par = Scaling3::Parametric {
        m: dims.0,
        n: dims.1,
        p: dims.2,
    };
    let e0 = energy_variants(&cells(&g), par).expect("energy");
    let (amp, nc0) = case
        .default_perturbation(dims)
        .apply(&mut g, 1)
        .unwrap_or((0.0, 0));
    let topo = Arc::new(HexTopology::from_mesh(&g).expect("topology"));
    let x0 = topo.initial_x();
    let h200 = |s: Scaling3| {
        HexFunctional::h_omega(topo.clone(), 200.0, s)
            .expect("H")
            .value(&x0)
    };
    println!(
        "{name} {}x{}x{}: unperturbed E (printed) {:.5}; perturbed (amp {amp:.3}, {nc0} non-convex): H_200 parametric {:.7}, index {:.3e}",
        dims.0, dims.1, dims.2, e0.printed, h200(par), h200(Scaling3::Index)
    );
    let opts = HexRunOptions::default().algorithm(HexAlgorithm::A);
    let r = run_hex(&mut g, &opts, &mut NullObserver).expect("run");
    let a = r.algorithm_a.expect("A ran");
    let e = energy_variants(&cells(&g), par).expect("energy");
    let show = |what: &str,
                it: usize,
                f: f64,
                omega: f64,
                e: &unamalla_functionals::EnergyVariants| {
        println!(
            "  {what} ({it} it): f {f:.5} at ω {omega:.3e}; E printed {:.5}, per-decomposition {:.5}, volume-weighted {:.5}, interior-raw {:.5} (V ≤ 0: {})",
            e.printed, e.per_decomposition, e.volume_weighted, e.interior_raw, e.non_positive
        )
    };
    show(
        &format!("after A (NC {})", r.non_convex_cells),
        a.iterations,
        a.f,
        a.omega.unwrap_or(f64::NAN),
        &e,
    );
    // the thesis's sphere run continues the ω halving to ω* = 10⁻⁸ (§3.4.3), where H_ω is the
    // energy itself: minimise H at ω = 10⁻⁸·v̄ from the convex A mesh (convexity safeguard on)
    let topo = Arc::new(HexTopology::from_mesh(&g).expect("topology"));
    let mut x = topo.initial_x();
    let probe = HexFunctional::h_omega(topo.clone(), 1.0, par).expect("probe");
    let mut obs = NullObserver;
    let mut session = Session::new(&probe, &x, &mut obs);
    let vbar = session.convexity(&probe, &x).mean;
    session.set_phase(Phase::Classic);
    session.guard_threshold = opts.omega.eps * vbar;
    let w = 1e-8 * vbar;
    let hf = HexFunctional::h_omega(topo.clone(), w, par).expect("H");
    let solver = opts.omega.solver.clone().max_iter(500);
    let rr = minimize_with(&hf, &mut x, &solver, &mut session, None).expect("minimize");
    let mut g2 = g.clone();
    topo.scatter(&x, unamalla_mesh::HasNodes::nodes_mut(&mut g2));
    let e2 = energy_variants(&cells(&g2), par).expect("energy");
    show("then H at ω = 1e-8·v̄", rr.iterations, rr.f, w, &e2);
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = args.first().map(String::as_str).unwrap_or("a-time");
    let case = || -> HexCase {
        args.get(1)
            .map(|s| s.parse().expect("case"))
            .unwrap_or(HexCase::Sphere)
    };
    match mode {
        "a-time" => a_time(
            case(),
            args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5),
        ),
        "a-variants" => a_variants(case()),
        "hessian" => {
            let cells = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(19);
            hessian(cells, args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5));
        }
        "b-study" => {
            let num = |i: usize, d: f64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
            let dims = args.get(5).map(|s| {
                let v: Vec<usize> = s.split(',').map(|t| t.parse().expect("size")).collect();
                (v[0], v[1], v[2])
            });
            b_study(
                case(),
                num(2, 0.1),
                num(3, 1e-12),
                num(4, 50.0) as usize,
                dims,
            );
        }
        "b-trace" => {
            // b-trace <case> <m,n,p|-> <mu0> <factor> <iters> <bj|mg|jacobi|none> <cg_max>
            let num = |i: usize, d: f64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
            let dims = args.get(2).filter(|s| s.as_str() != "-").map(|s| {
                let v: Vec<usize> = s.split(',').map(|t| t.parse().expect("size")).collect();
                (v[0], v[1], v[2])
            });
            use unamalla_optim::Preconditioner as Pc;
            let pre = match args.get(6).map(String::as_str).unwrap_or("bj") {
                "mg" => Pc::Multigrid,
                "jacobi" => Pc::Jacobi,
                "none" => Pc::None,
                _ => Pc::BlockJacobi,
            };
            let o = BTrace {
                mu0: num(3, 0.1),
                factor: num(4, 0.1),
                iters: num(5, 50.0) as usize,
                pre,
                cg_max: num(7, 200.0) as usize,
                mu_min: num(8, 1e-12),
            };
            b_trace(case(), dims, &o);
        }
        "energy" => {
            let cases: Vec<String> = if args.len() > 1 {
                args[1..].to_vec()
            } else {
                vec!["sphere".into(), "ellipsoid".into(), "pico".into()]
            };
            for c in cases {
                energy(&c);
            }
        }
        other => {
            eprintln!(
                "unknown mode {other}: a-time | a-variants | hessian | b-study | b-trace | energy"
            )
        }
    }
}
