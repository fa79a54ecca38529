//! Deliberately infeasible problems (the error must name the right blocks, sides, cuts and pins) and the
//! typed validation errors.

use unamalla_compat_ilp::fixtures::{grid_decomposition, thesis_example_5_1};
use unamalla_compat_ilp::{
    solve, Block, CompatError, CompatProblem, ConflictItem, Curve, CutPair, LowerBounds, Side,
    SolveOptions,
};

fn report(e: CompatError) -> unamalla_compat_ilp::InfeasibilityReport {
    match e {
        CompatError::Infeasible(r) => r,
        other => panic!("expected Infeasible, got {other:?}"),
    }
}

#[test]
fn pin_against_length_bound_names_block_2_bottom_and_top() {
    // m5 − m9 = 0 (block 2 b/t) with ℓ5 = 7.5 ⇒ m5 ≥ 8, but m9 pinned to 4.
    let mut p = thesis_example_5_1();
    p.curves[8].pinned = Some(4);
    let r = report(solve(&p, &SolveOptions::density(1)).unwrap_err());
    assert!(r.irreducible);
    assert_eq!(
        r.conflict,
        vec![
            ConflictItem::SideEquation {
                block: 2,
                first_side: Side::Bottom,
                second_side: Side::Top,
                first_curves: vec![5],
                second_curves: vec![9],
                rhs: 0,
            },
            ConflictItem::Pin { curve: 9, count: 4 },
        ]
    );
    assert!(r.bounds.iter().any(|b| b.curve == 5 && b.bound == 8));
    let msg = r.to_string();
    assert!(
        msg.contains("block 2: bottom (curves 5) vs top (curves 9)"),
        "{msg}"
    );
    assert!(msg.contains("pinned count m9 = 4"), "{msg}");
}

#[test]
fn pin_conflict_through_a_cut_names_the_cut() {
    // Pin m2 = 7 and m4 = 9 (both above every bound involved, ≤ 6): block 1 r/l says m2 = m4.
    // Conflict = {block 1 r/l, pin m2, pin m4}.
    let mut p = thesis_example_5_1();
    p.curves[1].pinned = Some(7);
    p.curves[3].pinned = Some(9);
    let r = report(solve(&p, &SolveOptions::density(1)).unwrap_err());
    assert_eq!(r.conflict.len(), 3, "{r}");
    assert!(r
        .conflict
        .contains(&ConflictItem::Pin { curve: 2, count: 7 }));
    assert!(r
        .conflict
        .contains(&ConflictItem::Pin { curve: 4, count: 9 }));
    assert!(r.conflict.iter().any(|c| matches!(
        c,
        ConflictItem::SideEquation {
            block: 1,
            first_side: Side::Right,
            second_side: Side::Left,
            ..
        }
    )));
}

#[test]
fn pin_propagated_through_cut_names_cut_and_both_blocks() {
    // Pin m11 = 7 (copy of cut 1 in block 2's left side) and m4 = 9: block 1 r/l gives m2 = m4 = 9,
    // cut 1 gives m11 = m2. Conflict = {block 1 r/l, cut 1, pin m11, pin m4}.
    let mut p = thesis_example_5_1();
    p.curves[10].pinned = Some(7);
    p.curves[3].pinned = Some(9);
    let r = report(solve(&p, &SolveOptions::density(1)).unwrap_err());
    assert_eq!(r.conflict.len(), 4, "{r}");
    assert!(r.conflict.iter().any(|c| matches!(
        c,
        ConflictItem::CutEquation {
            cut: 1,
            first_curve: 11,
            second_curve: 2,
            ..
        }
    )));
    assert!(r.to_string().contains("cut 1"));
}

#[test]
fn self_adjacent_cut_without_pins_is_infeasible() {
    // One block, bottom = [Q1, Q2], right = [Q3], top = [Q4], left = [Q5], cut (Q2, Q4):
    // m1 + m2 − m4 = 2 − 1 = 1 and m2 = m4 ⇒ m1 = 1 < 2.
    let curves = (1..=5).map(|id| Curve::new(id, 1.0)).collect();
    let p = CompatProblem::new(
        curves,
        vec![Block::new(7, vec![0, 1], vec![2], vec![3], vec![4])],
        vec![CutPair::new(1, 3)],
    );
    let r = report(solve(&p, &SolveOptions::density(1)).unwrap_err());
    assert!(r.irreducible);
    assert_eq!(r.conflict.len(), 2, "{r}");
    assert!(matches!(
        r.conflict[0],
        ConflictItem::SideEquation {
            block: 7,
            first_side: Side::Bottom,
            ..
        }
    ));
    assert!(matches!(
        r.conflict[1],
        ConflictItem::CutEquation { cut: 1, .. }
    ));
}

#[test]
fn conflict_in_a_large_grid_is_localised() {
    // 4×5 grid; block (0,0) has id 1. Pin its right side (a single cut copy, to 40, above every length
    // bound ≤ ⌈5/0.5⌉ = 10) and its left boundary curves (to 2 each) inconsistently: block 1's r/l row
    // needs 40 − Σ left = 1 − s_l, i.e. Σ left = 39 + s_l ≠ 2·s_l.
    let mut p = grid_decomposition(4, 5, 3);
    let b = p.blocks[0].clone();
    let right = b.side(Side::Right)[0];
    p.curves[right].pinned = Some(40);
    for &j in b.side(Side::Left) {
        p.curves[j].pinned = Some(2);
    }
    let r = report(solve(&p, &SolveOptions::density(1)).unwrap_err());
    assert!(r.irreducible);
    // only block 1's r/l equation and pins are needed
    for c in &r.conflict {
        match c {
            ConflictItem::SideEquation {
                block, first_side, ..
            } => {
                assert_eq!((*block, *first_side), (1, Side::Right))
            }
            ConflictItem::Pin { .. } => {}
            other => panic!("unexpected {other:?}"),
        }
    }
    assert!(r.conflict.len() <= 1 + 1 + b.side(Side::Left).len());
}

#[test]
fn pin_below_the_bound_of_the_other_cut_copy() {
    // Pin m2 = 3 while its cut partner Q11 has ℓ11 = 5.5 ⇒ m11 ≥ 6: {cut 1, pin m2} suffices.
    let mut p = thesis_example_5_1();
    p.curves[1].pinned = Some(3);
    let r = report(solve(&p, &SolveOptions::density(1)).unwrap_err());
    assert_eq!(r.conflict.len(), 2, "{r}");
    assert!(r
        .conflict
        .contains(&ConflictItem::Pin { curve: 2, count: 3 }));
    assert!(r.bounds.iter().any(|b| b.curve == 11 && b.bound == 6));
}

#[test]
fn validation_errors_name_blocks_and_sides() {
    let good = thesis_example_5_1();
    assert!(good.validate().is_ok());

    let mut p = good.clone();
    p.blocks[1].sides[2].clear();
    assert_eq!(
        p.validate(),
        Err(CompatError::EmptySide {
            block: 2,
            side: Side::Top
        })
    );

    let mut p = good.clone();
    p.blocks[2].sides[3].push(0); // Q1 also on block 3's left
    assert_eq!(
        p.validate(),
        Err(CompatError::CurveUsedTwice {
            curve: 1,
            first_block: 1,
            first_side: Side::Bottom,
            second_block: 3,
            second_side: Side::Left
        })
    );

    let mut p = good.clone();
    p.blocks[0].sides[1].push(99);
    assert!(matches!(
        p.validate(),
        Err(CompatError::CurveIndexOutOfRange {
            block: 1,
            side: Side::Right,
            index: 99,
            ..
        })
    ));

    let mut p = good.clone();
    p.curves.push(Curve::new(18, 1.0));
    assert_eq!(p.validate(), Err(CompatError::CurveUnused { curve: 18 }));

    let mut p = good.clone();
    p.curves[4].length = f64::NAN;
    assert!(matches!(
        p.validate(),
        Err(CompatError::InvalidLength { curve: 5, .. })
    ));
    p.curves[4].length = -1.0;
    assert!(matches!(
        p.validate(),
        Err(CompatError::InvalidLength { curve: 5, .. })
    ));

    let mut p = good.clone();
    p.cuts.push(CutPair::new(0, 40));
    assert!(matches!(
        p.validate(),
        Err(CompatError::CutCurveOutOfRange {
            cut: 3,
            index: 40,
            ..
        })
    ));

    let mut p = good.clone();
    p.cuts.push(CutPair::new(1, 3)); // Q2 is already in cut 1
    assert_eq!(
        p.validate(),
        Err(CompatError::CurveInTwoCuts {
            curve: 2,
            first_cut: 1,
            second_cut: 3
        })
    );

    let mut p = good.clone();
    p.cuts.push(CutPair::new(3, 3));
    assert_eq!(
        p.validate(),
        Err(CompatError::CutSelfPair { cut: 3, curve: 4 })
    );

    let mut p = good.clone();
    p.curves[0].pinned = Some(1);
    assert_eq!(
        p.validate(),
        Err(CompatError::PinnedTooSmall { curve: 1, count: 1 })
    );

    let mut p = good.clone();
    p.curves[0].id = 2;
    assert_eq!(p.validate(), Err(CompatError::DuplicateCurveId { id: 2 }));

    let p = CompatProblem::new(vec![], vec![], vec![]);
    assert_eq!(p.validate(), Err(CompatError::NoBlocks));

    assert!(matches!(
        solve(&good, &SolveOptions::density(0)),
        Err(CompatError::InvalidParameter(_))
    ));
    assert!(matches!(
        solve(&good, &SolveOptions::cell_size(0.0)),
        Err(CompatError::InvalidParameter(_))
    ));
    // a length ratio that overflows the count range is an error, not a panic
    let mut p = good.clone();
    p.curves[0].length = 1e300;
    assert!(matches!(
        LowerBounds::Density(1).compute(&p),
        Err(CompatError::CountTooLarge { curve: 1, .. })
    ));
}

#[test]
fn from_index_sets_follows_the_j_convention() {
    // J_{1,b} = {1}, J_{1,r} = {2,3}, J_{1,t} = {4}, J_{1,l} = {5}; J_{2,*} = {6},{7},{8},{9}
    let p = CompatProblem::from_index_sets(&[[1, 2, 1, 1], [1, 1, 1, 1]], &[1.0; 9], &[(2, 8)])
        .unwrap();
    assert_eq!(p.blocks[0].sides, [vec![0], vec![1, 2], vec![3], vec![4]]);
    assert_eq!(p.blocks[1].sides, [vec![5], vec![6], vec![7], vec![8]]);
    assert_eq!(p.curves[8].id, 9);
    assert!(matches!(
        CompatProblem::from_index_sets(&[[1, 1, 1, 1]], &[1.0; 3], &[]),
        Err(CompatError::DimensionMismatch(_))
    ));
}

#[test]
fn problems_and_reports_round_trip_through_json() {
    let p = thesis_example_5_1();
    let text = serde_json::to_string(&p).unwrap();
    let back: CompatProblem = serde_json::from_str(&text).unwrap();
    assert_eq!(back, p);

    let mut bad = p.clone();
    bad.curves[8].pinned = Some(4);
    let r = report(solve(&bad, &SolveOptions::density(1)).unwrap_err());
    let text = serde_json::to_string(&r).unwrap();
    let back: unamalla_compat_ilp::InfeasibilityReport = serde_json::from_str(&text).unwrap();
    assert_eq!(back, r);
}
