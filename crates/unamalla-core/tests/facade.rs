//! The facade: the main job through the crate root and the prelude, `Mesher` handed to another
//! thread, and `MeshResult::write_all` writing the whole file set at once.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use unamalla_core::prelude::*;

/// A 4 × 2 rectangle with a 1 × 0.5 hole: two holes' worth of patches (`outer`, `hole-1`).
fn plate() -> Region {
    let outer = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(4.0, 0.0),
        DVec2::new(4.0, 2.0),
        DVec2::new(0.0, 2.0),
    ];
    let hole = vec![
        DVec2::new(1.5, 0.75),
        DVec2::new(1.5, 1.25),
        DVec2::new(2.5, 1.25),
        DVec2::new(2.5, 0.75),
    ];
    Region::new(outer, vec![hole]).expect("valid plate")
}

/// A fresh scratch directory under the target directory (removed first if a previous run left
/// it).
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

fn listing(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .expect("readable")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect()
}

#[test]
fn a_configured_mesher_runs_on_another_thread_and_shows_its_settings() {
    let stages = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let seen = stages.clone();
    let mesher = Mesher::new()
        .cells(400)
        .on_progress(move |s, _| seen.lock().expect("not poisoned").push(s));
    let shown = format!("{mesher:?}");
    assert!(shown.contains("Cells(400)"), "{shown}");
    assert!(shown.contains("progress: Some(\"callback\")"), "{shown}");
    let result = std::thread::spawn(move || mesher.mesh(&plate()))
        .join()
        .expect("no panic")
        .expect("the plate meshes");
    assert_eq!(result.report.non_convex_cells, 0);
    assert_eq!(result.report.interior_singularities, 0);
    let stages = stages.lock().expect("not poisoned");
    assert_eq!(stages.first(), Some(&Stage::Simplify));
    assert!(stages.contains(&Stage::Smooth), "{stages:?}");
}

#[test]
fn write_all_writes_the_documented_set_and_leaves_the_target_alone_on_failure() {
    let result = Mesher::new().cells(400).mesh(&plate()).expect("meshes");
    let root = scratch("facade-write-all");
    let out = root.join("plate");
    let written = result
        .write_all(&out, &OutputOptions::default())
        .expect("written");

    // the set of the module docs' table: one .vts per block, the solver formats of the
    // default options, the decomposition, the pictures and the report
    let mut expected: BTreeSet<String> = (0..result.report.blocks)
        .map(|k| format!("block-{k}.vts"))
        .collect();
    for f in [
        "blocks.vtm",
        "mesh.vtu",
        "mesh.msh",
        "mesh.su2",
        "openfoam",
        "decomposition.json",
        "decomposition.svg",
        "mesh.svg",
        "mesh.png",
        "report.json",
    ] {
        expected.insert(f.to_string());
    }
    let returned: BTreeSet<String> = written
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    assert_eq!(returned, expected);
    let mut on_disk = listing(&out);
    // the marker of a committed output directory (what lets a later run replace it)
    assert!(on_disk.remove(unamalla_core::output::MARKER));
    assert_eq!(on_disk, expected);

    // report.json is the report; the VTK mesh reads back with the report's cell count
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("read"))
            .expect("JSON");
    assert_eq!(json["cells"].as_u64(), Some(result.report.cells as u64));
    let msh = std::fs::read_to_string(out.join("mesh.msh")).expect("read");
    assert!(msh.contains("\"outer\"") && msh.contains("\"hole-1\""));

    // a failing write (CGNS asked for in a build without it) leaves the old set in place
    if !cfg!(feature = "cgns") {
        let before = listing(&out);
        let err = result
            .write_all(
                &out,
                &OutputOptions::default().formats(true, true, true, true),
            )
            .expect_err("no CGNS in this build");
        assert!(matches!(err, CoreError::CgnsNotBuilt), "{err}");
        assert_eq!(listing(&out), before);
        assert_eq!(listing(&root), BTreeSet::from(["plate".to_string()]));
    }

    // a directory holding someone else's files is refused, not replaced
    let foreign = root.join("foreign");
    std::fs::create_dir_all(&foreign).expect("dir");
    std::fs::write(foreign.join("notes.txt"), "mine").expect("file");
    let err = result
        .write_all(&foreign, &OutputOptions::minimal())
        .expect_err("foreign directory");
    assert!(matches!(err, CoreError::Output(_)), "{err}");
    assert_eq!(listing(&foreign), BTreeSet::from(["notes.txt".to_string()]));
}

/// Every options struct of the stage crates is `#[non_exhaustive]`: a user crate builds it
/// from its `Default` (or constructor) and the setters, or assigns the public fields of a
/// default value. Each setter sets its own field and leaves the others at their defaults.
#[test]
fn options_are_built_through_their_api() {
    use unamalla_core::bspline::{Degree, InteriorOptions, ParametrizeOptions};
    use unamalla_core::bspline_maps::BlockMapOptions;
    use unamalla_core::compat_ilp::{
        FitOptions, IntervalOptions, LowerBounds, Method as CompatMethod, MilpBackend,
        SolveOptions as CompatSolveOptions, VertexClassOptions,
    };
    use unamalla_core::contour::{HoleFilter, Method, MppOptions, Preset, SimplifyOptions};
    use unamalla_core::decompose::submap::{SubmapOptions, SumMode};
    use unamalla_core::decompose::{CornerWeights, DecomposeOptions, Layout};
    use unamalla_core::io::{CrsChoice, LoadOptions};
    use unamalla_core::mesh::quality::ReportOptions;
    use unamalla_core::optim::drivers::{
        AdaptiveKOptions, BlockSmoothingOptions, CoplanarityOptions, OmegaOptions,
    };
    use unamalla_core::optim::linesearch::LineSearchParams;
    use unamalla_core::optim::multigrid::MultigridOptions;
    use unamalla_core::optim::{
        ClassicCombination, ClassicOptions, CoarseToFineOptions, HexDriver, HexSmoothOptions,
        HomotopySchedule, KFunctional, PointwiseMode, Preconditioner, SmoothFunctional,
        SmoothOptions, Solver, SolverOptions, StopRules,
    };
    use unamalla_core::verify::VerifyOptions;

    // optim: the solver options nest into every driver's options
    let solver = SolverOptions::new(Solver::Lbfgs)
        .max_iter(77)
        .ftol(1e-7)
        .gtol(1e-5)
        .gtol_abs(1e-12)
        .preconditioner(Preconditioner::Jacobi)
        .cg_max_iter(33)
        .forcing_max(0.25)
        .lbfgs_memory(9)
        .pointwise_mode(PointwiseMode::Components)
        .line_search(LineSearchParams::default().maxfev(7).gtol(0.5))
        .stop(StopRules::default());
    assert_eq!(solver.solver, Solver::Lbfgs);
    assert_eq!(
        (solver.max_iter, solver.cg_max_iter, solver.lbfgs_memory),
        (77, 33, 9)
    );
    assert_eq!(
        (solver.ftol, solver.gtol, solver.gtol_abs),
        (1e-7, 1e-5, 1e-12)
    );
    assert_eq!(solver.preconditioner, Preconditioner::Jacobi);
    assert_eq!(solver.forcing_max, 0.25);
    assert_eq!(solver.pointwise_mode, PointwiseMode::Components);
    assert_eq!(
        (solver.line_search.maxfev, solver.line_search.gtol),
        (7, 0.5)
    );
    assert_eq!(solver.line_search.ftol, LineSearchParams::default().ftol);
    assert_eq!(solver.hessian, SolverOptions::default().hessian);
    assert_eq!(
        SolverOptions::default().solver(Solver::TnLs).solver,
        Solver::TnLs
    );

    let smooth = SmoothOptions::default()
        .functional(SmoothFunctional::block_smoothing(0.3))
        .solver(solver.clone())
        .eps(0.02)
        .presmooth(4)
        .iters_per_k(6)
        .max_k_updates(8)
        .time_limit(Some(2.5))
        .sigma_continuation(vec![1.0])
        .continuation_iter(12)
        .schedule(HomotopySchedule::Cube);
    assert_eq!(smooth.functional, SmoothFunctional::block_smoothing(0.3));
    assert_eq!(smooth.solver, solver);
    assert_eq!((smooth.eps, smooth.time_limit), (0.02, Some(2.5)));
    assert_eq!(
        (smooth.presmooth, smooth.iters_per_k, smooth.max_k_updates),
        (4, 6, 8)
    );
    assert_eq!(smooth.sigma_continuation, vec![1.0]);
    assert_eq!(smooth.continuation_iter, 12);
    assert_eq!(smooth.schedule, HomotopySchedule::Cube);
    // field assignment after `default()` works as well
    let mut edited = SmoothOptions::default();
    edited.solver.max_iter = 5;
    assert_eq!(edited.solver.max_iter, 5);
    assert_eq!(edited.eps, SmoothOptions::default().eps);

    let c2f = CoarseToFineOptions::default()
        .smooth(smooth.clone())
        .ratio(2)
        .min_nodes(9)
        .coarse_ftol(1e-3);
    assert_eq!(c2f.smooth, smooth);
    assert_eq!((c2f.ratio, c2f.min_nodes, c2f.coarse_ftol), (2, 9, 1e-3));

    let mg = MultigridOptions::default()
        .coarse_size(50)
        .max_levels(3)
        .sweeps(2)
        .strength(0.1);
    assert_eq!(
        (mg.coarse_size, mg.max_levels, mg.sweeps, mg.strength),
        (50, 3, 2, 0.1)
    );

    let ak = AdaptiveKOptions::default()
        .functional(KFunctional::KSmoothness)
        .sigma(0.7)
        .k_star(-0.02)
        .iters_per_k(3)
        .max_updates(4)
        .presmooth(1)
        .classic(false)
        .solver(solver.clone())
        .schedule(HomotopySchedule::Sine)
        .stop_at_target(true);
    assert_eq!(ak.functional, KFunctional::KSmoothness);
    assert_eq!((ak.sigma, ak.k_star), (0.7, -0.02));
    assert_eq!((ak.iters_per_k, ak.max_updates, ak.presmooth), (3, 4, 1));
    assert!(!ak.classic && ak.stop_at_target);
    assert_eq!((ak.schedule, &ak.solver), (HomotopySchedule::Sine, &solver));

    let bs = BlockSmoothingOptions::default()
        .sigma(0.2)
        .density(2.0)
        .layers(3)
        .eps(0.05)
        .untangle(ak.clone())
        .solver(solver.clone())
        .sigma_continuation(vec![1.0, 0.5])
        .continuation_iter(20);
    assert_eq!(
        (bs.sigma, bs.density, bs.layers, bs.eps),
        (0.2, 2.0, 3, 0.05)
    );
    assert_eq!((&bs.untangle, &bs.solver), (&ak, &solver));
    assert_eq!(
        (bs.sigma_continuation.as_slice(), bs.continuation_iter),
        (&[1.0, 0.5][..], 20)
    );

    let classic = ClassicOptions::new(ClassicCombination::AreaLength, 0.9)
        .presmooth(2)
        .eps(0.03)
        .solver(solver.clone());
    assert_eq!(classic.combination, ClassicCombination::AreaLength);
    assert_eq!(
        (classic.sigma, classic.presmooth, classic.eps),
        (0.9, 2, 0.03)
    );
    assert_eq!(classic.solver, solver);
    let classic = classic
        .combination(ClassicCombination::AreaOrthogonality)
        .sigma(0.5);
    assert_eq!(classic.combination, ClassicCombination::AreaOrthogonality);
    assert_eq!(classic.sigma, 0.5);

    let omega = OmegaOptions::default()
        .omega0_rel(0.1)
        .omega_floor_rel(1e-6)
        .eps(1e-4)
        .refinement(false)
        .solver(solver.clone());
    assert_eq!(
        (omega.omega0_rel, omega.omega_floor_rel, omega.eps),
        (0.1, 1e-6, 1e-4)
    );
    assert!(!omega.refinement);
    assert_eq!(omega.solver, solver);

    let cop = CoplanarityOptions::thesis()
        .omega_rel(1e-7)
        .mu0(3.0)
        .mu_min(1e-9)
        .planarity_tol(0.02)
        .stop_cos(Some(0.01))
        .check_every(4)
        .solver(solver.clone());
    assert_eq!((cop.omega_rel, cop.mu0, cop.mu_min), (1e-7, 3.0, 1e-9));
    assert_eq!(
        (cop.planarity_tol, cop.stop_cos, cop.check_every),
        (0.02, Some(0.01), 4)
    );
    assert_eq!(cop.solver, solver);

    let hex = HexSmoothOptions::default()
        .driver(HexDriver::AlgorithmAB)
        .omega(omega.clone())
        .coplanarity(cop.clone());
    assert_eq!(hex.driver, HexDriver::AlgorithmAB);
    assert_eq!((&hex.omega, &hex.coplanarity), (&omega, &cop));
    assert_eq!(hex.scaling, HexSmoothOptions::default().scaling);

    // decompose
    let cw = CornerWeights::default();
    let dec = DecomposeOptions::default()
        .min_area_fraction(1e-3)
        .max_blocks(50)
        .concave_starts(4)
        .corner_weights(cw)
        .critical_triangles(false)
        .merge_blocks(false)
        .triangle_insert_fraction(0.3)
        .min_triangle_fraction(1e-4)
        .repair_corners(false)
        .edge_point_cuts(true)
        .layout(Layout::Concavity)
        .chord_aspect(2.0)
        .cell_size(Some(0.5));
    assert_eq!(
        (dec.min_area_fraction, dec.max_blocks, dec.concave_starts),
        (1e-3, 50, 4)
    );
    assert!(!dec.critical_triangles && !dec.merge_blocks && !dec.repair_corners);
    assert!(dec.edge_point_cuts);
    assert_eq!(
        (dec.triangle_insert_fraction, dec.min_triangle_fraction),
        (0.3, 1e-4)
    );
    assert_eq!(
        (dec.layout, dec.chord_aspect, dec.cell_size),
        (Layout::Concavity, 2.0, Some(0.5))
    );
    assert_eq!(dec.tolerances, DecomposeOptions::default().tolerances);

    let sub = SubmapOptions::new(0.25)
        .sum_mode(SumMode::Global)
        .include_max_term(false)
        .keep_vertex_angle_deg(15.0)
        .max_pieces(100)
        .max_attempts(2);
    assert_eq!((sub.target_size, sub.sum_mode), (0.25, SumMode::Global));
    assert!(!sub.include_max_term);
    assert_eq!(
        (sub.keep_vertex_angle_deg, sub.max_pieces, sub.max_attempts),
        (15.0, 100, 2)
    );

    // compat-ilp
    let vc = VertexClassOptions::default()
        .holes(2)
        .rho(Some(vec![1.0, 2.0]))
        .omega(Some(vec![3.0]))
        .backend(MilpBackend::Microlp);
    assert_eq!(
        (vc.holes, vc.rho.as_deref(), vc.omega.as_deref()),
        (2, Some(&[1.0, 2.0][..]), Some(&[3.0][..]))
    );
    let iv = IntervalOptions::new(0.5)
        .include_max_term(false)
        .backend(MilpBackend::Microlp);
    assert_eq!((iv.target_size, iv.include_max_term), (0.5, false));
    let fit = FitOptions::default()
        .time_limit(None)
        .backend(MilpBackend::Microlp);
    assert_eq!((fit.time_limit, fit.backend), (None, MilpBackend::Microlp));
    let cs = CompatSolveOptions::density(2)
        .with_method(CompatMethod::NetworkFlow)
        .bounds(LowerBounds::CellSize(0.1))
        .minimize_conflict(false)
        .time_limit(Some(5.0));
    assert_eq!(
        (cs.bounds, cs.method),
        (LowerBounds::CellSize(0.1), CompatMethod::NetworkFlow)
    );
    assert_eq!((cs.minimize_conflict, cs.time_limit), (false, Some(5.0)));

    // contour
    let mpp = MppOptions::default().tol(1e-4).max_iter(10).levels(2);
    assert_eq!((mpp.tol, mpp.max_iter, mpp.levels), (1e-4, 10, 2));
    let simp = SimplifyOptions::new(Method::Visvalingam, Preset::Noisy)
        .epsilon(Some(2.0))
        .delta(Some(1e-3))
        .holes(HoleFilter::MinArea(0.5))
        .mpp(mpp);
    assert_eq!(
        (simp.method, simp.preset),
        (Method::Visvalingam, Preset::Noisy)
    );
    assert_eq!((simp.epsilon, simp.delta), (Some(2.0), Some(1e-3)));
    assert_eq!((simp.holes, simp.mpp), (HoleFilter::MinArea(0.5), mpp));
    let simp = SimplifyOptions::default()
        .method(Method::Visvalingam)
        .preset(Preset::Auto);
    assert_eq!(
        (simp.method, simp.preset, simp.epsilon),
        (Method::Visvalingam, Preset::Auto, None)
    );

    // bspline
    let interior = InteriorOptions::default()
        .omega(10.0)
        .eps(0.1)
        .sigma(0.25)
        .omega_doublings(1)
        .solver(solver.clone());
    assert_eq!(
        (interior.omega, interior.eps, interior.sigma),
        (10.0, 0.1, 0.25)
    );
    assert_eq!((interior.omega_doublings, &interior.solver), (1, &solver));
    let par = ParametrizeOptions::default()
        .degree(Degree::Bilinear)
        .interior(interior.clone())
        .samples(50)
        .subdivision(2);
    assert_eq!((par.degree, &par.interior), (Degree::Bilinear, &interior));
    assert_eq!((par.samples, par.subdivision), (50, 2));

    // io, mesh, core
    let load = LoadOptions::default()
        .feature(Some("name=Crete".into()))
        .crs(CrsChoice::Planar);
    assert_eq!(
        (load.feature.as_deref(), &load.crs),
        (Some("name=Crete"), &CrsChoice::Planar)
    );
    let rep = ReportOptions::default()
        .histogram_bins(10)
        .epsilon(0.02)
        .tet_epsilon(0.01)
        .planarity_tolerance(0.05);
    assert_eq!((rep.histogram_bins, rep.epsilon), (10, 0.02));
    assert_eq!((rep.tet_epsilon, rep.planarity_tolerance), (0.01, 0.05));
    let maps = BlockMapOptions::default()
        .samples(20)
        .subdivision(1)
        .biquadratic(false);
    assert_eq!(
        (maps.samples, maps.subdivision, maps.biquadratic),
        (20, 1, false)
    );
    assert_eq!(
        VerifyOptions::default().area_tolerance(0.1).area_tolerance,
        0.1
    );
}
