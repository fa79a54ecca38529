//! `split_chord` and `layout_from_cuts`: the building blocks of the mesher's predicted-quality
//! re-split, checked on shapes whose answer follows from the chord score
//! `min(A₁, A₂)/w²` by hand.

use unamalla_decompose::{
    decompose, layout_from_cuts, split_chord, DecomposeOptions, EdgeKind, Layout,
};
use unamalla_mesh::{DVec2, Region};

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn rect(w: f64, h: f64) -> Region {
    Region::new(vec![v(0.0, 0.0), v(w, 0.0), v(w, h), v(0.0, h)], vec![]).unwrap()
}

fn concavity() -> DecomposeOptions {
    DecomposeOptions::default().layout(Layout::Concavity)
}

/// A 3 × 1 rectangle is one block. Its best chord is the transverse one at x = 1.5: a chord
/// from (x₁, 0) to (x₂, 1) has w² = 1 + (x₂ − x₁)² and leaves the smaller side an area of at
/// most min(x₁, x₂) + |x₂ − x₁|/2 ≤ 1.5, so the score is at most 1.5, reached only by x₁ = x₂ =
/// 1.5 (score 1.5). Cutting there gives two 1.5 × 1 blocks.
#[test]
fn a_long_rectangle_is_split_across_its_middle() {
    let r = rect(3.0, 1.0);
    let opts = concavity();
    let d = decompose(&r, &opts).unwrap();
    assert_eq!(d.blocks.len(), 1);
    let (p, q) = split_chord(&r, &d, 0, &[], 0.5, 0.0).expect("a chord of score 1.5");
    // samples every perimeter/400 = 0.02
    for e in [p, q] {
        assert!((e.x - 1.5).abs() <= 0.021, "{e:?}");
        assert!(e.y.abs() < 1e-12 || (e.y - 1.0).abs() < 1e-12, "{e:?}");
    }
    assert!((p.y - q.y).abs() > 0.999);
    // above the best score: no chord
    assert!(split_chord(&r, &d, 0, &[], 1.6, 0.0).is_none());
    // nor when the smaller side must hold more than the 1.5 any chord leaves it
    assert!(split_chord(&r, &d, 0, &[], 0.5, 1.6).is_none());
    assert!(split_chord(&r, &d, 0, &[], 0.5, 1.4).is_some());

    let d2 = layout_from_cuts(&r, &opts, &[(p, q)]).unwrap();
    assert_eq!(d2.blocks.len(), 2);
    assert_eq!(d2.cuts.len(), 1);
    for b in &d2.blocks {
        assert!((b.area() - 1.5).abs() <= 0.021, "{}", b.area());
    }
    d2.validate(&r).unwrap();
}

/// A unit square's best chord is its midline with score ½ (the smaller side 0.5, w = 1): it is
/// the best chord, near 0.5 (the sampled chords come within a few hundredths of it), and no
/// chord scores above it.
#[test]
fn a_square_has_only_its_midlines_at_score_one_half() {
    let r = rect(1.0, 1.0);
    let d = decompose(&r, &concavity()).unwrap();
    assert_eq!(d.blocks.len(), 1);
    assert!(split_chord(&r, &d, 0, &[], 0.51, 0.0).is_none());
    let (p, q) = split_chord(&r, &d, 0, &[], 0.45, 0.0).unwrap();
    let mid = 0.5 * (p + q);
    assert!(mid.distance(v(0.5, 0.5)) < 0.05, "{p:?} {q:?}");
}

/// A chord may end on a layout cut (it is replayed after it), not on a cut Algorithm 1 made.
/// The 6 × 1 rectangle cut at x = 3 leaves two 3 × 1 blocks; each one's best chord is at
/// x = 1.5 / 4.5, with both ends on the region boundary, and applying both gives four blocks.
#[test]
fn chords_are_replayed_after_the_layout_cuts() {
    let r = rect(6.0, 1.0);
    let opts = concavity();
    let first = [(v(3.0, 0.0), v(3.0, 1.0))];
    let d = layout_from_cuts(&r, &opts, &first).unwrap();
    assert_eq!(d.blocks.len(), 2);
    let mut cuts = first.to_vec();
    for b in 0..2 {
        let (p, q) = split_chord(&r, &d, b, &first, 0.5, 0.0).unwrap();
        let x = 0.5 * (p.x + q.x);
        assert!(
            (x - 1.5).abs() < 0.05 || (x - 4.5).abs() < 0.05,
            "{p:?} {q:?}"
        );
        cuts.push((p, q));
    }
    let d4 = layout_from_cuts(&r, &opts, &cuts).unwrap();
    assert_eq!(d4.blocks.len(), 4);
    d4.validate(&r).unwrap();
    // every block has boundary on both long sides
    for b in &d4.blocks {
        let on = b
            .edges
            .iter()
            .filter(|e| matches!(e, EdgeKind::Boundary { .. }))
            .count();
        assert!(on >= 2);
    }
}
