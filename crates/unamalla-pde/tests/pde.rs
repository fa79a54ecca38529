//! Convergence of the curvilinear PDE solver (`unamalla_pde`) with manufactured
//! solutions on a curved region: the nodal max error must shrink at second order when the
//! grid spacing is halved, on TFI grids and on optimized grids.

use unamalla_mesh::{HasNodes, StructuredGrid2};
use unamalla_optim::{smooth, NullObserver, SmoothOptions};
use unamalla_pde::manufactured::{curved_grid, observed_order, Manufactured};
use unamalla_pde::{solve_grid, SolveOptions};

/// (U, [a, b, c, d]): the Laplacian with U = sin(πx)cosh(y), and a cubic with all four
/// coefficients non-zero (a·c − b² = 1.75 > 0).
fn problems() -> [(Manufactured, [f64; 4]); 2] {
    [
        (Manufactured::sin_cosh(), [1.0, 0.0, 1.0, 0.0]),
        (Manufactured::polynomial(), [2.0, 0.5, 1.0, -1.0]),
    ]
}

fn max_errors(grids: &[StructuredGrid2]) -> Vec<Vec<f64>> {
    problems()
        .iter()
        .map(|(man, k)| {
            let eq = man.equation(k[0], k[1], k[2], k[3]);
            grids
                .iter()
                .map(|g| {
                    let s = solve_grid(g, &eq, &man.sides(), &SolveOptions::default()).unwrap();
                    man.error(g.nodes(), &s.u).max
                })
                .collect()
        })
        .collect()
}

fn assert_second_order(errors: &[Vec<f64>], what: &str) {
    for (p, e) in errors.iter().enumerate() {
        for w in e.windows(2) {
            // h halves from one grid to the next: order = log2(e_coarse / e_fine)
            let order = observed_order(w[0], w[1], 2.0);
            assert!(
                order >= 1.8,
                "{what}, problem {p}: errors {e:?}, order {order:.2}"
            );
        }
    }
}

#[test]
fn second_order_on_tfi_grids_of_a_curved_region() {
    // 17, 33, 65 nodes per side: h = 1/16, 1/32, 1/64 of the logical square
    let grids: Vec<_> = [17, 33, 65]
        .iter()
        .map(|&n| curved_grid(n, n).unwrap())
        .collect();
    let e = max_errors(&grids);
    assert_second_order(&e, "TFI");
}

#[test]
fn second_order_on_optimized_grids_of_a_curved_region() {
    // the thesis's default functional kArea-Length (σ = 0.5); its optimum is the discretization
    // of a smooth map, so the optimized grids form a smooth family too
    let opts = SmoothOptions::default().functional("karea-length".parse().unwrap());
    let grids: Vec<_> = [21, 41, 81]
        .iter()
        .map(|&n| {
            let mut g = curved_grid(n, n).unwrap();
            smooth(&mut g, &opts, &mut NullObserver).unwrap();
            g
        })
        .collect();
    let e = max_errors(&grids);
    assert_second_order(&e, "optimized");
}
