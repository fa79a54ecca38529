//! The `unamalla eval` entry point: raw values against hand-computed sums.
#![allow(clippy::needless_range_loop)]

use approx::assert_relative_eq;
use unamalla_functionals::*;
use unamalla_mesh::{DVec2, QuadMesh, StructuredGrid2};

/// One quad v0 = (0,0), v1 = (2,0), v2 = (3,2), v3 = (0,1). Corner triangles (P; a = Q−P,
/// b = R−P; α, l, o), worked out by hand:
/// * corner 0: P = (0,0), a = (2,0),   b = (0,1):   α = 2, l = 5,  o = 0
/// * corner 1: P = (2,0), a = (1,2),   b = (−2,0):  α = 4, l = 9,  o = −2
/// * corner 2: P = (3,2), a = (−3,−1), b = (−1,−2): α = 5, l = 15, o = 5
/// * corner 3: P = (0,1), a = (0,−1),  b = (3,1):   α = 3, l = 11, o = −1
///
/// Σα = 14 = 4 · 3.5 (shoelace area 3.5).
fn one_quad() -> QuadMesh {
    QuadMesh::new(
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(3.0, 2.0),
            DVec2::new(0.0, 1.0),
        ],
        vec![[0, 1, 2, 3]],
    )
    .unwrap()
}

#[test]
fn raw_values_match_hand_computed_sums() {
    let mesh = one_quad();
    let cases: [(&str, Option<f64>, Option<f64>, f64); 8] = [
        ("length", None, None, 40.0),                    // 5 + 9 + 15 + 11
        ("area", None, None, 54.0),                      // 4 + 16 + 25 + 9
        ("orthogonality", None, None, 30.0),             // 0 + 4 + 25 + 1
        ("area-orthogonality", None, None, 42.0),        // (54 + 30)/2
        ("smoothness", None, None, 137.0 / 12.0),        // 5/2 + 9/4 + 15/5 + 11/3
        ("k-smoothness", None, Some(1.0), 637.0 / 60.0), // 7/3 + 11/5 + 17/6 + 13/4
        ("k-area", None, Some(1.0), 57.0 / 60.0),        // 1/3 + 1/5 + 1/6 + 1/4
        // ω = 4: α = 2 → 5·(8−2)/16; α = 4 → 9/4; α = 5 → 15/5; α = 3 → 11·(8−3)/16
        ("h-omega", Some(4.0), None, 169.0 / 16.0),
    ];
    for (name, omega, k, expected) in cases {
        let spec = FunctionalSpec::from_name(name, omega, k).unwrap();
        let r = evaluate(&mesh, &spec, true).unwrap();
        assert_relative_eq!(r.value, expected, max_relative = 1e-14);
        assert_eq!(
            r.gradient_norm, 0.0,
            "all nodes of a single quad are boundary nodes"
        );
        assert_eq!(r.num_triangles, 4);
        assert_relative_eq!(r.alpha_bar, 3.5, max_relative = 1e-14);
        assert_eq!(r.alpha_min, 2.0);
        assert_eq!(r.functional, name);
    }
    // castillo: cell area 3.5 → 12.25; a4p: (α − 3.5)⁴ = 2.25² + 0.5⁴ + 1.5⁴ + 0.5⁴
    let r = evaluate(
        &mesh,
        &FunctionalSpec::from_name("castillo-area", None, None).unwrap(),
        true,
    )
    .unwrap();
    assert_relative_eq!(r.value, 12.25, max_relative = 1e-14);
    let r = evaluate(
        &mesh,
        &FunctionalSpec::from_name("a4p", None, None).unwrap(),
        true,
    )
    .unwrap();
    assert_relative_eq!(
        r.value,
        5.0625 + 0.0625 + 5.0625 + 0.0625,
        max_relative = 1e-14
    );
}

/// Independent few-line implementation of the raw sums (the documented recipe).
fn reference(name: &str, nodes: &[DVec2], cells: &[[usize; 4]], omega: f64, k: f64) -> f64 {
    let mut s = 0.0;
    for c in cells {
        for i in 0..4 {
            let p = nodes[c[i]];
            let a = nodes[c[(i + 1) % 4]] - p;
            let b = nodes[c[(i + 3) % 4]] - p;
            let al = a.x * b.y - a.y * b.x;
            let l = a.x * a.x + a.y * a.y + b.x * b.x + b.y * b.y;
            let o = a.x * b.x + a.y * b.y;
            s += match name {
                "length" => l,
                "area" => al * al,
                "orthogonality" => o * o,
                "area-orthogonality" => 0.5 * (al * al + o * o),
                "smoothness" => l / al,
                "k-smoothness" => (l + 2.0 * k) / (k + al),
                "k-area" => 1.0 / (k + al),
                "h-omega" => {
                    l * if al >= omega {
                        1.0 / al
                    } else {
                        (2.0 * omega - al) / (omega * omega)
                    }
                }
                _ => unreachable!(),
            };
        }
    }
    s
}

#[test]
fn raw_values_and_gradient_norms_match_an_independent_implementation() {
    let g = StructuredGrid2::from_fn(4, 4, |i, j| {
        let (x, y) = (i as f64, j as f64);
        let inner = i > 0 && j > 0 && i < 3 && j < 3;
        let d = if inner {
            0.2 * ((3 * i + j) as f64).sin()
        } else {
            0.0
        };
        DVec2::new(x + d, y - 0.5 * d)
    })
    .unwrap();
    let mesh = QuadMesh::from_grid(&g);
    let nodes = g.clone().into_nodes();
    let cells: Vec<[usize; 4]> = mesh.cells().to_vec();
    let free: Vec<usize> = (0..16).filter(|&v| !mesh.fixed()[v]).collect();
    let (omega, k) = (0.9, 0.25);
    for name in &FUNCTIONAL_NAMES[..8] {
        let spec = FunctionalSpec::from_name(name, Some(omega), Some(k)).unwrap();
        let r = evaluate(&mesh, &spec, true).unwrap();
        let v = reference(name, &nodes, &cells, omega, k);
        assert_relative_eq!(r.value, v, max_relative = 1e-13);
        // gradient norm by central differences of the reference
        let mut g2 = 0.0;
        for &node in &free {
            for d in 0..2 {
                let h = 1e-6;
                let mut np = nodes.clone();
                np[node][d] += h;
                let mut nm = nodes.clone();
                nm[node][d] -= h;
                let fd = (reference(name, &np, &cells, omega, k)
                    - reference(name, &nm, &cells, omega, k))
                    / (2.0 * h);
                g2 += fd * fd;
            }
        }
        assert_relative_eq!(
            r.gradient_norm,
            g2.sqrt(),
            max_relative = 1e-6,
            epsilon = 1e-8
        );
        // the normalized value differs from the raw one by a positive constant
        let n = evaluate(&mesh, &spec, false).unwrap();
        assert!(!n.raw && n.value.is_finite() && n.value > 0.0 || *name == "orthogonality");
    }
}

#[test]
fn unknown_names_list_the_valid_ones_and_bad_parameters_are_rejected() {
    let e = FunctionalSpec::from_name("winslowish", None, None).unwrap_err();
    match &e {
        FunctionalError::UnknownFunctional { name, valid } => {
            assert_eq!(name, "winslowish");
            for n in FUNCTIONAL_NAMES {
                assert!(valid.contains(n));
            }
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().contains("h-omega"));
    assert!(FunctionalSpec::from_name("h-omega", Some(-1.0), None).is_err());
    assert!(FunctionalSpec::from_name("k-area", None, Some(f64::NAN)).is_err());
    // defaults: k = 0, ω = ᾱ/2
    let r = evaluate(
        &one_quad(),
        &FunctionalSpec::from_name("h-omega", None, None).unwrap(),
        true,
    )
    .unwrap();
    assert_eq!(r.omega, Some(1.75));
}

#[test]
fn k_functionals_beyond_the_barrier_are_infinite_in_raw_mode() {
    let r = evaluate(
        &one_quad(),
        &FunctionalSpec::from_name("k-area", None, Some(-2.0)).unwrap(),
        true,
    )
    .unwrap();
    assert_eq!(r.value, f64::INFINITY);
}
