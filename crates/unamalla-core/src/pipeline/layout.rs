//! Choosing the block layout by predicted quality ([`choose_layout`]) and re-splitting
//! the blocks predicted worst.

use super::*;

/// At most this many other candidate layouts are tried after the automatically chosen one
/// left non-convex cells or cells outside the region ([`Mesher::mesh_observed`]); each try is
/// a whole run of the pipeline, so the work is bounded by `1 + LAYOUT_FALLBACKS` runs.
pub const LAYOUT_FALLBACKS: usize = 2;

/// Default of [`Mesher::quality_target`]: μ ≥ 0.8 on 90 % of the cells, the acceptance level
/// of the project's region tables (and of `unamalla mesh --strict`).
pub const QUALITY_TARGET_PERCENT: f64 = 90.0;

/// At most this many other candidate layouts are tried after the automatically chosen one
/// passed the guarantee below [`Mesher::quality_target`]; with [`LAYOUT_FALLBACKS`] the work
/// is bounded by `1 + LAYOUT_FALLBACKS + QUALITY_FALLBACKS` runs of the pipeline.
pub const QUALITY_FALLBACKS: usize = 2;

/// Further runs of the narrow-hole retry of [`Mesher::mesh_observed`] after the one without
/// the holes narrower than a cell: each also leaves out the holes narrower than
/// [`NEAR_HOLE_WIDTH`] cell sizes within a cell size of a failing cell. Each round is a run
/// with its layout fallbacks, so the retry is bounded by
/// `(1 + NEAR_HOLE_ROUNDS)·(1 + LAYOUT_FALLBACKS)` runs.
pub const NEAR_HOLE_ROUNDS: usize = 2;

/// The width, in cell sizes, below which a hole next to a failing cell may be left out by
/// the later rounds of the narrow-hole retry ([`NEAR_HOLE_ROUNDS`]): an island less than two
/// cells across has at most one row of cells along each side of its blocks, the case the
/// untangling could not open (measured on the synthetic archipelago of 500 islands at 20,000
/// cells, docs/results.md).
pub const NEAR_HOLE_WIDTH: f64 = 2.0;

/// The widest hole, in cell sizes, the pipeline carves out of the mesh ([`crate::carve`])
/// instead of bridging it with cuts. The narrow-hole retry and the carving retry of
/// [`Mesher::mesh_observed`] first leave the holes narrower than [`NEAR_HOLE_WIDTH`] cell sizes
/// out of the layout; when the block decomposition still finds no admissible cuts around the
/// rest, or (the quality retry) the mesh bridging the rest stays below the one it would
/// replace (a sea of islands two to three cells across), the width doubles up to this one. A
/// carved hole is a rectangle of cells whose ring of nodes moves onto the island's contour; up
/// to four cells across its corner cells still keep convex angles near 135° around a round
/// island, while larger islands get blocks of their own.
pub const CARVE_MAX_WIDTH: f64 = 4.0;

/// Margin (share of cells) by which the chord layout's prediction must beat the concavity
/// layout's to be chosen: the prediction is made on a coarse mesh with a few Laplacian sweeps,
/// so differences below a percent are not resolved by it (`tests/predictor.rs`).
pub const LAYOUT_MARGIN: f64 = 0.01;

/// The chord layouts [`choose_layout`] tries: aspect thresholds T of the transverse cuts
/// (`unamalla_decompose::chords`). Measured with the predictor on the 34 development regions
/// at 20,000 cells (`layout_eval --predict-only --aspect T`): mean predicted μ ≥ 0.8 share of
/// the chord layout alone 86.9 % (T = 0.35), 84.0 % (0.75), 82.8 % (1.5), 81.9 % (2), 81.0 %
/// (3), against 83.0 % for the concavity layout; no single T is best on every region, the best
/// of the three per region averages 89.4 %.
pub const LAYOUT_ASPECTS: [(&str, f64); 3] = [
    ("chords-0.35", 0.35),
    ("chords-0.75", 0.75),
    ("chords-1.5", 1.5),
];

/// Predicted-quality re-split: at most this many candidate cuts are tried
/// ([`choose_layout`]).
pub const RESPLIT_EVALS: usize = 8;
/// Layouts with more blocks than this are not re-split: every candidate rebuilds and predicts
/// the whole layout (work linear in the blocks), so the re-split's work is bounded by
/// `RESPLIT_EVALS` rebuilds of a layout of at most this size.
pub const RESPLIT_MAX_BLOCKS: usize = 150;
/// A block is a re-split candidate while its predicted μ ≥ 0.8 share is below this.
pub const RESPLIT_BELOW: f64 = 0.9;
/// Smallest chord score `min(A₁, A₂)/w²` of a re-split cut: the smaller part extends at
/// least half a chord width beyond it (a half disc at its base scores π/8 ≈ 0.39, so a cape
/// is not cut off).
pub const RESPLIT_SCORE: f64 = 0.5;
/// A re-split cut leaves at least this many cells of the requested size on its smaller side
/// (a cut off a smaller feature cannot change the mesh beyond its few cells).
pub const RESPLIT_CELLS: f64 = 16.0;
/// A re-split cut is kept when it raises the predicted share of the whole mesh by at least
/// this much (a fifth of a percentage point; the prediction resolves differences of that
/// order between layouts that differ in one block).
pub const RESPLIT_GAIN: f64 = 0.002;

/// Which layout [`Mesher`] chose, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayoutChoice {
    /// `"concavity"` or `"chords-T"` (T the aspect threshold, [`LAYOUT_ASPECTS`]).
    pub layout: String,
    /// Predicted μ ≥ 0.8 percentage of the chosen layout.
    pub predicted_percent: f64,
    /// Predicted μ ≥ 0.8 percentage of every candidate (`(layout, percent)`; a candidate that
    /// could not be built or predicted is absent).
    pub candidates: Vec<(String, f64)>,
    /// Predicted μ ≥ 0.8 share per block of the chosen layout.
    pub blocks: Vec<f64>,
    /// Cuts added to the chosen layout by the predicted-quality re-split (each raised the
    /// predicted share by at least [`RESPLIT_GAIN`]).
    pub resplit_cuts: usize,
    /// Candidate cuts the re-split evaluated (at most [`RESPLIT_EVALS`]).
    pub resplit_tried: usize,
}

/// Rule breaks of a layout: interior singularities of its coarse mesh (cut joints, which the
/// triangle-block rule makes when it must split a cut) plus blocks that are not admissible.
fn rule_breaks(
    d: &Decomposition,
    p: &crate::predict::Prediction,
    opts: &DecomposeOptions,
) -> usize {
    let bad: Vec<usize> = (0..d.blocks.len())
        .filter(|&b| !d.block_admissible(b, &opts.tolerances))
        .collect();
    if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
        for &b in &bad {
            let blk = &d.blocks[b];
            let c = unamalla_decompose::concavity(&blk.ring);
            let crit = unamalla_decompose::critical_angles(&blk.ring, opts.tolerances.theta_minus);
            eprintln!(
                "  inadmissible block {b}: {} vertices, area {:.4e}, triangle {}, convex {}, kappa {:.3} {:.3} {:.3} {:.3}, critical {:?} at {:?}",
                blk.ring.len(),
                blk.area(),
                blk.triangle,
                c.approximately_convex(&opts.tolerances),
                c.kappa1, c.kappa2, c.kappa3, c.kappa4,
                crit,
                blk.ring.first()
            );
        }
    }
    p.singularities + bad.len()
}

/// Builds the concavity layout and the chord layouts of [`LAYOUT_ASPECTS`] of `region` and
/// keeps the one with the highest predicted μ ≥ 0.8 share ([`crate::predict::predict_mesh`]):
/// a layout whose coarse mesh has fewer interior singularities always wins; then the predicted
/// share decides (the concavity layout wins ties within [`LAYOUT_MARGIN`]), then fewer
/// non-admissible blocks, then fewer blocks. (Until 2026-12-06 non-admissible blocks counted
/// with the singularities, before the prediction; measured on the 34 development regions:
/// docs/results.md, "Seventh pass".)
///
/// The chosen layout is then **re-split by the prediction**: the block with the most
/// predicted bad cells (`(1 − share)·cells`, share below [`RESPLIT_BELOW`]) that has a chord
/// of score ≥ [`RESPLIT_SCORE`] between boundary points or layout cuts
/// ([`unamalla_decompose::split_chord`]) gets it as one more layout cut; the layout is rebuilt
/// ([`unamalla_decompose::layout_from_cuts`]) and predicted again, and the cut is kept when the
/// predicted share rises by at least [`RESPLIT_GAIN`] without more rule breaks. At most
/// [`RESPLIT_EVALS`] candidates are tried, on layouts of at most [`RESPLIT_MAX_BLOCKS`]
/// blocks, so the work is bounded. For a chord layout the layout cuts are its chords; for the
/// concavity layout they are its own cuts in the order Algorithm 1 made them. (Until the fifth
/// session of 2026-12-06 only chord layouts were re-split: the concavity layout of the crow
/// kept its body — back and belly converging towards the tail — in one block predicted at
/// 67 %, whose smoothed cells showed diagonal bands of shear; one transverse cut raised the
/// mesh from 94.7 to 98.9 % at 20,000 cells. Measured on the 34 regions: docs/results.md,
/// "The concavity layout re-split too".)
pub fn choose_layout(
    region: &Region,
    opts: &DecomposeOptions,
    size: MeshSize,
) -> Result<(Decomposition, LayoutChoice), CoreError> {
    choose_layout_excluding(region, opts, size, &[])
}

/// [`choose_layout`] without the candidates named in `excluded` (the names of
/// [`LayoutChoice::layout`]: `concavity` and those of [`LAYOUT_ASPECTS`]); when every
/// candidate is excluded, the same error as when none can be built.
pub fn choose_layout_excluding(
    region: &Region,
    opts: &DecomposeOptions,
    size: MeshSize,
    excluded: &[String],
) -> Result<(Decomposition, LayoutChoice), CoreError> {
    // (name, layout cuts for a chord layout, decomposition)
    type Cand = (&'static str, Option<Vec<(DVec2, DVec2)>>, Decomposition);
    // the candidate layouts are independent: built (and predicted below) in parallel, the
    // results kept in the order of the list, so the choice does not depend on the threads
    let conc_opts = opts.clone().layout(Layout::Concavity);
    let (conc, chord_layouts) = rayon::join(
        || decompose(region, &conc_opts),
        || {
            LAYOUT_ASPECTS
                .par_iter()
                .map(|&(name, aspect)| {
                    let o = opts.clone().chord_aspect(aspect);
                    (name, chord_layout_cuts(region, &o))
                })
                .collect::<Vec<_>>()
        },
    );
    let mut cands: Vec<Cand> = Vec::new();
    let conc_err = match conc {
        Ok(d) => {
            cands.push(("concavity", None, d));
            None
        }
        Err(e) => Some(e),
    };
    for (name, built) in chord_layouts {
        if let Ok((cuts, d)) = built {
            if !cands.iter().any(|(_, _, c)| *c == d) {
                cands.push((name, Some(cuts), d));
            }
        }
    }
    cands.retain(|(name, _, _)| !excluded.iter().any(|e| e == name));
    let predictions: Vec<_> = cands
        .par_iter()
        .map(|(_, _, d)| crate::predict::predict_mesh(d, size))
        .collect();
    // key: fewer interior singularities, then the predicted share, then fewer rule breaks,
    // then fewer blocks
    type Key = (usize, f64, usize, usize);
    let mut best: Option<(Key, usize, crate::predict::Prediction)> = None;
    let mut scores = Vec::new();
    for (k, ((name, _, d), pred)) in cands.iter().zip(predictions).enumerate() {
        let Ok(p) = pred else {
            continue;
        };
        scores.push((name.to_string(), 100.0 * p.good_share));
        let share = p.good_share
            + if *name == "concavity" {
                LAYOUT_MARGIN
            } else {
                0.0
            };
        // interior singularities are a hard rule (the mesh must have none); a block that is not
        // admissible (a corner below the critical angle) only costs the cells the prediction
        // already counts, so the predicted share decides before it (norway-mainland at
        // 100,000 cells: the layout with the fewest such blocks was predicted 12 points below
        // the best; docs/results.md, "Seventh pass")
        let key = (
            p.singularities,
            share,
            rule_breaks(d, &p, opts),
            d.blocks.len(),
        );
        if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
            eprintln!(
                "layout {name}: {} blocks, predicted {:.2} %, {} singular nodes, {} rule breaks",
                d.blocks.len(),
                100.0 * p.good_share,
                p.singularities,
                key.0
            );
        }
        let better = match &best {
            None => true,
            Some((bk, _, _)) => {
                key.0 < bk.0
                    || (key.0 == bk.0
                        && (key.1 > bk.1 || (key.1 == bk.1 && (key.2, key.3) < (bk.2, bk.3))))
            }
        };
        if better {
            best = Some((key, k, p));
        }
    }
    match best {
        Some((_, k, p)) => {
            let (name, cuts, d) = cands.swap_remove(k);
            let aspect = LAYOUT_ASPECTS
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, a)| *a);
            let (d, p, added, tried) = match (cuts, aspect) {
                (Some(cuts), Some(aspect)) => {
                    let o = opts.clone().chord_aspect(aspect);
                    resplit(region, &o, size, cuts, d, p)
                }
                // the concavity layout: its own cuts, in the order they were made, are the
                // layout cuts the split chords are added to
                (None, None) => {
                    let cuts: Vec<(DVec2, DVec2)> = d.cuts.iter().map(|c| (c.a, c.b)).collect();
                    resplit(region, &conc_opts, size, cuts, d, p)
                }
                _ => (d, p, 0, 0),
            };
            let choice = LayoutChoice {
                layout: name.to_string(),
                predicted_percent: 100.0 * p.good_share,
                candidates: scores,
                blocks: p.blocks,
                resplit_cuts: added,
                resplit_tried: tried,
            };
            Ok((d, choice))
        }
        None => match cands.pop() {
            Some((name, _, d)) => Ok((
                d,
                LayoutChoice {
                    layout: name.to_string(),
                    predicted_percent: f64::NAN,
                    candidates: scores,
                    blocks: Vec::new(),
                    resplit_cuts: 0,
                    resplit_tried: 0,
                },
            )),
            None => Err(conc_err.map(CoreError::from).unwrap_or(CoreError::NoLayout)),
        },
    }
}

/// The split chords found by [`resplit`], by (block geometry key, number of layout cuts).
type ChordCache = std::collections::HashMap<(Vec<u64>, usize), Option<(DVec2, DVec2)>>;

/// The predicted-quality re-split of a layout ([`choose_layout`]): returns the
/// decomposition, its prediction, the cuts added and the candidates tried.
fn resplit(
    region: &Region,
    opts: &DecomposeOptions,
    size: MeshSize,
    mut cuts: Vec<(DVec2, DVec2)>,
    mut d: Decomposition,
    mut p: crate::predict::Prediction,
) -> (Decomposition, crate::predict::Prediction, usize, usize) {
    let mut breaks = rule_breaks(&d, &p, opts);
    // a cut must leave at least RESPLIT_CELLS cells of the requested size on its smaller side
    let area = crate::curves::decomposition_area(&d);
    let h2 = match size {
        MeshSize::Cells(n) => area / n.max(1) as f64,
        MeshSize::CellSize(h) => h * h,
        _ => area / 20_000.0,
    };
    let min_area = RESPLIT_CELLS * h2;
    let mut tried: Vec<(DVec2, DVec2)> = Vec::new();
    let mut searched: ChordCache = ChordCache::new();
    let mut added = 0;
    while tried.len() < RESPLIT_EVALS && d.blocks.len() <= RESPLIT_MAX_BLOCKS {
        let mut order: Vec<(f64, usize)> = (0..d.blocks.len().min(p.blocks.len()))
            .filter(|&b| p.blocks[b] < RESPLIT_BELOW)
            .map(|b| ((1.0 - p.blocks[b]) * p.block_cells[b] as f64, b))
            .collect();
        order.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        let cand = order.iter().find_map(|&(_, b)| {
            // a block's chord depends on its ring and on the layout cuts, which only grow
            // (by an accepted cut): each (ring, layout) is searched once
            let key = (d.blocks[b].geometry_key(), cuts.len());
            let chord = *searched
                .entry(key)
                .or_insert_with(|| split_chord(region, &d, b, &cuts, RESPLIT_SCORE, min_area));
            chord.filter(|c| !tried.contains(c))
        });
        let Some(c) = cand else {
            break;
        };
        tried.push(c);
        let mut next = cuts.clone();
        next.push(c);
        let Ok(nd) = layout_from_cuts(region, opts, &next) else {
            continue;
        };
        if nd == d {
            continue;
        }
        let Ok(np) = crate::predict::predict_mesh(&nd, size) else {
            continue;
        };
        let nb = rule_breaks(&nd, &np, opts);
        if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
            eprintln!(
                "re-split candidate {:?}-{:?}: {} -> {} blocks, {:.2} % -> {:.2} %, breaks {breaks} -> {nb}",
                c.0,
                c.1,
                d.blocks.len(),
                nd.blocks.len(),
                100.0 * p.good_share,
                100.0 * np.good_share
            );
        }
        if nb <= breaks && np.good_share >= p.good_share + RESPLIT_GAIN {
            if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
                eprintln!(
                    "re-split: {:?}-{:?} predicted {:.2} % -> {:.2} %",
                    c.0,
                    c.1,
                    100.0 * p.good_share,
                    100.0 * np.good_share
                );
            }
            cuts = next;
            d = nd;
            p = np;
            breaks = nb;
            added += 1;
        }
    }
    (d, p, added, tried.len())
}
