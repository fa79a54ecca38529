//! Property: on random star-shaped regions (with and without a hole) the blocks tile the region
//! exactly — areas add up, each cut is shared by exactly two blocks, no two blocks overlap.

use proptest::prelude::*;
use unamalla_decompose::{decompose, DecomposeOptions, EdgeKind};
use unamalla_mesh::geometry::locate_in_ring;
use unamalla_mesh::{DVec2, Location, Region};

fn star(radii: &[f64], jitter: &[f64]) -> Vec<DVec2> {
    let n = radii.len();
    (0..n)
        .map(|k| {
            let t = (k as f64 + 0.4 * jitter[k]) / n as f64 * std::f64::consts::TAU;
            DVec2::new(t.cos(), t.sin()) * radii[k]
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]
    #[test]
    fn blocks_tile_the_region(
        radii in prop::collection::vec(0.5f64..1.6, 5..16),
        jitter in prop::collection::vec(-1.0f64..1.0, 16),
        hole in any::<bool>(),
    ) {
        let outer = star(&radii, &jitter);
        let holes = if hole {
            vec![vec![DVec2::new(-0.15, -0.1), DVec2::new(0.1, -0.15), DVec2::new(0.15, 0.12), DVec2::new(-0.1, 0.15)]]
        } else {
            vec![]
        };
        let region = Region::new(outer, holes).unwrap();
        let d = decompose(&region, &DecomposeOptions::default()).unwrap();
        d.validate(&region).unwrap();
        let sum: f64 = d.blocks.iter().map(|b| b.area()).sum();
        prop_assert!((sum - region.area()).abs() <= 1e-9 * region.area());
        for c in &d.cuts {
            let n: usize = d.blocks.iter().map(|b| b.edges.iter().filter(|e| matches!(e, EdgeKind::Cut { cut, .. } if *cut == c.id)).count()).sum();
            prop_assert_eq!(n, 2);
        }
        prop_assert_eq!(d.graph_cycles(), region.holes().len());
        // no overlap: the centroid of every triangle of a fan from each block's interior
        // sample lies in exactly one block; sample a grid
        for i in 0..25 {
            for j in 0..25 {
                let p = DVec2::new(-1.6 + 3.2 * (i as f64 + 0.5) / 25.0, -1.6 + 3.2 * (j as f64 + 0.5) / 25.0);
                let count = d.blocks.iter().filter(|b| locate_in_ring(&b.ring, p) == Location::Inside).count();
                let on = d.blocks.iter().any(|b| locate_in_ring(&b.ring, p) == Location::OnBoundary);
                if region.contains_point(p) {
                    prop_assert!(count == 1 || (on && count == 0));
                } else {
                    prop_assert_eq!(count, 0);
                }
            }
        }
    }
}
