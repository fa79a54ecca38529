//! Step 2 and 3 of the repair: merges with a neighbour, and the re-split of a block or its
//! union with one or two neighbours into two or three good blocks.

use rayon::prelude::*;

use super::cache::{host_key, relabel_resplits, FitMemo};
use super::table::CutTable;
use super::{as_first_cut, beats, ring_key, union_ring, Merge, Resplit, Split, RESPLIT_SLACK};
use crate::builder::Builder;
use crate::piece::{Ring, Tag};

/// The neighbourhood of a block that a repair attempt reads: block slot `k`, the blocks
/// across its cuts and the blocks across theirs (rings, tags, and whether those cuts are
/// alive and protected), in a numbering independent of slot numbers and cut ids (`key`) and
/// the numbering itself (`slots`, `cuts`): two neighbourhoods are equal exactly when they
/// hold the same blocks in the same slots with the same cuts.
#[derive(PartialEq)]
pub(super) struct Neighbourhood {
    /// The slots, block first, in the order of discovery (canonical slot `i` is `slots[i]`).
    pub(super) slots: Vec<usize>,
    /// The cut ids in order of first appearance in the key (canonical cut `i` is `cuts[i]`).
    pub(super) cuts: Vec<usize>,
    /// For each slot in order: the rank of its slot number among `slots` (the attempt picks
    /// the first slot holding a cut), its vertices, and per edge the original-boundary ring
    /// or the canonical cut id with whether the cut is protected and alive.
    pub(super) key: Vec<u64>,
}

/// The slots holding each cut, in slot order (as `neighbour_unions` searches them): what
/// [`Neighbourhood::new`] follows from a block to its neighbours. A function of the slots
/// alone, so [`Builder::repair_pass`] computes it once per state of the slots.
pub(super) type CutHolders = std::collections::HashMap<usize, Vec<usize>>;

/// The [`CutHolders`] of `slot`.
pub(super) fn cut_holders(slot: &[Option<Ring>]) -> CutHolders {
    let mut holders = CutHolders::new();
    for (j, o) in slot.iter().enumerate() {
        for t in o.iter().flat_map(|r| r.tags.iter()) {
            if let Tag::Cut(c) = *t {
                let h = holders.entry(c).or_default();
                if h.last() != Some(&j) {
                    h.push(j);
                }
            }
        }
    }
    holders
}

impl Neighbourhood {
    /// The neighbourhood of block slot `k`; `holders` = [`cut_holders`]`(slot)`.
    pub(super) fn new(
        slot: &[Option<Ring>],
        holders: &CutHolders,
        k: usize,
        alive: &[bool],
        protected: usize,
    ) -> Self {
        let mut slots = vec![k];
        let mut frontier = vec![k];
        for _ in 0..2 {
            let mut next = Vec::new();
            for &s in &frontier {
                for t in slot[s].iter().flat_map(|r| r.tags.iter()) {
                    let Tag::Cut(c) = *t else { continue };
                    for &j in holders.get(&c).map(Vec::as_slice).unwrap_or(&[]) {
                        if !slots.contains(&j) {
                            slots.push(j);
                            next.push(j);
                        }
                    }
                }
            }
            frontier = next;
        }
        let mut sorted = slots.clone();
        sorted.sort_unstable();
        let mut cuts: Vec<usize> = Vec::new();
        let mut key = vec![slots.len() as u64];
        for &s in &slots {
            key.push(sorted.binary_search(&s).unwrap_or(usize::MAX) as u64);
            let Some(r) = slot[s].as_ref() else {
                key.push(u64::MAX);
                continue;
            };
            r.push_key(&mut key, |c, key| {
                let canon = match cuts.iter().position(|&x| x == c) {
                    Some(i) => i,
                    None => {
                        cuts.push(c);
                        cuts.len() - 1
                    }
                };
                let live = alive.get(c).copied().unwrap_or(false);
                key.extend([1, canon as u64, (c < protected) as u64, live as u64]);
            });
        }
        Self { slots, cuts, key }
    }
}

/// Where a re-split applies: the block alone, its union with the neighbour in slot
/// `j` across cut `c`, or its union with two neighbours (`j` across `c`, then `j2` across `c2`,
/// a neighbour of the block or of `j`).
#[derive(Clone, Copy)]
pub(super) enum Host {
    Alone,
    Merged {
        j: usize,
        c: usize,
    },
    Merged2 {
        j: usize,
        c: usize,
        j2: usize,
        c2: usize,
    },
}

impl Host {
    /// The slots of the blocks the host unites (block `k` first) and the cuts between them.
    fn parts(self, k: usize) -> (Vec<usize>, Vec<usize>) {
        match self {
            Host::Alone => (vec![k], vec![]),
            Host::Merged { j, c } => (vec![k, j], vec![c]),
            Host::Merged2 { j, c, j2, c2 } => (vec![k, j, j2], vec![c, c2]),
        }
    }
}

impl Builder<'_> {
    /// The best merge of block slot `k` with a neighbour across one live, unprotected cut
    /// (the two blocks share exactly that cut's endpoints): the union alone if `accept` takes
    /// it, else the best split of the union by `accept`. Returns (score, neighbour slot, cut,
    /// split or `None` for the union alone, union).
    /// `good_only` as in [`Builder::best_split_by`].
    pub(super) fn best_merge(
        &self,
        slot: &[Option<Ring>],
        k: usize,
        alive: &[bool],
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
    ) -> Option<Merge> {
        let mut best: Option<Merge> = None;
        let r = slot[k].as_ref()?;
        let unions = self.neighbour_unions(slot, r, &[k], alive);
        // the unions are searched in parallel and compared in order (the searches are pure)
        let options: Vec<Option<(f64, Option<Split>)>> = unions
            .par_iter()
            .map(|(_, _, u)| match accept(u) {
                Some(cost) => Some((cost, None)),
                None => self
                    .best_split_by(u, accept, good_only, None)
                    .map(|s| (s.0, Some(s))),
            })
            .collect();
        for ((j, c, u), option) in unions.into_iter().zip(options) {
            if let Some((s, split)) = option {
                if beats(
                    s,
                    ring_key(&u),
                    best.as_ref().map(|b| (b.0, ring_key(&b.4))),
                ) {
                    best = Some((s, j, c, split, u));
                }
            }
        }
        best
    }

    /// The unions of ring `r` (a block, or a union of the blocks in slots `exclude`) with each
    /// other block across one live, unprotected cut (the two share exactly that cut's
    /// endpoints), as (neighbour slot, cut, union); degenerate or clockwise unions are left out.
    fn neighbour_unions(
        &self,
        slot: &[Option<Ring>],
        r: &Ring,
        exclude: &[usize],
        alive: &[bool],
    ) -> Vec<(usize, usize, Ring)> {
        let mut out = Vec::new();
        for (e, t) in r.tags.iter().enumerate() {
            let Tag::Cut(c) = *t else { continue };
            if c < self.protected_cuts || !alive.get(c).copied().unwrap_or(false) {
                continue;
            }
            let Some((j, f)) = slot.iter().enumerate().find_map(|(j, o)| {
                let o = o.as_ref()?;
                if exclude.contains(&j) {
                    return None;
                }
                o.tags
                    .iter()
                    .position(|x| *x == Tag::Cut(c))
                    .map(|f| (j, f))
            }) else {
                continue;
            };
            let Some(other) = slot[j].as_ref() else {
                continue;
            };
            if r.pts.iter().filter(|p| other.pts.contains(p)).count() != 2 {
                continue;
            }
            let Some(u) = union_ring(r, e, other, f) else {
                continue;
            };
            if crate::geom::signed_area(&u.pts) > 0.0 {
                out.push((j, c, u));
            }
        }
        out
    }

    /// Step 3 of the repair: the best re-split into good blocks of block slot `k` alone, of
    /// its union with one neighbour (both by two cuts into three blocks,
    /// [`Builder::best_split3`]), or of its union with two neighbours (by two cuts into three
    /// blocks, or by one cut into two). The lowest score wins, ties broken by the coordinates
    /// of the first child's vertices.
    pub(super) fn best_resplit(
        &self,
        slot: &[Option<Ring>],
        k: usize,
        alive: &[bool],
    ) -> Option<(Host, Resplit)> {
        let r = slot[k].as_ref()?;
        let mut hosts = vec![(Host::Alone, r.clone())];
        let mut hosts2 = Vec::new();
        let mut pairs = Vec::new();
        for (j, c, u) in self.neighbour_unions(slot, r, &[k], alive) {
            for (j2, c2, u2) in self.neighbour_unions(slot, &u, &[k, j], alive) {
                if !pairs.contains(&(j2.min(j), j2.max(j))) {
                    pairs.push((j2.min(j), j2.max(j)));
                    hosts2.push((Host::Merged2 { j, c, j2, c2 }, u2));
                }
            }
            hosts.push((Host::Merged { j, c }, u));
        }
        let memo = FitMemo::default();
        // the candidates of one host, in the order the search yields them: the split of a
        // union with two neighbours by one cut, then the split by two cuts
        let candidates = |(host, u): &(Host, Ring)| -> Vec<Resplit> {
            // a good neighbour may not come out with a worse corner score than RESPLIT_SLACK
            // above the worst good block it replaces (gulf-of-mexico: the repair of a small
            // block re-cornered the 39-vertex central basin, F 0.13 → 0.20, whose transfinite
            // grid then folded over more area than it covered)
            let limit = host
                .parts(k)
                .0
                .iter()
                .filter_map(|&s| slot[s].as_ref().and_then(|r| memo.good_fit(self, r)))
                .map(|f| f + RESPLIT_SLACK)
                .fold(f64::NEG_INFINITY, f64::max);
            let limit = if limit == f64::NEG_INFINITY {
                f64::INFINITY
            } else {
                limit
            };
            let is_two = matches!(host, Host::Merged2 { .. });
            // the same host searched before (in an earlier sweep or layout): its candidates
            // (exact, `host_key`)
            let cache = self.cache.as_ref().map(|c| &c.repair);
            let (key, ids) = host_key(u, limit, is_two);
            let hit = cache.and_then(|c| c.lock().ok()?.hosts.get(&key).cloned());
            if let Some(found) = hit.and_then(|f| relabel_resplits(&f, &|c| ids.get(c).copied())) {
                return found;
            }
            let good = |u: &Ring| memo.good_fit(self, u).filter(|&f| f <= limit);
            let angles = CutTable::new(&u.pts, *self.tier1_screen());
            let two = is_two
                .then(|| self.best_split_by(u, &good, true, Some(&angles)))
                .flatten()
                .map(|(s, a, b, ends)| (s, vec![as_first_cut(a), as_first_cut(b)], vec![ends]));
            let found: Vec<Resplit> = two
                .into_iter()
                .chain(self.best_split3(u, &good, true, &angles))
                .collect();
            let canon = relabel_resplits(&found, &|c| ids.iter().position(|&x| x == c));
            if let (Some(cache), Some(canon)) = (cache, canon) {
                if let Ok(mut c) = cache.lock() {
                    c.hosts.insert(key, canon);
                }
            }
            found
        };
        // the lowest score wins, candidates compared in host order (as a sequential loop
        // over the hosts would: the searches are pure, the memo only saves work)
        let fold = |best: &mut Option<(Host, Resplit)>, host: Host, found: Vec<Resplit>| {
            for s in found {
                if beats(
                    s.0,
                    ring_key(&s.1[0]),
                    best.as_ref().map(|(_, b)| (b.0, ring_key(&b.1[0]))),
                ) {
                    *best = Some((host, s));
                }
            }
        };
        let mut best: Option<(Host, Resplit)> = None;
        let found: Vec<Vec<Resplit>> = hosts.par_iter().map(candidates).collect();
        for ((host, _), f) in hosts.iter().zip(found) {
            fold(&mut best, *host, f);
        }
        // the fewest blocks disturbed: two neighbours only when no re-split of the block
        // alone or with one neighbour works, and then the first of those that works (the
        // sequential loop stops at the next one once it has a candidate; searched in
        // parallel, the later ones are given up once an earlier one has candidates)
        if best.is_none() {
            let first = hosts2
                .par_iter()
                .map(|h| (h.0, candidates(h)))
                .find_first(|(_, found)| !found.is_empty());
            if let Some((host, found)) = first {
                fold(&mut best, host, found);
            }
        }
        best
    }

    /// Applies a re-split found by [`Builder::best_resplit`]: the merged cuts die, the children
    /// take the slots of the host's blocks in order (block `k` first), a third child of fewer
    /// host blocks gets a new slot and a leaf in the tree, a host block left without a child
    /// is merged into `k`.
    pub(super) fn apply_resplit(
        &mut self,
        slot: &mut Vec<Option<Ring>>,
        owner: &mut Vec<usize>,
        alive: &mut Vec<bool>,
        k: usize,
        (host, (_, children, ends)): (Host, Resplit),
    ) {
        let (children, ids) = self.commit_resplit(children, &ends);
        alive.extend(ids.iter().map(|_| true));
        let (mut slots, merged) = host.parts(k);
        for c in merged {
            alive[c] = false;
        }
        let n = children.len();
        for (i, child) in children.into_iter().enumerate() {
            if i < slots.len() {
                slot[slots[i]] = Some(child);
            } else {
                slot.push(Some(child));
                let m = slot.len() - 1;
                owner.push(m);
                self.branch_leaf(slots[i - 1], m, ids[i - 1]);
                slots.push(m);
            }
        }
        for &s in &slots[n..] {
            slot[s] = None;
            owner[s] = k;
        }
    }

    /// Applies a merge found by [`Builder::best_merge`] to slots `k` and `j`.
    pub(super) fn apply_merge(
        &mut self,
        slot: &mut [Option<Ring>],
        owner: &mut [usize],
        alive: &mut Vec<bool>,
        k: usize,
        m: Merge,
    ) {
        let (_, j, c, split, u) = m;
        alive[c] = false;
        match split {
            None => {
                slot[k] = Some(u);
                slot[j] = None;
                owner[j] = k;
            }
            Some((_, a, b, ends)) => {
                let (a, b, _) = self.commit_split(a, b, ends);
                alive.push(true);
                slot[k] = Some(a);
                slot[j] = Some(b);
            }
        }
    }
}
