use super::arms::{arm_free, ARM_FREE_SCORE};
use super::*;

fn rect(w: f64, h: f64) -> Region {
    Region::new(
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(w, 0.0),
            DVec2::new(w, h),
            DVec2::new(0.0, h),
        ],
        vec![],
    )
    .expect("rectangle")
}

/// The 4 × 4 square with a 2 × 2 square hole in its middle (area 12, gap 1).
fn square_with_hole() -> Region {
    Region::new(
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(0.0, 4.0),
        ],
        vec![vec![
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 3.0),
            DVec2::new(3.0, 3.0),
            DVec2::new(3.0, 1.0),
        ]],
    )
    .expect("square with a hole")
}

#[test]
fn the_inside_triangles_cover_the_region() {
    let r = square_with_hole();
    let m = ChordMesh::new(&r, 0.5).expect("triangulation");
    let a: f64 = (0..m.tris.len()).map(|t| m.tri_area(t)).sum();
    assert!((a - 12.0).abs() < 1e-9, "area {a}");
}

#[test]
fn neck_scores_of_a_square_and_a_dumbbell() {
    let v = DVec2::new;
    // square: the best chord is a midline, w = 1 and A = ½ on each side → ½
    let sq = [v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)];
    let s = neck_score(&sq);
    assert!(s <= 0.5 + 1e-9 && s > 0.45, "{s}");
    // two 4 × 4 squares joined by a 1 × 1 neck: the chord across the neck has w = 1 and
    // at least 16 on each side
    let db = [
        v(0.0, 0.0),
        v(4.0, 0.0),
        v(4.0, 1.5),
        v(5.0, 1.5),
        v(5.0, 0.0),
        v(9.0, 0.0),
        v(9.0, 4.0),
        v(5.0, 4.0),
        v(5.0, 2.5),
        v(4.0, 2.5),
        v(4.0, 4.0),
        v(0.0, 4.0),
    ];
    let d = neck_score(&db);
    assert!(d >= 16.0, "{d}");
}

/// A 20 × 10 rectangle with a V slit from the top whose tip stops 0.05 above the bottom
/// side, at x = 10.37 (between the uniform samples, spaced perimeter/400 ≈ 0.2): the pinch
/// is a quarter of the spacing wide. The neck score must see the true width w = 0.05 (the
/// foot of the perpendicular from the tip is sampled), so it equals A_left/w² with A_left
/// the shoelace area of the part left of the vertical chord (without the feet the best
/// chord runs to the nearest uniform sample, 0.0547 long, and the score is 16 % lower).
#[test]
fn a_neck_narrower_than_the_sample_spacing_is_seen_at_its_true_width() {
    let v = DVec2::new;
    let (x, w) = (10.37, 0.05);
    let ring = [
        v(0.0, 0.0),
        v(20.0, 0.0),
        v(20.0, 10.0),
        v(x + 0.5, 10.0),
        v(x, w),
        v(x - 0.5, 10.0),
        v(0.0, 10.0),
    ];
    let per: f64 = (0..ring.len())
        .map(|i| ring[i].distance(ring[(i + 1) % ring.len()]))
        .sum();
    assert!(
        w < 0.5 * per / 400.0,
        "the neck must be below the sample spacing"
    );
    let left = [
        v(0.0, 0.0),
        v(x, 0.0),
        v(x, w),
        v(x - 0.5, 10.0),
        v(0.0, 10.0),
    ];
    let right = [
        v(x, 0.0),
        v(20.0, 0.0),
        v(20.0, 10.0),
        v(x + 0.5, 10.0),
        v(x, w),
    ];
    let area = |p: &[DVec2]| {
        0.5 * (0..p.len())
            .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
            .sum::<f64>()
    };
    let expect = area(&left).min(area(&right)) / (w * w);
    let s = neck_score(&ring);
    assert!((s / expect - 1.0).abs() < 1e-6, "{s} vs {expect}");
}

/// Where `arm_free` holds, no chord of the triangulation scores [`ARM_FREE_SCORE`] or
/// more (`neck_score`: the largest score over the same chords), on rectangles of many
/// aspects, regular polygons and pseudo-random star-shaped rings; and it holds for fat
/// shapes, fails for a dumbbell.
#[test]
fn arm_free_blocks_have_no_chord_near_the_arm_score() {
    let v = DVec2::new;
    let check = |ring: &[DVec2]| -> bool {
        let region = Region::new(ring.to_vec(), vec![]).expect("ring");
        let pts = region.outer().points();
        let free = arm_free(
            pts,
            &vec![true; pts.len()],
            region.area(),
            region.perimeter(),
        );
        if free {
            let s = neck_score(ring);
            assert!(s < ARM_FREE_SCORE, "score {s} for {ring:?}");
        }
        free
    };
    let mut shown = 0;
    for k in 1..40 {
        let a = 1.0 + 0.25 * k as f64;
        shown += check(&[v(0.0, 0.0), v(a, 0.0), v(a, 1.0), v(0.0, 1.0)]) as usize;
    }
    for n in 3..24 {
        let ring: Vec<DVec2> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                v(t.cos(), t.sin())
            })
            .collect();
        assert!(check(&ring), "a regular {n}-gon has no arm");
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..400 {
        let n = 3 + (next() * 60.0) as usize;
        let (sx, sy) = (0.2 + 3.0 * next(), 0.2 + 3.0 * next());
        let ring: Vec<DVec2> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * (i as f64 + 0.8 * next()) / n as f64;
                let r = 0.3 + next();
                v(sx * r * t.cos(), sy * r * t.sin())
            })
            .collect();
        shown += check(&ring) as usize;
    }
    assert!(shown > 50, "{shown}");
    let dumbbell = [
        v(0.0, 0.0),
        v(4.0, 0.0),
        v(4.0, 1.5),
        v(5.0, 1.5),
        v(5.0, 0.0),
        v(9.0, 0.0),
        v(9.0, 4.0),
        v(5.0, 4.0),
        v(5.0, 2.5),
        v(4.0, 2.5),
        v(4.0, 4.0),
        v(0.0, 4.0),
    ];
    assert!(!check(&dumbbell));
}

#[test]
fn a_square_gets_no_transverse_cut() {
    let cuts = layout_cuts(&rect(1.0, 1.0), 0.05, DEFAULT_ASPECT, 0.0).expect("cuts");
    assert!(cuts.is_empty(), "{cuts:?}");
}

#[test]
fn a_long_strip_is_cut_across_into_short_blocks() {
    // 10 × 1: every cut is vertical (perpendicular to the axis); the pieces are at most
    // 2T = 3 widths long, so at least 10/3 → 3 cuts
    let cuts = layout_cuts(&rect(10.0, 1.0), 0.1, DEFAULT_ASPECT, 0.0).expect("cuts");
    assert!(cuts.len() >= 3, "{cuts:?}");
    let mut xs: Vec<f64> = cuts
        .iter()
        .map(|(a, b)| {
            assert!((a.x - b.x).abs() < 1e-9, "cut not transverse: {a:?} {b:?}");
            a.x
        })
        .collect();
    xs.sort_by(f64::total_cmp);
    let mut prev = 0.0;
    for x in xs.iter().chain(std::iter::once(&10.0)) {
        assert!(
            x - prev <= 3.0 + 1e-9,
            "piece {prev}..{x} longer than 3 widths"
        );
        prev = *x;
    }
}

#[test]
fn a_hole_gets_two_bridges_that_split_it() {
    let r = square_with_hole();
    let cuts = layout_cuts(&r, 0.25, DEFAULT_ASPECT, 0.0).expect("cuts");
    assert!(cuts.len() >= 2, "{cuts:?}");
    // the first two are the bridge and its closing chord, each 1 long (the gap)
    for (a, b) in &cuts[..2] {
        assert!((a.distance(*b) - 1.0).abs() < 1e-9, "{a:?} {b:?}");
    }
}
