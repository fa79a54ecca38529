//! `Region` construction from arbitrary coordinates (via `arbitrary`): raw `f64`s (NaN, ±∞,
//! subnormals, 1e308 …), small integer lattices scaled by 1, 1e-9, 1e9, 1e-300 or 1e300, and
//! small integer lattices offset far from the origin (`10^e + i`, e = 0..=18), so that
//! collinear, touching, duplicate and crossing configurations are frequent.
//!
//! Oracle: no panic; an accepted region has every vertex finite, its outer ring
//! counter-clockwise and its holes clockwise — checked **exactly** with `orient2d` at the
//! lexicographically smallest vertex (a convex vertex of any simple ring, whose neighbours are
//! not collinear with it) — a non-NaN area, and `locate` of each vertex is `OnBoundary`.
#![no_main]
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use unamalla_mesh::geometry::{orient2d, Location};
use unamalla_mesh::{DVec2, Region};

#[derive(Arbitrary, Debug)]
enum Coords {
    Raw(Vec<(f64, f64)>),
    Lattice(u8, Vec<(i8, i8)>),
    Offset(u8, Vec<(i8, i8)>),
}

#[derive(Arbitrary, Debug)]
struct Input {
    outer: Coords,
    holes: Vec<Coords>,
    cleaned: bool,
}

fn points(c: Coords) -> Vec<DVec2> {
    match c {
        Coords::Raw(v) => v.into_iter().map(|(x, y)| DVec2::new(x, y)).collect(),
        Coords::Lattice(s, v) => {
            let scale = [1.0, 1e-9, 1e9, 1e-300, 1e300][usize::from(s) % 5];
            v.into_iter()
                .map(|(x, y)| DVec2::new(f64::from(x) * scale, f64::from(y) * scale))
                .collect()
        }
        Coords::Offset(e, v) => {
            let base = 10f64.powi(i32::from(e % 19));
            v.into_iter()
                .map(|(x, y)| DVec2::new(base + f64::from(x), base + f64::from(y)))
                .collect()
        }
    }
}

/// Exact orientation sign of a simple open ring (positive = counter-clockwise).
fn orientation(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    let (k, _) = ring
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)))
        .expect("non-empty ring");
    orient2d(ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n])
}

fuzz_target!(|input: Input| {
    let outer = points(input.outer);
    let holes: Vec<Vec<DVec2>> = input.holes.into_iter().map(points).collect();
    let result = if input.cleaned {
        Region::new_cleaned(outer, holes).map(|(r, _)| r)
    } else {
        Region::new(outer, holes)
    };
    if let Ok(r) = result {
        assert!(
            orientation(r.outer().points()) > 0.0,
            "outer ring not counter-clockwise"
        );
        for h in r.holes() {
            assert!(orientation(h.points()) < 0.0, "hole not clockwise");
        }
        assert!(!r.area().is_nan(), "area is NaN");
        for ring in r.rings() {
            for &p in ring.points() {
                assert!(p.is_finite());
                assert_eq!(r.locate(p), Location::OnBoundary);
            }
        }
    }
});
