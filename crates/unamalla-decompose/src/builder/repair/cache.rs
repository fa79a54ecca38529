//! The repair attempts that the layouts of one region share ([`RepairCache`]), keyed by
//! their host ring up to cut ids, and the corner-score memo of one repair pass.

use unamalla_mesh::DVec2;

use super::merge::Host;
use super::{Merge, Resplit, Split, TMP_CUT, TMP_CUT2};
use crate::builder::Builder;
use crate::piece::{Ring, Tag};

/// What one repair attempt of a block found (steps 1–3 of [`Builder::repair_pass`]).
#[derive(Clone)]
pub(super) enum Attempt {
    /// Step 1: a split of the block alone.
    Split(Split),
    /// Step 2: a merge with a neighbour (possibly re-split).
    Merge(Merge),
    /// Step 3: a re-split of the block or of a union with neighbours.
    Resplit(Host, Resplit),
    /// Nothing found.
    Fail,
}

/// Whether cut id `c` is one of the placeholders of a candidate ([`TMP_CUT`], [`TMP_CUT2`]).
pub(super) fn placeholder(c: usize) -> bool {
    c == TMP_CUT || c == TMP_CUT2
}

/// `r` with every cut id `c` (placeholders excepted) replaced by `cut(c)`; `None` if `cut`
/// has no image for one of them.
fn relabel_ring(r: &Ring, cut: &dyn Fn(usize) -> Option<usize>) -> Option<Ring> {
    let tags = r
        .tags
        .iter()
        .map(|t| match *t {
            Tag::Cut(c) if !placeholder(c) => cut(c).map(Tag::Cut),
            t => Some(t),
        })
        .collect::<Option<Vec<Tag>>>()?;
    Some(Ring {
        pts: r.pts.clone(),
        tags,
    })
}

/// [`relabel_ring`] for both children of a [`Split`].
fn relabel_split(s: &Split, cut: &dyn Fn(usize) -> Option<usize>) -> Option<Split> {
    Some((s.0, relabel_ring(&s.1, cut)?, relabel_ring(&s.2, cut)?, s.3))
}

impl Attempt {
    /// The attempt with slot numbers mapped by `slot` and cut ids by `cut` (placeholders
    /// kept); `None` if a map has no image for one of them.
    pub(super) fn relabel(
        &self,
        slot: &dyn Fn(usize) -> Option<usize>,
        cut: &dyn Fn(usize) -> Option<usize>,
    ) -> Option<Attempt> {
        Some(match self {
            Attempt::Split(s) => Attempt::Split(relabel_split(s, cut)?),
            Attempt::Merge((s, j, c, split, u)) => Attempt::Merge((
                *s,
                slot(*j)?,
                cut(*c)?,
                match split {
                    Some(x) => Some(relabel_split(x, cut)?),
                    None => None,
                },
                relabel_ring(u, cut)?,
            )),
            Attempt::Resplit(host, (s, rings, ends)) => {
                let host = match *host {
                    Host::Alone => Host::Alone,
                    Host::Merged { j, c } => Host::Merged {
                        j: slot(j)?,
                        c: cut(c)?,
                    },
                    Host::Merged2 { j, c, j2, c2 } => Host::Merged2 {
                        j: slot(j)?,
                        c: cut(c)?,
                        j2: slot(j2)?,
                        c2: cut(c2)?,
                    },
                };
                let rings = rings
                    .iter()
                    .map(|r| relabel_ring(r, cut))
                    .collect::<Option<Vec<Ring>>>()?;
                Attempt::Resplit(host, (*s, rings, ends.clone()))
            }
            Attempt::Fail => Attempt::Fail,
        })
    }
}

/// Repair attempts of earlier passes over the same region with the same options (the
/// rebuilds of [`crate::auto::chord_layout_cuts`] repair mostly the same blocks again), keyed
/// by [`Neighbourhood::key`](super::merge::Neighbourhood), with slot numbers and cut ids in the key's canonical numbering.
#[derive(Default)]
pub(crate) struct RepairCache {
    pub(super) attempts: std::collections::HashMap<Vec<u64>, Attempt>,
    /// The candidates of a re-split host ([`Builder::best_resplit`]), keyed by
    /// [`host_key`], the rings' cut ids numbered as in the key.
    pub(super) hosts: std::collections::HashMap<Vec<u64>, Vec<Resplit>>,
}

/// The key of a re-split host's search: the host ring (points, per edge the region ring or
/// the cut numbered in the order the cuts first appear), the corner-score limit's bits and
/// whether the one-cut split is searched too (a union with two neighbours); and the cut ids
/// in that order.
///
/// The search ([`Builder::best_resplit`]'s `candidates`) reads only these — the points and
/// whether an edge is region boundary or cut, never a cut's id except to copy it to the
/// children — and the options and minimum area, the same for every builder sharing the
/// cache: an equal key means the same search up to the cut ids.
pub(super) fn host_key(u: &Ring, limit: f64, two: bool) -> (Vec<u64>, Vec<usize>) {
    let mut key = Vec::new();
    let mut ids: Vec<usize> = Vec::new();
    u.push_key(&mut key, |c, key| {
        let k = ids.iter().position(|&x| x == c).unwrap_or_else(|| {
            ids.push(c);
            ids.len() - 1
        });
        key.extend([1, k as u64]);
    });
    key.extend([limit.to_bits(), two as u64]);
    (key, ids)
}

/// `found` with the rings' cut ids mapped by `cut` (placeholders kept); `None` if one has no
/// image.
pub(super) fn relabel_resplits(
    found: &[Resplit],
    cut: &dyn Fn(usize) -> Option<usize>,
) -> Option<Vec<Resplit>> {
    found
        .iter()
        .map(|(s, rings, ends)| {
            let rings = rings
                .iter()
                .map(|r| relabel_ring(r, cut))
                .collect::<Option<Vec<Ring>>>()?;
            Some((*s, rings, ends.clone()))
        })
        .collect()
}

/// A memo of [`Builder::good_fit`] by exact vertex sequence, for one re-split search
/// ([`Builder::best_resplit`]): its two-cut searches meet the same child rings many times
/// (a block cut by X then Y has the pieces of the block cut by Y then X, and the second-cut
/// searches of different first cuts share most of their children). Exact: `good_fit` is a
/// function of the vertex sequence alone (the builder's options and minimum area are fixed),
/// and entries are matched on the full sequence, bit for bit.
#[derive(Default)]
pub(super) struct FitMemo(std::sync::Mutex<std::collections::HashMap<u64, Vec<FitEntry>>>);

/// An entry of a [`FitMemo`]: a vertex sequence and its `good_fit`.
type FitEntry = (Box<[DVec2]>, Option<f64>);

impl FitMemo {
    /// `b.good_fit(ring)`, computed once per vertex sequence.
    pub(super) fn good_fit(&self, b: &Builder<'_>, ring: &Ring) -> Option<f64> {
        let same = |p: &[DVec2]| {
            p.len() == ring.pts.len()
                && p.iter()
                    .zip(&ring.pts)
                    .all(|(a, b)| a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits())
        };
        // the bucket: a quick hash of the coordinates' bits (FxHash's multiply and rotate;
        // the entries in a bucket are told apart by the full sequence)
        const K: u64 = 0x517c_c1b7_2722_0a95;
        let mix = |h: u64, x: f64| (h.rotate_left(5) ^ x.to_bits()).wrapping_mul(K);
        let h = ring.pts.iter().fold(0u64, |h, p| mix(mix(h, p.x), p.y));
        if let Ok(m) = self.0.lock() {
            if let Some(f) = m.get(&h).and_then(|v| v.iter().find(|e| same(&e.0))) {
                return f.1;
            }
        }
        let f = b.good_fit(ring);
        if let Ok(mut m) = self.0.lock() {
            m.entry(h)
                .or_default()
                .push((ring.pts.clone().into_boxed_slice(), f));
        }
        f
    }
}
