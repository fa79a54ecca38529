//! Exact synthetic test geometries for submapping — our stand-ins for the figures of
//! [Ruiz-Gironés & Sarrate], which come without coordinates. Used by the tests, the comparison
//! example of `unamalla-core` and the GeoJSON files in `fixtures/synthetic/`.
//!
//! | name | stand-in for | expected labels (outer; holes) |
//! |---|---|---|
//! | `l-shape` | (the simplest case with one Corner) | E = 5, C = 1 |
//! | `u-shape` | (two Corners) | E = 6, C = 2 |
//! | `u-slot` | Ex 2 / Fig 14 (one Reversal) | E = 6, R = 1 |
//! | `square-hole` | Fig 8 | E = 4; C = 4 |
//! | `plate-3-holes` | Fig 10, Fig 17 | E = 4; C = 4 per hole |
//! | `half-nut` | Ex 1 / Fig 13 | rule gives E = 7, ILP (6) → E = 4 |
//! | `mechanical-part` | Ex 4 / Fig 15b + a hole (Ex 6) | rule gives E − C = 5, ILP (6) → E = 5, C = 1; C = 4 |

use std::f64::consts::{FRAC_PI_2, PI};

use unamalla_mesh::{DVec2, GeometryError, Region};

fn ring(p: &[(f64, f64)]) -> Vec<DVec2> {
    p.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec2> {
    ring(&[(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
}

/// L-shape `(0,0),(2,0),(2,1),(1,1),(1,2),(0,2)`: Corner at `(1,1)`.
pub fn l_shape() -> Result<Region, GeometryError> {
    Region::new(
        ring(&[(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]),
        vec![],
    )
}

/// U-shape `[0,3]×[0,2]` minus the slot `[1,2]×[1,2]`: Corners at `(2,1)` and `(1,1)`.
pub fn u_shape() -> Result<Region, GeometryError> {
    Region::new(
        ring(&[
            (0., 0.),
            (3., 0.),
            (3., 2.),
            (2., 2.),
            (2., 1.),
            (1., 1.),
            (1., 2.),
            (0., 2.),
        ]),
        vec![],
    )
}

/// A U whose slot is a narrow V down to `(1.5, 0.8)`: the slot bottom turns by −175.2°
/// (α = −1.95, Reversal), the slot mouths by +87.6° (End).
pub fn u_slot() -> Result<Region, GeometryError> {
    Region::new(
        ring(&[
            (0., 0.),
            (3., 0.),
            (3., 2.),
            (1.55, 2.),
            (1.5, 0.8),
            (1.45, 2.),
            (0., 2.),
        ]),
        vec![],
    )
}

/// Square `[0,4]²` with the square hole `[1.5,2.5]²`.
pub fn square_hole() -> Result<Region, GeometryError> {
    Region::new(rect(0., 0., 4., 4.), vec![rect(1.5, 1.5, 2.5, 2.5)])
}

/// Plate `[0,10]×[0,6]` with the holes `[1,3]×[2,4]`, `[4,6]×[1,2.5]`, `[7,9]×[3,5]`.
pub fn plate_three_holes() -> Result<Region, GeometryError> {
    Region::new(
        rect(0., 0., 10., 6.),
        vec![
            rect(1., 2., 3., 4.),
            rect(4., 1., 6., 2.5),
            rect(7., 3., 9., 5.),
        ],
    )
}

/// Right half of a hexagonal nut (circumradius 2, flats at `y = ±√3`) with the half bore of
/// radius 1 (24 chords). The three hexagon bends turn by +60° (α = 2/3, End by the rule), so the
/// rule gives E = 7 and ILP (6) relabels them Side.
pub fn half_nut() -> Result<Region, GeometryError> {
    let s3 = 3f64.sqrt();
    let mut pts = ring(&[(0., -s3), (1., -s3), (2., 0.), (1., s3), (0., s3), (0., 1.)]);
    for k in 1..24 {
        let t = FRAC_PI_2 - PI * k as f64 / 24.0;
        pts.push(DVec2::new(t.cos(), t.sin()));
    }
    pts.push(DVec2::new(0., -1.));
    Region::new(pts, vec![])
}

/// Mechanical part: a stepped bracket (Corner at `(4,2)`) with a slanted roof whose lower bend
/// `(4,3.2)` turns by 48.4° (α = 0.537, End by the rule, so E − C = 5 ≠ 4 and ILP (6) makes it
/// Side), plus the rectangular hole `[1,2.5]×[0.8,2]`.
pub fn mechanical_part() -> Result<Region, GeometryError> {
    Region::new(
        ring(&[
            (0., 0.),
            (8., 0.),
            (8., 2.),
            (4., 2.),
            (4., 3.2),
            (2.2, 4.8),
            (0., 3.2),
        ]),
        vec![rect(1.0, 0.8, 2.5, 2.0)],
    )
}

/// All shapes with their file names (without extension).
pub fn all() -> Result<Vec<(&'static str, Region)>, GeometryError> {
    Ok(vec![
        ("l-shape", l_shape()?),
        ("u-shape", u_shape()?),
        ("u-slot", u_slot()?),
        ("square-hole", square_hole()?),
        ("plate-3-holes", plate_three_holes()?),
        ("half-nut", half_nut()?),
        ("mechanical-part", mechanical_part()?),
    ])
}
