//! The cleanup (merge) pass: two blocks sharing one cut are merged when their union is
//! approximately convex and its corners are no worse (crate documentation).

use super::cache::MergeMemo;
use super::Builder;
use crate::piece::{Ring, Tag};

impl Builder<'_> {
    /// The cleanup pass: removes every cut whose two blocks form a better block together.
    /// Two blocks sharing exactly one cut (and no other point) are merged when the union is
    /// approximately convex, has no critical angle and its corner score is not worse than the
    /// worse of the two (`F*(A ∪ B) ≤ max(F*(A), F*(B)) + 0.02`). Candidates are applied in
    /// order of gain, each block at most once per pass, until a pass merges nothing. Removed
    /// cuts are dropped and the remaining cuts renumbered; leaf nodes of the tree point to the
    /// merged block.
    pub(super) fn merge_pass(&mut self, rings: Vec<Ring>) -> Vec<Ring> {
        // the tests of blocks and unions, shared with the other layouts of the region (or
        // kept for this pass's rounds)
        let cache = self.cache.clone();
        let local = MergeMemo::default();
        let memo = cache.as_deref().map_or(&local, |c| &c.merges);
        let mut slot: Vec<Option<Ring>> = rings.into_iter().map(Some).collect();
        let mut owner: Vec<usize> = (0..slot.len()).collect(); // union-find over slots
        let mut fit: Vec<f64> = slot
            .iter()
            .map(|r| r.as_ref().map_or(0.0, |r| memo.fit(&r.pts)))
            .collect();
        let mut alive_cut = vec![true; self.cuts.len()];
        loop {
            // cut → (slot, edge) uses
            let mut uses: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.cuts.len()];
            for (k, r) in slot.iter().enumerate() {
                if let Some(r) = r {
                    for (e, t) in r.tags.iter().enumerate() {
                        if let Tag::Cut(c) = t {
                            uses[*c].push((k, e));
                        }
                    }
                }
            }
            let mut cands: Vec<(f64, usize, Ring)> = Vec::new();
            for (c, u) in uses.iter().enumerate() {
                if c < self.protected_cuts || u.len() != 2 || u[0].0 == u[1].0 {
                    continue;
                }
                let ((ka, ea), (kb, eb)) = (u[0], u[1]);
                let (Some(a), Some(b)) = (&slot[ka], &slot[kb]) else {
                    continue;
                };
                // exactly one shared cut and no other shared point; the union approximately
                // convex and without a critical angle
                let Some(f) = memo.union_fit(&self.opts.tolerances, a, ea, b, eb) else {
                    continue;
                };
                let worst = fit[ka].max(fit[kb]);
                // a triangle bounded by cuts only could get its fourth corner only inside a cut
                // (a valence-3 interior node): merge it whenever the union is admissible
                let cut_triangle =
                    |r: &Ring| r.len() == 3 && r.tags.iter().all(|t| matches!(t, Tag::Cut(_)));
                if f <= worst + 0.02 || cut_triangle(a) || cut_triangle(b) {
                    if let Some(u) = crate::builder::repair::union_ring(a, ea, b, eb) {
                        cands.push((worst - f, c, u));
                    }
                }
            }
            if cands.is_empty() {
                break;
            }
            cands.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
            let mut touched = vec![false; slot.len()];
            let mut merged = false;
            for (_, c, ring) in cands {
                let u = &uses[c];
                let (ka, kb) = (u[0].0, u[1].0);
                if touched[ka] || touched[kb] {
                    continue;
                }
                touched[ka] = true;
                touched[kb] = true;
                fit[ka] = memo.fit(&ring.pts);
                slot[ka] = Some(ring);
                slot[kb] = None;
                owner[kb] = ka;
                alive_cut[c] = false;
                merged = true;
            }
            if !merged {
                break;
            }
        }
        self.renumber(slot, owner, alive_cut)
    }
}
