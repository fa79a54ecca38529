//! The smoother does not depend on the units of the mesh: a folded mesh scaled by a power of
//! two is smoothed into the same mesh scaled by that power, bit for bit.
//!
//! Multiplying by `2^k` is exact in floating point, and every relative test of the solvers
//! (FTOL and GTOL against the first value or gradient, trust radius against ‖x‖, the safeguard's
//! margin against ᾱ, the homotopy's `k` against ᾱ) makes the same decision at both scales, so
//! any difference comes from an absolute constant. The untangling homotopy (a folded start)
//! and the classic phase of (6.8) both run here, on a structured grid and on the same cells as
//! an unstructured `QuadMesh` (the form of the pipeline's untangling patches).

use unamalla_mesh::{DVec2, FreeNodes, HasNodes, HasQuadCells, QuadMesh, StructuredGrid2};
use unamalla_optim::{smooth, Control, Monitor, SmoothFunctional, SmoothOptions, StopRules};

/// A wavy 12 × 12 grid with two interior nodes moved across their neighbours (folded cells),
/// all coordinates times `s`.
fn folded(s: f64) -> StructuredGrid2 {
    let n = 12;
    let mut g = StructuredGrid2::from_fn(n, n, |i, j| {
        let x = i as f64 + 0.3 * (j as f64 * 0.7).sin();
        let y = j as f64 + 0.2 * (i as f64 * 0.9).cos();
        DVec2::new(x * s, y * s)
    })
    .unwrap();
    for (k, d) in [
        (5 * n + 5, DVec2::new(1.6, 1.4)),
        (7 * n + 3, DVec2::new(-1.3, 0.2)),
    ] {
        let p = g.nodes()[k];
        g.nodes_mut()[k] = p + d * s;
    }
    g
}

fn as_quad_mesh(g: &StructuredGrid2) -> QuadMesh {
    let cells: Vec<[usize; 4]> = (0..g.num_quads()).map(|c| g.quad(c)).collect();
    let fixed: Vec<bool> = (0..g.nodes().len()).map(|v| g.is_fixed(v)).collect();
    let mut m = QuadMesh::new(g.nodes().to_vec(), cells).unwrap();
    m.set_fixed(fixed).unwrap();
    m
}

fn options() -> SmoothOptions {
    let mut o = SmoothOptions::default();
    o.functional = SmoothFunctional::block_smoothing(0.5);
    o.max_k_updates = 60;
    o.iters_per_k = 5;
    o.solver.max_iter = 60;
    o.solver.cg_max_iter = 40;
    o.solver.stop = StopRules::default();
    o
}

fn assert_scaled(a: &[DVec2], b: &[DVec2], s: f64, what: &str) {
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        assert!(*p * s == *q, "{what}: node {i}: {q} against {} scaled", *p);
    }
}

#[test]
fn a_mesh_scaled_by_a_power_of_two_is_smoothed_into_the_same_mesh_scaled() {
    let o = options();
    let mut never = |_: &Monitor| Control::Continue;
    let g0 = folded(1.0);
    assert!(
        unamalla_mesh::quality::non_convex_cells(&g0).len() >= 2,
        "the start is folded"
    );
    for k in [-14i32, 20] {
        let s = 2f64.powi(k);
        let (mut a, mut b) = (folded(1.0), folded(s));
        let ra = smooth(&mut a, &o, &mut never).unwrap();
        let rb = smooth(&mut b, &o, &mut never).unwrap();
        assert!(ra.convex, "{}", ra.status);
        assert_eq!(ra.iterations(), rb.iterations(), "× 2^{k}: iterations");
        assert_scaled(a.nodes(), b.nodes(), s, &format!("grid × 2^{k}"));
        let (mut a, mut b) = (as_quad_mesh(&folded(1.0)), as_quad_mesh(&folded(s)));
        smooth(&mut a, &o, &mut never).unwrap();
        smooth(&mut b, &o, &mut never).unwrap();
        assert_scaled(a.nodes(), b.nodes(), s, &format!("quad mesh × 2^{k}"));
        assert!(a.num_free() > 0);
    }
}
