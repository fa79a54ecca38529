//! Modified areas vs scaled Visvalingam at the same ε ([Méndez 2023, §3.1.1, §3.3.4,
//! (3.4), (3.6)]): both remove the vertex of smallest key while it is below `ε·ā` (`ā` the mean
//! triangle area of the input ring); Visvalingam's key is the triangle area `a`, the modified
//! one `ζ = 2a|sin θ|`. Neither removes more in general: right-angle vertices (`|sin θ| = 1`,
//! `ζ = 2a`) are kept longer by the modified criterion, flat vertices (`|sin θ| < ½`) go
//! sooner. Two squares with counts worked out by hand, one for each case.

use unamalla_contour::{simplify_region, Method, Preset, SimplifyOptions};
use unamalla_mesh::{DVec2, Region};

fn removed(ring: Vec<DVec2>, method: Method, eps: f64) -> usize {
    let region = Region::new(ring, vec![]).unwrap();
    let opts = SimplifyOptions::new(method, Preset::Clean).epsilon(Some(eps));
    let r = simplify_region(&region, &opts).unwrap();
    r.vertices_before - r.vertices_after
}

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

#[test]
fn a_right_angled_bump_goes_with_visvalingam_and_stays_with_modified_areas() {
    // square [0,10]² with a bump of height 1 on the bottom edge, x ∈ [4, 6]:
    // areas a: (0,0) ½·10·4 = 20, (4,0) ½·4·1 = 2, (4,1) ½·1·2 = 1, (6,1) 1, (6,0) 2,
    // (10,0) 20, (10,10) 50, (0,10) 50; ā = 146/8 = 18.25; ε = 0.1 → threshold 1.825.
    // Visvalingam: (4,1) (a = 1) goes, then (6,1) (triangle (4,0),(6,1),(6,0): a = 1), then
    // (4,0) and (6,0) are collinear (a = 0): 4 removed.
    // Modified: every bump vertex has θ = 90°, ζ = 2a ∈ {2, 4} > 1.825: none removed.
    let ring = vec![
        v(0.0, 0.0),
        v(4.0, 0.0),
        v(4.0, 1.0),
        v(6.0, 1.0),
        v(6.0, 0.0),
        v(10.0, 0.0),
        v(10.0, 10.0),
        v(0.0, 10.0),
    ];
    assert_eq!(removed(ring.clone(), Method::Visvalingam, 0.1), 4);
    assert_eq!(removed(ring, Method::ModifiedAreas, 0.1), 0);
}

#[test]
fn a_flat_vertex_goes_with_modified_areas_and_stays_with_visvalingam() {
    // square [0,10]² with the bottom edge bent up to (5, 0.5): a = ½·10·0.5 = 2.5 there,
    // corners 25, 25, 50, 50; ā = 152.5/5 = 30.5; ε = 0.05 → threshold 1.525.
    // sin θ at (5, 0.5) = |det((−5,−0.5),(5,−0.5))|/|·|² = 5/25.25, ζ = 2·2.5·5/25.25 = 0.990.
    // Visvalingam: 2.5 > 1.525, nothing removed. Modified: 0.990 < 1.525, the vertex goes; the
    // square's corners then have ζ ≥ 100.
    let ring = vec![
        v(0.0, 0.0),
        v(5.0, 0.5),
        v(10.0, 0.0),
        v(10.0, 10.0),
        v(0.0, 10.0),
    ];
    assert_eq!(removed(ring.clone(), Method::Visvalingam, 0.05), 0);
    assert_eq!(removed(ring, Method::ModifiedAreas, 0.05), 1);
}
