//! The removal loops: one vertex at a time by a key (`sequential`), or a given batch.

use glam::DVec2;

use super::queue::{order_bits, IndexedHeap, Queue};
use super::Workspace;

/// When the sequential removal stops.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Stop {
    /// Remove while the smallest key is below this fixed value (scaled Visvalingam, modified
    /// criteria (3.6), (3.8): `ε ·` the mean triangle area of the input ring).
    Below(f64),
}

/// Rounds of retrying vertices whose removal was blocked by the topology check.
pub(super) const RETRY_ROUNDS: usize = 4;

/// Sequential (one vertex at a time) removal on ring `r` with a priority queue: repeatedly
/// take the live vertex of smallest `key` (ties: lowest vertex id), stop when it is not below
/// the threshold, skip it if its removal is topologically unsafe, otherwise remove it and
/// update only its two neighbours' keys. O(n log n) ([`Queue`]). A skipped vertex comes
/// back when a neighbour changes; the vertices still skipped when the queue runs out are
/// retried in up to [`RETRY_ROUNDS`] further rounds (other removals may have emptied their
/// triangles). Returns the number removed.
pub(crate) fn sequential<K>(ws: &mut Workspace, r: usize, key: K, stop: Stop) -> usize
where
    K: Fn(DVec2, DVec2, DVec2) -> f64,
{
    let Stop::Below(threshold) = stop;
    let ids = ws.ring_ids(r);
    let n = ws.num_vertices();
    let mut sorted = Vec::with_capacity(ids.len());
    for &v in &ids {
        let (a, b, c) = ws.triangle(v);
        let k = key(a, b, c);
        if k < threshold {
            sorted.push((order_bits(k), v as u32, ws.stamp(v)));
        }
    }
    sorted.sort_unstable();
    let mut q = Queue {
        sorted,
        pos: 0,
        heap: IndexedHeap::new(n),
    };
    let mut removed = 0;
    // skipped vertices with their stamps: one is re-queued in a retry round only if no
    // neighbour change re-queued it since
    let mut skipped: Vec<(u32, u32)> = Vec::new();
    for _ in 0..=RETRY_ROUNDS {
        let mut removed_round = 0;
        while let Some(v) = q.pop(ws) {
            // every queued key is below the threshold (only those are queued)
            if ws.ring_len(r) <= 3 {
                break;
            }
            // prefetch the heap positions the key updates will read (see `touch`)
            let (ia, ic) = ws.neighbours(v);
            q.heap.warm(ia);
            q.heap.warm(ic);
            if !ws.can_remove(v) {
                skipped.push((v as u32, ws.stamp(v)));
                continue;
            }
            ws.remove(v);
            // second prefetch stage for the heap's root (its node was prefetched at the pop)
            if let Some(&(_, u)) = q.heap.items.first() {
                ws.warm_around(u as usize);
            }
            removed += 1;
            removed_round += 1;
            // `remove` bumped the stamps of `ia`, `ic`: their `sorted` entries are stale
            for w in [ia, ic] {
                let (a, b, c) = ws.triangle(w);
                let k = key(a, b, c);
                if k < threshold {
                    q.heap.set(w, order_bits(k));
                } else {
                    q.heap.remove(w);
                }
            }
        }
        if removed_round == 0 || skipped.is_empty() || ws.ring_len(r) <= 3 {
            break;
        }
        q.heap.clear();
        q.pos = q.sorted.len();
        for (v, st) in skipped.drain(..) {
            let v = v as usize;
            // still live and not re-queued since (a neighbour change would have done that)
            if ws.alive(v) && ws.stamp(v) == st {
                // its neighbours are those of its last key evaluation (unchanged stamp), so
                // this recomputes exactly that key
                let (a, b, c) = ws.triangle(v);
                q.heap.set(v, order_bits(key(a, b, c)));
            }
        }
    }
    removed
}

/// Batch ("non-sequential") removal on ring `r` (§3.3.1–§3.3.2, Obs 3.3): each pass evaluates
/// `remove(a, b, c, mean_area)` for every live vertex of the current ring (`mean_area` is the
/// current mean triangle area), then deletes all vertices that satisfied it (each deletion
/// topology-checked against the ring as it is at that moment); passes repeat until one deletes
/// nothing. Returns the number removed.
pub(crate) fn batch<F>(ws: &mut Workspace, r: usize, remove: F) -> usize
where
    F: Fn(DVec2, DVec2, DVec2, f64) -> bool,
{
    let mut removed = 0;
    loop {
        let ids = ws.ring_ids(r);
        let tris: Vec<(DVec2, DVec2, DVec2)> = ids.iter().map(|&v| ws.triangle(v)).collect();
        let mean = tris
            .iter()
            .map(|&(a, b, c)| crate::criteria::triangle_area(a, b, c))
            .sum::<f64>()
            / ids.len() as f64;
        let cands: Vec<usize> = ids
            .iter()
            .zip(&tris)
            .filter(|(_, &(a, b, c))| remove(a, b, c, mean))
            .map(|(&v, _)| v)
            .collect();
        let mut pass = 0;
        for v in cands {
            if ws.ring_len(r) <= 3 {
                break;
            }
            if ws.can_remove(v) {
                ws.remove(v);
                pass += 1;
            }
        }
        removed += pass;
        if pass == 0 {
            break;
        }
    }
    removed
}
