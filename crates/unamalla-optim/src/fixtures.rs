//! The test regions of [González Flores] (§A.4.3, §A.5, (2.3)–(2.6)) as folded TFI grids, and the
//! curvy four-sided benchmark region.
//!
//! * [`cuad2pp`]: the contour of `cuad2pp.red` (§A.5): B1 = (0.4,0)–(0.6,0), B2 = (0.6,0)–(1,0),
//!   B3 = (1,0),(1,1),(0,1),(0,0), B4 = (0,0)–(0.4,0). Two block corners, (0.4,0) and (0.6,0),
//!   are straight angles, so their corner triangles (all three vertices fixed) have α = 0.
//! * [`one_hole`]: the 13-point contour with `ibflag = 13` (§A.5.1, Fig A.40): B1 = cut
//!   (0,0)→(9,0), B2 = the hexagonal hole (9,0),(12,4),(16,4),(19,1),(15,−3),(11,−3),(9,0)
//!   (clockwise), B3 = the cut back, B4 = the outer quadrilateral
//!   (0,0),(20,−15),(30,1),(12,15),(0,0).
//! * [`ivanenko`]: the image of the unit square under `x = ½(ξ²−η²) − ⅔ξ`,
//!   `y = ξη + ½ξ − ⅓η` ((2.3)–(2.6)), boundary sampled uniformly in `ξ`, `η`.
//! * [`sinusoidal`]: the unit square with sinusoidal sides (the benchmark region).
//!
//! Sides with polyline data are resampled by arc length; the interior is plain TFI
//! ([`tfi2`], uniform parameters).

use unamalla_mesh::{resample_arc_length, tfi2, DVec2, MeshError, StructuredGrid2, TfiParams};

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn rev(mut p: Vec<DVec2>) -> Vec<DVec2> {
    p.reverse();
    p
}

/// TFI grid of the `cuad2pp` contour with `m` points on B1/B3 and `n` on B2/B4. With
/// `m − 1` divisible by 3 the square's corners (0,1), (1,1) are grid nodes.
pub fn cuad2pp(m: usize, n: usize) -> Result<StructuredGrid2, MeshError> {
    let bottom = resample_arc_length(&[v(0.4, 0.0), v(0.6, 0.0)], m)?;
    let right = resample_arc_length(&[v(0.6, 0.0), v(1.0, 0.0)], n)?;
    // B3 runs (1,0)→(1,1)→(0,1)→(0,0) counter-clockwise; TFI wants it left to right
    let top = rev(resample_arc_length(
        &[v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0), v(0.0, 0.0)],
        m,
    )?);
    // B4 runs (0,0)→(0.4,0); TFI wants the left side bottom to top: (0.4,0)→(0,0)
    let left = rev(resample_arc_length(&[v(0.0, 0.0), v(0.4, 0.0)], n)?);
    tfi2(&bottom, &right, &top, &left, TfiParams::Uniform)
}

/// TFI grid of the one-hole contour through its cut: `m` points on the cut (B1, B3), `n` on
/// the hole loop (B2) and on the outer loop (B4). The bottom and top rows coincide
/// geometrically (the two sides of the cut); both are fixed.
pub fn one_hole(m: usize, n: usize) -> Result<StructuredGrid2, MeshError> {
    let cut = resample_arc_length(&[v(0.0, 0.0), v(9.0, 0.0)], m)?;
    let hole = [
        v(9.0, 0.0),
        v(12.0, 4.0),
        v(16.0, 4.0),
        v(19.0, 1.0),
        v(15.0, -3.0),
        v(11.0, -3.0),
        v(9.0, 0.0),
    ];
    let right = resample_arc_length(&hole, n)?;
    let outer_ccw = [
        v(0.0, 0.0),
        v(20.0, -15.0),
        v(30.0, 1.0),
        v(12.0, 15.0),
        v(0.0, 0.0),
    ];
    // B4 runs counter-clockwise from the top-left corner to the bottom-left corner; TFI wants
    // it bottom to top
    let left = rev(resample_arc_length(&outer_ccw, n)?);
    tfi2(&cut, &right, &cut, &left, TfiParams::Uniform)
}

/// Ivanenko's map `(ξ, η) ↦ (½(ξ²−η²) − ⅔ξ, ξη + ½ξ − ⅓η)`.
pub fn ivanenko_map(xi: f64, eta: f64) -> DVec2 {
    v(
        0.5 * (xi * xi - eta * eta) - 2.0 / 3.0 * xi,
        xi * eta + 0.5 * xi - eta / 3.0,
    )
}

/// TFI grid of Ivanenko's parabolic region, `m × n` nodes.
pub fn ivanenko(m: usize, n: usize) -> Result<StructuredGrid2, MeshError> {
    if m < 2 || n < 2 {
        return Err(MeshError::InvalidSize(format!(
            "grid needs m, n ≥ 2, got {m} × {n}"
        )));
    }
    let s = |k: usize, i: usize| i as f64 / (k - 1) as f64;
    let bottom: Vec<DVec2> = (0..m).map(|i| ivanenko_map(s(m, i), 0.0)).collect();
    let top: Vec<DVec2> = (0..m).map(|i| ivanenko_map(s(m, i), 1.0)).collect();
    let left: Vec<DVec2> = (0..n).map(|j| ivanenko_map(0.0, s(n, j))).collect();
    let right: Vec<DVec2> = (0..n).map(|j| ivanenko_map(1.0, s(n, j))).collect();
    tfi2(&bottom, &right, &top, &left, TfiParams::Uniform)
}

/// TFI grid of the unit square with sinusoidal sides of amplitude `amp` (`waves` periods per
/// side): bottom `y = amp·sin(2π·waves·x)`, top `y = 1 + amp·sin(2π·waves·x + 1)`, left
/// `x = amp·sin(2π·waves·y)`, right `x = 1 + amp·sin(2π·waves·y + 2)`, `m × n` nodes.
pub fn sinusoidal(m: usize, n: usize, amp: f64, waves: f64) -> Result<StructuredGrid2, MeshError> {
    if m < 2 || n < 2 {
        return Err(MeshError::InvalidSize(format!(
            "grid needs m, n ≥ 2, got {m} × {n}"
        )));
    }
    let w = 2.0 * std::f64::consts::PI * waves;
    let s = |k: usize, i: usize| i as f64 / (k - 1) as f64;
    // corner values: the sines vanish at 0 and 1 only for the unshifted sides, so the shifted
    // sides are multiplied by a taper that is 0 at the ends
    let taper = |t: f64| (std::f64::consts::PI * t).sin();
    let bottom: Vec<DVec2> = (0..m)
        .map(|i| {
            let t = s(m, i);
            v(t, amp * (w * t).sin() * taper(t))
        })
        .collect();
    let top: Vec<DVec2> = (0..m)
        .map(|i| {
            let t = s(m, i);
            v(t, 1.0 + amp * (w * t + 1.0).sin() * taper(t))
        })
        .collect();
    let left: Vec<DVec2> = (0..n)
        .map(|j| {
            let t = s(n, j);
            v(amp * (w * t).sin() * taper(t), t)
        })
        .collect();
    let right: Vec<DVec2> = (0..n)
        .map(|j| {
            let t = s(n, j);
            v(1.0 + amp * (w * t + 2.0).sin() * taper(t), t)
        })
        .collect();
    tfi2(&bottom, &right, &top, &left, TfiParams::Uniform)
}

/// A copy of `grid` whose interior nodes are displaced by a deterministic pseudo-random vector
/// of length up to `amp` times the shortest edge at the node (`amp ≳ 0.5` folds cells).
pub fn perturbed(grid: &StructuredGrid2, amp: f64, seed: u64) -> StructuredGrid2 {
    let mut g = grid.clone();
    let (m, n) = (grid.m(), grid.n());
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for j in 1..n.saturating_sub(1) {
        for i in 1..m.saturating_sub(1) {
            let p = grid.node(i, j);
            let h = [
                grid.node(i + 1, j),
                grid.node(i - 1, j),
                grid.node(i, j + 1),
                grid.node(i, j - 1),
            ]
            .iter()
            .map(|q| q.distance(p))
            .fold(f64::INFINITY, f64::min);
            let (r, t) = (amp * h * rnd(), 2.0 * std::f64::consts::PI * rnd());
            g.set_node(i, j, p + DVec2::new(r * t.cos(), r * t.sin()));
        }
    }
    g
}
