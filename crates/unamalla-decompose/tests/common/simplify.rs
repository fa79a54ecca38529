//! A stand-in topology-safe scaled Visvalingam reduction for tests and examples only (the
//! project's simplifier is the contour crate): vertices whose triangle area is below
//! `eps · area(region)` are removed in passes, never two neighbours in one pass, never when the
//! new edge would hit another edge or swallow a vertex of another ring.

use unamalla_mesh::geometry::{doubled_signed_area, open_segment_hits, orient2d};
use unamalla_mesh::{DVec2, Region, SegmentIndex};

/// Simplifies every ring of `region` (see the module docs).
pub fn simplify(region: &Region, eps: f64) -> Region {
    let mut rings: Vec<Vec<DVec2>> = region.rings().map(|p| p.points().to_vec()).collect();
    let limit = eps * region.area();
    loop {
        let index = SegmentIndex::new(rings.clone());
        let mut removed_any = false;
        let mut new_segs: Vec<(DVec2, DVec2)> = Vec::new();
        let mut next_rings = Vec::with_capacity(rings.len());
        for ring in &rings {
            let n = ring.len();
            let mut order: Vec<(f64, usize)> = (0..n)
                .map(|i| {
                    let a = doubled_signed_area(ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n])
                        .abs()
                        * 0.5;
                    (a, i)
                })
                .filter(|x| x.0 < limit)
                .collect();
            order.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut remove = vec![false; n];
            let mut count = n;
            for (_, i) in order {
                if count <= 4 {
                    break;
                }
                let (ip, inx) = ((i + n - 1) % n, (i + 1) % n);
                if remove[ip] || remove[inx] {
                    continue;
                }
                let (p, v, q) = (ring[ip], ring[i], ring[inx]);
                let blocked = index.candidates(p.min(q).min(v), p.max(q).max(v)).any(|e| {
                    let (a, b) = index.edge(e);
                    if open_segment_hits(p, q, a, b) {
                        return true;
                    }
                    // a vertex of another edge strictly inside the triangle p v q
                    [a, b].iter().any(|&x| {
                        x != p && x != q && x != v && {
                            let s = orient2d(p, v, q).signum();
                            orient2d(p, v, x).signum() == s
                                && orient2d(v, q, x).signum() == s
                                && orient2d(q, p, x).signum() == s
                        }
                    })
                }) || new_segs
                    .iter()
                    .any(|&(a, b)| open_segment_hits(p, q, a, b) || open_segment_hits(a, b, p, q));
                if blocked {
                    continue;
                }
                remove[i] = true;
                count -= 1;
                new_segs.push((p, q));
                removed_any = true;
            }
            next_rings.push(
                (0..n)
                    .filter(|&i| !remove[i])
                    .map(|i| ring[i])
                    .collect::<Vec<_>>(),
            );
        }
        rings = next_rings;
        if !removed_any {
            break;
        }
    }
    let outer = rings.remove(0);
    Region::new(outer, rings).expect("topology-safe simplification keeps the region valid")
}
