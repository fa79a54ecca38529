//! Ready-made decompositions: the thesis' Example 5.1 topology and generated grid decompositions for tests
//! and benchmarks.

use crate::problem::{Block, CompatProblem, Curve, CutPair};

/// The Fig 5.1 / Example 5.1 topology of [Méndez 2023, §5.2.2] (3 blocks, 2 cuts, 17 curves), with curve
/// ids 1..17 and the block-3 numbering printed in the example, which does not follow the b, r, t, l order
/// of the thesis's index sets `J_{k,side}` (§5.2.1): bottom `Q14`, right `Q13`, top `Q16, Q17`,
/// left `Q15`. Cut 1 is `(ι, ς) = (Q11, Q2)`, cut 2 is `(Q17, Q7)`, so the cut rows read `m11 − m2 = 0` and
/// `m17 − m7 = 0` (the thesis prints them negated).
///
/// The thesis gives no coordinates. The lengths are invented to be consistent with its `d = 1` solution:
/// `ℓ_16 = 1` is the shortest curve and every other curve has `ℓ_j = m_j − ½` where `m_j` is the thesis
/// count, so that `⌈ℓ_j/ℓ_min⌉ = m_j`; both copies of each cut have equal length.
pub fn thesis_example_5_1() -> CompatProblem {
    // thesis counts for d = 1 (used only to invent consistent lengths)
    let m = [6, 6, 6, 6, 8, 6, 6, 6, 8, 8, 6, 4, 8, 8, 8, 3, 6];
    let curves = m
        .iter()
        .enumerate()
        .map(|(j, &mj)| {
            let id = j + 1;
            let length = if id == 16 { 1.0 } else { mj as f64 - 0.5 };
            let c = Curve::new(id, length);
            match id {
                2 | 11 => c.with_label("cut 1 copy"),
                7 | 17 => c.with_label("cut 2 copy"),
                _ => c,
            }
        })
        .collect();
    // indices are ids − 1
    let blocks = vec![
        Block::new(1, vec![0], vec![1], vec![2], vec![3]),
        Block::new(2, vec![4], vec![5, 6, 7], vec![8], vec![9, 10, 11]),
        Block::new(3, vec![13], vec![12], vec![15, 16], vec![14]),
    ];
    let cuts = vec![CutPair::new(10, 1), CutPair::new(16, 6)];
    CompatProblem::new(curves, blocks, cuts)
}

/// Deterministic pseudo-random numbers (SplitMix64), so fixtures need no RNG dependency.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// Uniform integer in `lo..=hi`.
    pub fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next_u64() % (hi - lo + 1) as u64) as usize
    }
}

/// A `rows × cols` array of blocks. Neighbouring blocks share a cut (two copies, equal length); sides on the
/// outer boundary are split into 1–3 boundary curves with random lengths in `[0.5, 4)`. Row `r` and column
/// `c` give block id `r·cols + c + 1`. The system is always feasible and network-orientable.
pub fn grid_decomposition(rows: usize, cols: usize, seed: u64) -> CompatProblem {
    let mut rng = SplitMix64::new(seed);
    let mut curves: Vec<Curve> = Vec::new();
    let new_curve = |curves: &mut Vec<Curve>, length: f64| {
        curves.push(Curve::new(curves.len() + 1, length));
        curves.len() - 1
    };
    // cut lengths: horizontal cuts (between (r,c) and (r+1,c)) and vertical ones
    let mut hcut = vec![vec![0.0; cols]; rows.saturating_sub(1)];
    for row in hcut.iter_mut() {
        for v in row.iter_mut() {
            *v = rng.uniform(1.0, 5.0);
        }
    }
    let mut vcut = vec![vec![0.0; cols.saturating_sub(1)]; rows];
    for row in vcut.iter_mut() {
        for v in row.iter_mut() {
            *v = rng.uniform(1.0, 5.0);
        }
    }
    // indices of cut copies: top copy of (r,c) and bottom copy of (r+1,c); right of (r,c), left of (r,c+1)
    let mut top_copy = vec![vec![usize::MAX; cols]; rows];
    let mut bottom_copy = vec![vec![usize::MAX; cols]; rows];
    let mut right_copy = vec![vec![usize::MAX; cols]; rows];
    let mut left_copy = vec![vec![usize::MAX; cols]; rows];
    let mut cuts = Vec::new();
    for r in 0..rows.saturating_sub(1) {
        for c in 0..cols {
            let a = new_curve(&mut curves, hcut[r][c]);
            let b = new_curve(&mut curves, hcut[r][c]);
            top_copy[r][c] = a;
            bottom_copy[r + 1][c] = b;
            cuts.push(CutPair::new(a, b));
        }
    }
    for r in 0..rows {
        for c in 0..cols.saturating_sub(1) {
            let a = new_curve(&mut curves, vcut[r][c]);
            let b = new_curve(&mut curves, vcut[r][c]);
            right_copy[r][c] = a;
            left_copy[r][c + 1] = b;
            cuts.push(CutPair::new(a, b));
        }
    }
    let mut blocks = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            let side = |copy: usize, curves: &mut Vec<Curve>, rng: &mut SplitMix64| {
                if copy != usize::MAX {
                    vec![copy]
                } else {
                    let k = rng.range(1, 3);
                    (0..k)
                        .map(|_| {
                            let l = rng.uniform(0.5, 4.0);
                            new_curve(curves, l)
                        })
                        .collect()
                }
            };
            let b = side(bottom_copy[r][c], &mut curves, &mut rng);
            let rt = side(right_copy[r][c], &mut curves, &mut rng);
            let t = side(top_copy[r][c], &mut curves, &mut rng);
            let l = side(left_copy[r][c], &mut curves, &mut rng);
            blocks.push(Block::new(r * cols + c + 1, b, rt, t, l));
        }
    }
    CompatProblem::new(curves, blocks, cuts)
}
