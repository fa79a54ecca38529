//! Random small decompositions shared by the property tests (`properties.rs`, `fit.rs`).

use unamalla_compat_ilp::{Block, CompatProblem, Curve, CutPair};

/// A small decomposition from raw random choices: `nblocks` blocks whose sides have one curve
/// each, two for the sides listed in `doubled` (`4·block + side`), curve `j` of length
/// `lengths[j]` pinned to `pins[j]` (if given; missing entries unpinned), and cut pairs from
/// `cut_picks` (taken modulo the curve count; pairs reusing a curve are skipped).
pub fn build(
    nblocks: usize,
    doubled: &[usize],
    lengths: &[f64],
    cut_picks: &[(usize, usize)],
    pins: &[Option<usize>],
) -> CompatProblem {
    let mut next = 0usize;
    let mut blocks = Vec::new();
    for k in 0..nblocks {
        let mut sides: [Vec<usize>; 4] = Default::default();
        for (s, side) in sides.iter_mut().enumerate() {
            let n = if doubled.contains(&(4 * k + s)) { 2 } else { 1 };
            *side = (next..next + n).collect();
            next += n;
        }
        blocks.push(Block { id: k + 1, sides });
    }
    let p = next;
    let curves: Vec<Curve> = (0..p)
        .map(|j| Curve {
            id: j + 1,
            length: lengths[j],
            pinned: pins.get(j).copied().flatten(),
            label: None,
        })
        .collect();
    let mut used = vec![false; p];
    let mut cuts = Vec::new();
    for &(a, b) in cut_picks {
        let (a, b) = (a % p, b % p);
        if a != b && !used[a] && !used[b] {
            used[a] = true;
            used[b] = true;
            cuts.push(CutPair::new(a, b));
        }
    }
    CompatProblem::new(curves, blocks, cuts)
}
