//! Unit tests of the solver: exactness on affine grids, the series solution of Poisson's equation,
//! the automatic ω, the quad-mesh and multi-block schemes against the structured one, the input
//! checks, the boundary profiles, SOR divergence and the direct solver.

use unamalla_mesh::{BlockMesh2, QuadMesh};

use super::manufactured::{curved_grid, Manufactured};
use super::*;

fn zero_bc() -> [SideValue; 4] {
    std::array::from_fn(|_| SideValue::Constant(0.0))
}

fn sor() -> SolveOptions {
    SolveOptions::default()
}

#[test]
fn cubic_is_exact_on_affine_grids() {
    // On an affine grid (a parallelogram lattice) the metrics are constant, P = Q = 0 and
    // U∘x is a cubic in (ξ, η), for which the central differences are exact: the discrete
    // solution is U to rounding, with all four coefficients non-zero.
    let grid = StructuredGrid2::from_fn(13, 9, |i, j| {
        DVec2::new(
            0.1 * i as f64 + 0.04 * j as f64,
            0.03 * i as f64 + 0.12 * j as f64,
        )
    })
    .unwrap();
    let man = Manufactured::polynomial();
    let eq = man.equation(2.0, 0.5, 1.0, -1.0);
    let sol = solve_grid(&grid, &eq, &man.sides(), &sor()).unwrap();
    let e = man.error(grid.nodes(), &sol.u);
    assert!(e.max < 1e-8, "{e:?}");
    assert!(sol.residual < 1e-9);
    assert_eq!(sol.unknowns, 11 * 7);
}

#[test]
fn poisson_on_the_square_matches_the_series_solution() {
    // ΔU = −2, U = 0 on ∂[0,1]²: U(½,½) = 0.1473557 (Fourier series, 2 × torsion of the
    // unit square = 2 × 0.0736779); the 5-point scheme at h = 1/40 is within 1e-4.
    let grid =
        StructuredGrid2::from_fn(41, 41, |i, j| DVec2::new(i as f64 / 40.0, j as f64 / 40.0))
            .unwrap();
    let eq = Equation::poisson(Source::Constant(-2.0));
    let sol = solve_grid(&grid, &eq, &zero_bc(), &sor()).unwrap();
    let c = sol.u[grid.index(20, 20)];
    assert!((c - 0.1473557).abs() < 1e-4, "{c}");
    // the automatic ω is Young's for μ = cos(π/40): 2/(1 + sin(π/40))
    let w = 2.0 / (1.0 + (std::f64::consts::PI / 40.0).sin());
    assert!(
        (sol.omega.unwrap() - w).abs() < 1e-6,
        "{:?} vs {w}",
        sol.omega
    );
}

#[test]
fn automatic_omega_is_much_faster_than_gauss_seidel() {
    let grid = curved_grid(41, 41).unwrap();
    let man = Manufactured::sin_cosh();
    let eq = man.equation(1.0, 0.0, 1.0, 0.0);
    let auto = solve_grid(&grid, &eq, &man.sides(), &sor()).unwrap();
    let gs = solve_grid(
        &grid,
        &eq,
        &man.sides(),
        &SolveOptions {
            method: Method::Sor { omega: Some(1.0) },
            ..sor()
        },
    )
    .unwrap();
    assert!(
        5 * auto.iterations < gs.iterations,
        "auto {} sweeps (ω {:?}), Gauss–Seidel {}",
        auto.iterations,
        auto.omega,
        gs.iterations
    );
    let d = auto
        .u
        .iter()
        .zip(&gs.u)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(d < 1e-8, "{d}");
}

#[test]
fn quad_mesh_scheme_equals_the_structured_one_in_any_frame() {
    // The same grid as a QuadMesh, with every cell's vertex list rotated differently so
    // the local frames differ from the grid's: the solution must be the same.
    let grid = curved_grid(15, 11).unwrap();
    let man = Manufactured::sin_cosh();
    let eq = man.equation(1.0, 0.3, 2.0, -0.5);
    let opts = SolveOptions {
        tol: 1e-13,
        ..sor()
    };
    let a = solve_grid(&grid, &eq, &man.sides(), &opts).unwrap();
    let q = QuadMesh::from_grid(&grid);
    let cells: Vec<[usize; 4]> = q
        .cells()
        .iter()
        .enumerate()
        .map(|(k, c)| std::array::from_fn(|t| c[(t + k) % 4]))
        .collect();
    let q = QuadMesh::new(q.nodes().to_vec(), cells).unwrap();
    let b = solve_quads(&q, &eq, &man.boundary(), &opts).unwrap();
    let d =
        a.u.iter()
            .zip(&b.u)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
    assert!(d < 1e-9, "{d}");
}

#[test]
fn two_blocks_give_the_single_grid_solution() {
    // Split a 15 × 11 grid at i = 7 into two blocks, merge them: the interface nodes are
    // shared unknowns and the solution equals the single-grid one.
    let grid = curved_grid(15, 11).unwrap();
    let left = StructuredGrid2::from_fn(8, 11, |i, j| grid.node(i, j)).unwrap();
    let right = StructuredGrid2::from_fn(8, 11, |i, j| grid.node(i + 7, j)).unwrap();
    let bm = BlockMesh2::merge(vec![left, right], 1e-9).unwrap();
    let man = Manufactured::polynomial();
    let eq = man.equation(1.0, 0.0, 1.0, 0.0);
    let opts = SolveOptions {
        tol: 1e-13,
        ..sor()
    };
    let a = solve_grid(&grid, &eq, &man.sides(), &opts).unwrap();
    let b = solve_quads(&bm, &eq, &man.boundary(), &opts).unwrap();
    assert_eq!(b.unknowns, a.unknowns);
    for (k, p) in bm.nodes().iter().enumerate() {
        let g = grid
            .nodes()
            .iter()
            .position(|q| q.distance(*p) < 1e-12)
            .unwrap();
        assert!((a.u[g] - b.u[k]).abs() < 1e-9);
    }
}

#[test]
fn folded_and_non_elliptic_inputs_are_errors() {
    let mut grid = curved_grid(9, 9).unwrap();
    // push an interior node across its neighbour: cells fold
    let p = grid.node(5, 4);
    grid.set_node(4, 4, p + DVec2::new(0.05, 0.0));
    let eq = Equation::poisson(Source::Constant(1.0));
    let e = solve_grid(&grid, &eq, &zero_bc(), &sor());
    assert!(
        matches!(e, Err(PdeError::FoldedMesh { non_convex_cells, .. }) if non_convex_cells > 0),
        "{e:?}"
    );
    let e = solve_quads(
        &QuadMesh::from_grid(&grid),
        &eq,
        &SideValue::Constant(0.0),
        &sor(),
    );
    assert!(matches!(e, Err(PdeError::FoldedMesh { .. })));

    let grid = curved_grid(9, 9).unwrap();
    let eq = Equation::new(1.0, 1.0, 1.0, 0.0, Source::Constant(0.0));
    let e = solve_grid(&grid, &eq, &zero_bc(), &sor());
    assert!(matches!(e, Err(PdeError::NotElliptic { .. })), "{e:?}");
    let eq = Equation::new(1.0, 0.0, f64::NAN, 0.0, Source::Constant(0.0));
    assert!(matches!(
        solve_grid(&grid, &eq, &zero_bc(), &sor()),
        Err(PdeError::NonFiniteCoefficient { name: "c", .. })
    ));
    let nan = Source::Function(Arc::new(|p: DVec2| if p.x > 1.5 { f64::NAN } else { 0.0 }));
    assert!(matches!(
        solve_grid(&grid, &Equation::poisson(nan), &zero_bc(), &sor()),
        Err(PdeError::NonFiniteData {
            what: "source g",
            ..
        })
    ));
    let bad = SolveOptions {
        method: Method::Sor { omega: Some(2.5) },
        ..sor()
    };
    assert!(matches!(
        solve_grid(
            &grid,
            &Equation::poisson(Source::Constant(0.0)),
            &zero_bc(),
            &bad
        ),
        Err(PdeError::InvalidOption(_))
    ));
    assert!(matches!(
        solve_quads(
            &QuadMesh::from_grid(&grid),
            &Equation::poisson(Source::Constant(0.0)),
            &SideValue::Parabolic { peak: 1.0 },
            &sor()
        ),
        Err(PdeError::Boundary(_))
    ));
}

#[test]
fn side_profiles_peak_in_the_middle_and_corners_average() {
    // unit square, 5 × 5 nodes: the middle of each side is node 2 of 5, t = ½
    let grid =
        StructuredGrid2::from_fn(5, 5, |i, j| DVec2::new(i as f64 / 4.0, j as f64 / 4.0)).unwrap();
    let bc = [
        SideValue::Parabolic { peak: 2.0 },
        SideValue::Sinusoidal { peak: 3.0 },
        SideValue::Constant(1.0),
        SideValue::Constant(5.0),
    ];
    let v = grid_boundary_values(&grid, &bc).unwrap();
    assert_eq!(v[grid.index(2, 0)], Some(2.0)); // 4·2·½·½
    assert!((v[grid.index(1, 0)].unwrap() - 1.5).abs() < 1e-15); // 4·2·¼·¾
    assert!((v[grid.index(4, 2)].unwrap() - 3.0).abs() < 1e-15); // 3 sin(π/2)
    assert_eq!(v[grid.index(2, 4)], Some(1.0));
    assert_eq!(v[grid.index(0, 2)], Some(5.0));
    // corners: mean of the two sides' values at their ends
    assert_eq!(v[grid.index(0, 0)], Some(2.5)); // parabola 0, left 5
    assert!((v[grid.index(4, 4)].unwrap() - 0.5).abs() < 1e-15); // sine 0, top 1
    assert_eq!(v[grid.index(0, 4)], Some(3.0)); // top 1, left 5
    assert_eq!(v[grid.index(2, 2)], None);
}

#[test]
fn sor_reports_divergence_for_a_bad_fixed_omega() {
    // ω = 1.99 on a tiny grid converges slowly but does not diverge; d ≫ 0 near an
    // eigenvalue with ω close to 2 on the Helmholtz operator makes SOR blow up.
    let grid =
        StructuredGrid2::from_fn(21, 21, |i, j| DVec2::new(i as f64 / 20.0, j as f64 / 20.0))
            .unwrap();
    let eq = Equation::new(1.0, 0.0, 1.0, 400.0, Source::Constant(1.0));
    let opts = SolveOptions {
        method: Method::Sor { omega: Some(1.9) },
        max_iterations: 20_000,
        ..sor()
    };
    let e = solve_grid(&grid, &eq, &zero_bc(), &opts);
    assert!(
        matches!(
            e,
            Err(PdeError::SorDiverged { .. }) | Err(PdeError::NotConverged { .. })
        ),
        "{e:?}"
    );
}

#[cfg(feature = "direct")]
#[test]
fn direct_and_sor_agree() {
    let grid = curved_grid(21, 17).unwrap();
    let man = Manufactured::polynomial();
    let eq = man.equation(2.0, 0.5, 1.0, -1.0);
    let a = solve_grid(
        &grid,
        &eq,
        &man.sides(),
        &SolveOptions {
            tol: 1e-13,
            ..sor()
        },
    )
    .unwrap();
    let b = solve_grid(
        &grid,
        &eq,
        &man.sides(),
        &SolveOptions {
            method: Method::Direct,
            ..sor()
        },
    )
    .unwrap();
    assert_eq!(b.iterations, 0);
    assert!(b.residual < 1e-10, "{}", b.residual);
    let d =
        a.u.iter()
            .zip(&b.u)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
    assert!(d < 1e-9, "{d}");
}
