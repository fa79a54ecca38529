use super::queue::{order_bits, IndexedHeap};
use super::*;

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

#[test]
fn removal_blocked_by_a_vertex_of_another_ring() {
    // outer square with a midpoint bump at the top; a hole sits just under the bump's chord
    let outer = vec![v(0., 0.), v(10., 0.), v(10., 10.), v(5., 10.5), v(0., 10.)];
    let hole = vec![v(4.9, 9.9), v(5.1, 9.9), v(5.0, 10.1)];
    let ws = Workspace::new(&[outer.clone(), hole]);
    // vertex 3 (the bump) cannot go: the hole's apex (5, 10.1) is inside its triangle
    assert!(!ws.can_remove(3));
    let ws = Workspace::new(&[outer]);
    assert!(ws.can_remove(3));
}

#[test]
fn reflex_pocket_blocks_ear_removal() {
    // ring a, b, c, d with d inside triangle abc: removing b would flip the ring
    let ring = vec![v(0., 0.), v(5., 10.), v(10., 0.), v(5., 3.)];
    let ws = Workspace::new(&[ring]);
    assert!(!ws.can_remove(1));
    assert!(ws.can_remove(3));
}

use proptest::prelude::*;
use std::collections::BTreeSet;

/// Brute-force reference of the topology check: no other live vertex in the closed
/// triangle, tested against every live vertex with the exact predicate (no grid, no filter).
fn brute_can_remove(ws: &Workspace, b: usize) -> bool {
    let r = ws.ring(b);
    if !ws.alive(b) || ws.ring_len(r) <= 3 {
        return false;
    }
    let (ia, ic) = ws.neighbours(b);
    let (a, pb, c) = (ws.point(ia), ws.point(b), ws.point(ic));
    if ws.ring_len(r) == 4 && orient2d(a, c, ws.point(ws.neighbours(ic).1)) == 0.0 {
        return false;
    }
    let o = orient2d(a, pb, c);
    (0..ws.num_vertices())
        .filter(|&v| ws.alive(v) && v != ia && v != b && v != ic)
        .all(|v| {
            let p = ws.point(v);
            let inside = if o != 0.0 {
                let s = [orient2d(a, pb, p), orient2d(pb, c, p), orient2d(c, a, p)];
                s.iter().all(|&x| x * o >= 0.0)
            } else {
                point_on_segment(a, c, p)
                    || point_on_segment(a, pb, p)
                    || point_on_segment(pb, c, p)
            };
            !inside
        })
}

/// A star ring whose vertices sit on a coarse lattice (many exactly collinear triples and
/// vertices on triangle sides, so the exact fallback of the filter is exercised).
fn lattice_star(n: usize, radii: &[u8]) -> Vec<DVec2> {
    (0..n)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            let r = 4.0 + radii[k % radii.len()] as f64 % 6.0;
            v((r * t.cos()).round() * 0.5, (r * t.sin()).round() * 0.5)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, .. ProptestConfig::default() })]

    /// The grid query with the filtered orientation agrees with the brute-force exact test
    /// for every vertex, before and after a sequence of accepted removals.
    #[test]
    fn topology_check_matches_brute_force(
        n in 8usize..60,
        radii in prop::collection::vec(any::<u8>(), 1..60),
        order in prop::collection::vec(any::<u16>(), 0..80),
        lattice in any::<bool>(),
    ) {
        let mut ring = if lattice {
            lattice_star(n, &radii)
        } else {
            (0..n)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / n as f64;
                    let r = 40.0 + radii[k % radii.len()] as f64 * 0.2;
                    v(r * t.cos(), r * t.sin())
                })
                .collect()
        };
        ring.dedup();
        prop_assume!(unamalla_mesh::Region::new(ring.clone(), vec![]).is_ok());
        let hole: Vec<DVec2> = vec![v(-1.0, -1.0), v(1.5, -1.0), v(0.0, 1.5)];
        let mut ws = Workspace::new(&[ring, hole]);
        for step in order {
            for b in 0..ws.num_vertices() {
                if ws.alive(b) {
                    prop_assert_eq!(ws.can_remove(b), brute_can_remove(&ws, b), "vertex {}", b);
                }
            }
            let b = step as usize % ws.num_vertices();
            if ws.alive(b) && ws.can_remove(b) {
                ws.remove(b);
            }
        }
    }

    /// The filtered orientation has the sign of the exact predicate, also for exactly and
    /// nearly collinear points.
    #[test]
    fn filtered_orientation_has_the_exact_sign(
        ax in -1e3f64..1e3, ay in -1e3f64..1e3, bx in -1e3f64..1e3, by in -1e3f64..1e3,
        t in -2.0f64..3.0, ulps in -3i64..4,
    ) {
        let (a, b) = (v(ax, ay), v(bx, by));
        let p = a + t * (b - a);
        let p = v(f64::from_bits((p.x.to_bits() as i64 + ulps) as u64), p.y);
        for (x, y, z) in [(a, b, p), (b, p, a), (p, a, b), (a, a, p)] {
            prop_assert_eq!(orient_sign(x, y, z).partial_cmp(&0.0), orient2d(x, y, z).partial_cmp(&0.0));
        }
    }

    /// The indexed heap pops in (key, vertex) order under random set/remove operations
    /// (model: a `BTreeSet` of (key, vertex)).
    #[test]
    fn indexed_heap_matches_an_ordered_set(
        ops in prop::collection::vec((0usize..40, 0u64..20, 0u8..4), 1..300),
    ) {
        let mut h = IndexedHeap::new(40);
        let mut model: BTreeSet<(u64, u32)> = BTreeSet::new();
        let mut key_of = [None::<u64>; 40];
        for (v, k, op) in ops {
            match op {
                0 | 1 => {
                    if let Some(old) = key_of[v] {
                        model.remove(&(old, v as u32));
                    }
                    h.set(v, k);
                    model.insert((k, v as u32));
                    key_of[v] = Some(k);
                }
                2 => {
                    if let Some(old) = key_of[v].take() {
                        model.remove(&(old, v as u32));
                    }
                    h.remove(v);
                }
                _ => {
                    let got = h.pop();
                    let want = model.iter().next().copied();
                    if let Some(w) = want {
                        model.remove(&w);
                        key_of[w.1 as usize] = None;
                    }
                    prop_assert_eq!(got, want);
                }
            }
            prop_assert_eq!(h.peek(), model.iter().next().copied());
            prop_assert_eq!(h.items.len(), model.len());
        }
    }
}

#[test]
fn order_bits_is_total_cmp() {
    // the mapping must be monotone in f64::total_cmp, including signed zeros
    let xs = [
        f64::NEG_INFINITY,
        -2.0,
        -1e-300,
        -0.0,
        0.0,
        1e-300,
        1.0,
        3.5,
        f64::INFINITY,
    ];
    for w in xs.windows(2) {
        assert!(order_bits(w[0]) < order_bits(w[1]), "{} < {}", w[0], w[1]);
        assert_eq!(
            w[0].total_cmp(&w[1]),
            order_bits(w[0]).cmp(&order_bits(w[1]))
        );
    }
}
