//! TFI: boundary reproduction, exactness on affine data, 3D Boolean sum, sides from a ring.

use proptest::prelude::*;
use unamalla_mesh::tfi::sides_from_ring;
use unamalla_mesh::{tfi2, tfi3, DVec2, DVec3, HexFaces, MeshError, StructuredGrid3, TfiParams};

fn affine2(x: f64, y: f64) -> DVec2 {
    // a parallelogram: unit square under a shear + scale + translation
    DVec2::new(3.0 * x + 1.2 * y - 2.0, 0.4 * x + 2.0 * y + 5.0)
}

fn parallelogram_sides(m: usize, n: usize) -> [Vec<DVec2>; 4] {
    let b = (0..m)
        .map(|i| affine2(i as f64 / (m - 1) as f64, 0.0))
        .collect();
    let t = (0..m)
        .map(|i| affine2(i as f64 / (m - 1) as f64, 1.0))
        .collect();
    let l = (0..n)
        .map(|j| affine2(0.0, j as f64 / (n - 1) as f64))
        .collect();
    let r = (0..n)
        .map(|j| affine2(1.0, j as f64 / (n - 1) as f64))
        .collect();
    [b, r, t, l]
}

#[test]
fn tfi_of_a_parallelogram_is_the_affine_grid() {
    for kind in [TfiParams::Uniform, TfiParams::ArcLength] {
        let [b, r, t, l] = parallelogram_sides(7, 5);
        let g = tfi2(&b, &r, &t, &l, kind).unwrap();
        for j in 0..5 {
            for i in 0..7 {
                let want = affine2(i as f64 / 6.0, j as f64 / 4.0);
                assert!(g.node(i, j).distance(want) < 1e-12, "{kind:?} ({i},{j})");
            }
        }
    }
}

proptest! {
    #[test]
    fn tfi_reproduces_boundary_nodes_exactly(
        m in 2usize..12, n in 2usize..12,
        noise in prop::collection::vec(-0.3f64..0.3, 48),
        arc in any::<bool>()
    ) {
        // a wavy four-sided boundary with arbitrary (non-uniform) point spacing
        let wav = |k: usize| noise[k % noise.len()];
        let b: Vec<DVec2> = (0..m).map(|i| { let s = i as f64 / (m - 1) as f64; DVec2::new(s + if i > 0 && i + 1 < m { 0.1 * wav(i) } else { 0.0 }, 0.2 * (3.0 * s).sin()) }).collect();
        let t: Vec<DVec2> = (0..m).map(|i| { let s = i as f64 / (m - 1) as f64; DVec2::new(s + if i > 0 && i + 1 < m { 0.1 * wav(i + 12) } else { 0.0 }, 1.0 + 0.2 * (5.0 * s).cos()) }).collect();
        let tl = t[0];
        let tr = t[m - 1];
        let l: Vec<DVec2> = (0..n).map(|j| { let s = j as f64 / (n - 1) as f64; b[0].lerp(tl, s) + if j > 0 && j + 1 < n { DVec2::new(0.1 * wav(j + 24), 0.0) } else { DVec2::ZERO } }).collect();
        let r: Vec<DVec2> = (0..n).map(|j| { let s = j as f64 / (n - 1) as f64; b[m - 1].lerp(tr, s) + if j > 0 && j + 1 < n { DVec2::new(0.1 * wav(j + 36), 0.0) } else { DVec2::ZERO } }).collect();
        let kind = if arc { TfiParams::ArcLength } else { TfiParams::Uniform };
        let g = tfi2(&b, &r, &t, &l, kind).unwrap();
        prop_assert_eq!(g.bottom(), b);
        prop_assert_eq!(g.top(), t);
        prop_assert_eq!(g.left(), l);
        prop_assert_eq!(g.right(), r);
    }
}

#[test]
fn tfi_rejects_mismatched_input() {
    let [b, r, t, l] = parallelogram_sides(5, 4);
    let e = tfi2(&b, &r, &t[..4], &l, TfiParams::Uniform).unwrap_err();
    assert_eq!(
        e,
        MeshError::SideCountMismatch {
            which: "bottom/top",
            a: 5,
            b: 4
        }
    );
    let mut r2 = r.clone();
    r2[0] += DVec2::new(0.5, 0.0);
    let e = tfi2(&b, &r2, &t, &l, TfiParams::Uniform).unwrap_err();
    assert!(matches!(
        e,
        MeshError::CornerMismatch {
            corner: "bottom-right",
            ..
        }
    ));
}

#[test]
fn sides_from_a_rectangle_ring() {
    // rectangle 4 × 2 given with extra collinear vertices; corners at 0, 2, 3, 5
    let ring = vec![
        DVec2::new(0., 0.),
        DVec2::new(1., 0.),
        DVec2::new(4., 0.),
        DVec2::new(4., 2.),
        DVec2::new(2., 2.),
        DVec2::new(0., 2.),
    ];
    let [b, r, t, l] = sides_from_ring(&ring, [0, 2, 3, 5], 5, 3).unwrap();
    assert_eq!(
        b,
        (0..5).map(|i| DVec2::new(i as f64, 0.)).collect::<Vec<_>>()
    );
    assert_eq!(
        t,
        (0..5).map(|i| DVec2::new(i as f64, 2.)).collect::<Vec<_>>()
    );
    assert_eq!(
        l,
        (0..3).map(|j| DVec2::new(0., j as f64)).collect::<Vec<_>>()
    );
    assert_eq!(
        r,
        (0..3).map(|j| DVec2::new(4., j as f64)).collect::<Vec<_>>()
    );
    let g = tfi2(&b, &r, &t, &l, TfiParams::Uniform).unwrap();
    assert_eq!(g.node(2, 1), DVec2::new(2., 1.));
    assert!(sides_from_ring(&ring, [0, 3, 2, 5], 5, 3).is_err());
    assert!(sides_from_ring(&ring, [0, 2, 3, 9], 5, 3).is_err());
}

fn affine3(p: DVec3) -> DVec3 {
    DVec3::new(
        2.0 * p.x + 0.3 * p.y - 0.2 * p.z + 1.0,
        -0.5 * p.x + 1.5 * p.y + 0.1 * p.z,
        0.2 * p.x + 0.4 * p.y + 3.0 * p.z - 2.0,
    )
}

#[test]
fn tfi3_of_an_affine_box_is_the_affine_grid() {
    let (m, n, p) = (5, 4, 6);
    let exact = StructuredGrid3::from_fn(m, n, p, |i, j, k| {
        affine3(DVec3::new(
            i as f64 / (m - 1) as f64,
            j as f64 / (n - 1) as f64,
            k as f64 / (p - 1) as f64,
        ))
    })
    .unwrap();
    let g = tfi3(&HexFaces::of_grid(&exact)).unwrap();
    for (a, b) in g.into_nodes().iter().zip(exact.into_nodes()) {
        assert!(a.distance(b) < 1e-12);
    }
}

#[test]
fn tfi3_reproduces_curved_faces_and_checks_edges() {
    // a box with a curved top z = 1 + 0.2 sin(x) cos(y)
    let (m, n, p) = (6, 5, 4);
    let f = |i: usize, j: usize, k: usize| {
        let (x, y, t) = (i as f64 / 5.0, j as f64 / 4.0, k as f64 / 3.0);
        let top = 1.0 + 0.2 * (3.0 * x).sin() * (2.0 * y).cos();
        DVec3::new(x, y, t * top)
    };
    let full = StructuredGrid3::from_fn(m, n, p, f).unwrap();
    let faces = HexFaces::of_grid(&full);
    let g = tfi3(&faces).unwrap();
    for k in 0..p {
        for j in 0..n {
            for i in 0..m {
                if full.is_boundary(i, j, k) {
                    assert_eq!(g.node(i, j, k), full.node(i, j, k));
                }
            }
        }
    }
    // this map is linear in t along each vertical line, which the Boolean sum reproduces
    for k in 0..p {
        for j in 0..n {
            for i in 0..m {
                assert!(g.node(i, j, k).distance(full.node(i, j, k)) < 1e-12);
            }
        }
    }
    let mut bad = faces.clone();
    bad.k_max[0] += DVec3::new(0.0, 0.0, 0.1);
    assert!(matches!(tfi3(&bad), Err(MeshError::CornerMismatch { .. })));
    let mut short = faces;
    short.i_min.pop();
    assert!(matches!(tfi3(&short), Err(MeshError::InvalidSize(_))));
}
