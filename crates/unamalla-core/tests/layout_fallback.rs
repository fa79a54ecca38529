//! The layout fallback of `Mesher::mesh_observed` (the guarantee holds or the run
//! fails — and a run should not fail where another candidate layout meets it).
//!
//! Newfoundland at 5,000 cells: the best-predicted layout (chords at aspect 0.35) has a block
//! whose side is notched deeper than its cells; its transfinite start has folds no untangling
//! removes (8 non-convex cells were left, exit 3 before the fallback existed). The mesh must
//! now come out valid, checked again here independently of the pipeline's own verification.

use std::path::Path;

use unamalla_core::io::{self, PartSelector};
use unamalla_core::mesh::quality::non_convex_cells;
use unamalla_core::pipeline::{choose_layout_excluding, Mesher, LAYOUT_ASPECTS, QUALITY_FALLBACKS};
use unamalla_core::verify::{verify_quads, VerifyOptions};

/// `fixtures/FOLDER/NAME.geojson`, its largest part.
fn fixture(folder: &str, name: &str) -> unamalla_core::mesh::Region {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(folder)
        .join(format!("{name}.geojson"));
    io::read_region_geojson(p, PartSelector::Largest).unwrap()
}

fn region(name: &str) -> unamalla_core::mesh::Region {
    fixture("regions", name)
}

/// The independent check of the mesh against the region it was made of passes.
fn assert_verified(r: &unamalla_core::pipeline::MeshResult) {
    let v = verify_quads(
        r.mesh.global(),
        Some(&r.simplified),
        &VerifyOptions::default(),
    );
    assert!(v.passed(), "{v}");
}

#[test]
fn a_layout_that_leaves_folds_is_replaced_by_the_next_candidate() {
    let r = Mesher::new()
        .cells(5_000)
        .mesh(&region("newfoundland"))
        .expect("a valid mesh from some candidate layout");
    assert_eq!(non_convex_cells(r.mesh.global()).len(), 0);
    assert_verified(&r);
    let layout = r
        .report
        .layout
        .as_ref()
        .expect("automatic layout")
        .layout
        .clone();
    // every layout named as failed in the notes differs from the one kept
    let failed: Vec<&String> = r
        .report
        .notes
        .iter()
        .filter(|n| n.contains("non-convex or outside the region"))
        .collect();
    for n in &failed {
        assert!(!n.starts_with(&format!("layout {layout} ")), "{n}");
    }
    eprintln!("newfoundland 5k: kept {layout}, notes {failed:?}");
}

/// `choose_layout_excluding` never returns an excluded candidate, and with every candidate
/// excluded it is an error (the fallback then keeps the first failure).
#[test]
fn excluded_layouts_are_not_chosen() {
    let reg = region("crete");
    let opts = unamalla_core::decompose::DecomposeOptions::default()
        .cell_size(Some((reg.area() / 2_000.0).sqrt()));
    let size = unamalla_core::pipeline::MeshSize::Cells(2_000);
    let (_, first) = choose_layout_excluding(&reg, &opts, size, &[]).unwrap();
    let (_, second) =
        choose_layout_excluding(&reg, &opts, size, std::slice::from_ref(&first.layout)).unwrap();
    assert_ne!(first.layout, second.layout);
    let all: Vec<String> = std::iter::once("concavity".to_string())
        .chain(LAYOUT_ASPECTS.iter().map(|(n, _)| n.to_string()))
        .collect();
    assert!(choose_layout_excluding(&reg, &opts, size, &all).is_err());
}

/// The share `X` of a note "layout L reached μ ≥ 0.8 on X % …".
fn share_in(note: &str) -> Option<f64> {
    let rest = note.split("reached μ ≥ 0.8 on ").nth(1)?;
    rest.split(' ').next()?.parse().ok()
}

/// The quality fallback of `Mesher::mesh_observed`: with the target off (0 %) the chosen
/// layout is kept; with an unreachable target (100 %) the chosen layout is named as below it
/// with the share the first run reached, at most `QUALITY_FALLBACKS` other candidates are
/// made, and the mesh kept is the attempt with the highest share.
#[test]
fn a_layout_below_the_quality_target_is_retried_and_the_best_share_kept() {
    let reg = region("crete");
    let base = Mesher::new()
        .cells(2_000)
        .quality_target(0.0)
        .mesh(&reg)
        .expect("crete at 2,000 cells");
    assert!(
        !base
            .report
            .notes
            .iter()
            .any(|n| n.contains("below the target")),
        "{:?}",
        base.report.notes
    );
    let first = base
        .report
        .layout
        .as_ref()
        .expect("automatic")
        .layout
        .clone();
    let r = Mesher::new()
        .cells(2_000)
        .quality_target(100.0)
        .mesh(&reg)
        .expect("crete at 2,000 cells, target 100 %");
    let below: Vec<&String> = r
        .report
        .notes
        .iter()
        .filter(|n| n.contains("below the target 100 %"))
        .collect();
    assert!(
        !below.is_empty() && below.len() <= QUALITY_FALLBACKS,
        "{:?}",
        r.report.notes
    );
    // the first attempt is the run without the target, to the bit
    assert!(
        below[0].starts_with(&format!(
            "layout {first} reached μ ≥ 0.8 on {:.1} % of the cells",
            base.report.mu_ge_0_8_percent
        )),
        "{}",
        below[0]
    );
    let shares: Vec<f64> = r.report.notes.iter().filter_map(|n| share_in(n)).collect();
    assert_eq!(shares.len(), 2 * below.len(), "{:?}", r.report.notes);
    let best = shares.iter().copied().fold(0.0, f64::max);
    let kept = r.report.mu_ge_0_8_percent;
    assert!(kept >= base.report.mu_ge_0_8_percent);
    // the notes round to 0.1
    assert!(
        (kept - best).abs() <= 0.05 + 1e-9,
        "kept {kept}, notes {shares:?}"
    );
}

/// Holes narrower than a cell (`Mesher::drop_narrow_holes`): a sea with 100 islands at 1,000
/// cells, where every island is narrower than the cell size h = √(area/1000). Keeping them,
/// the run fails with the error naming such a hole; by default it is made again without the
/// holes narrower than h — exactly the input holes whose bounding box is narrower than h,
/// computed here from the input — and the notes say so; the mesh passes the independent check.
#[test]
#[ignore = "meshes a 100-island sea several times; run in release: \
            cargo test --release -p unamalla-core --test layout_fallback -- --ignored"]
fn a_failure_next_to_holes_narrower_than_a_cell_is_meshed_without_them() {
    use unamalla_core::preflight::PreflightError;
    use unamalla_core::CoreError;
    let reg = fixture("synthetic", "archipelago-100");
    let h = (reg.area() / 1_000.0).sqrt();
    let narrow: Vec<usize> = (0..reg.holes().len())
        .filter(|&k| unamalla_core::contour::hole_width(&reg.holes()[k]) < h)
        .collect();
    assert!(!narrow.is_empty());
    let Err(e) = Mesher::new()
        .cells(1_000)
        .drop_narrow_holes(false)
        .mesh(&reg)
    else {
        panic!("the narrow holes were kept and meshed");
    };
    assert!(
        matches!(e, CoreError::Preflight(PreflightError::SmallHole(_))),
        "{e}"
    );
    let r = Mesher::new()
        .cells(1_000)
        .carve_dropped_holes(false)
        .mesh(&reg)
        .expect("meshed without the narrow holes");
    let mut dropped = r.report.holes_dropped.clone();
    dropped.sort_unstable();
    assert_eq!(dropped, narrow);
    assert!(
        r.report
            .notes
            .iter()
            .any(|n| n.contains(&format!("made again without the {} hole(s)", narrow.len()))),
        "{:?}",
        r.report.notes
    );
    assert_verified(&r);
}

/// A sea of 500 islands 0.5–1.6 cell sizes across (synthetic: a 200 × 120 box, five chains)
/// at 20,000 cells, with carving off. The mesh keeping every island fails; it is made again
/// without the islands narrower than a cell, and where that still leaves a cell folded next to
/// an island between one and two cells across, a later round leaves out the islands narrower
/// than `NEAR_HOLE_WIDTH` cells next to the failure (not all of them; measured with the
/// bounding-box width of the fourth session: 1 of 189; with the hull width no later round is
/// needed): the mesh is made, passes the independent check, and every dropped hole is either
/// narrower than a cell or narrower than two and named in a note. (With carving off: by default the
/// islands are carved, `a_sea_of_islands_is_meshed_with_its_islands_carved`.)
#[test]
#[ignore = "meshes a 500-island sea about nine times (≈ 90 s in release): \
            cargo test --release -p unamalla-core --test layout_fallback -- --ignored"]
fn a_sea_of_islands_one_or_two_cells_across_is_meshed() {
    use unamalla_core::pipeline::NEAR_HOLE_WIDTH;
    let reg = fixture("synthetic", "archipelago-500");
    let h = (reg.area() / 20_000.0).sqrt();
    let width = |k: usize| unamalla_core::contour::hole_width(&reg.holes()[k]);
    let narrow = (0..reg.holes().len()).filter(|&k| width(k) < h).count();
    let near_scale = (0..reg.holes().len())
        .filter(|&k| width(k) >= h && width(k) < NEAR_HOLE_WIDTH * h)
        .count();
    let r = Mesher::new()
        .cells(20_000)
        .carve_dropped_holes(false)
        .mesh(&reg)
        .expect("the sea is meshed");
    assert_verified(&r);
    assert_eq!(r.report.interior_singularities, 0);
    let dropped = &r.report.holes_dropped;
    // every hole narrower than a cell, and of those one to two cells across only some (those
    // next to which a later round still failed, each round named in a note; none when the
    // mesh without the narrower ones passes)
    assert_eq!(dropped.iter().filter(|&&k| width(k) < h).count(), narrow);
    let later = dropped.iter().filter(|&&k| width(k) >= h).count();
    assert!(later < near_scale, "{later} of {near_scale}");
    assert!(dropped.iter().all(|&k| width(k) < NEAR_HOLE_WIDTH * h));
    assert_eq!(
        r.simplified.holes().len(),
        reg.holes().len() - dropped.len()
    );
    assert_eq!(
        later > 0,
        r.report
            .notes
            .iter()
            .any(|n| n.contains("narrower than 2 cell sizes")),
        "{later} dropped in later rounds; notes {:?}",
        r.report.notes
    );
}

/// The same sea of 500 islands at 20,000 cells with the default carving: after the mesh keeping
/// every island fails, the islands narrower than `NEAR_HOLE_WIDTH` cells (all 500) leave the
/// layout and are carved into the mesh of the open sea. Every island at least a quarter of a
/// cell in area (`carve::MIN_AREA_FRACTION`) is carved unless its cells touch another carved
/// island; the mesh passes the independent check with μ ≥ 0.8 on at least 90 % of the cells.
#[test]
#[ignore = "meshes a 500-island sea about five times (≈ 30 s in release): \
            cargo test --release -p unamalla-core --test layout_fallback -- --ignored"]
fn a_sea_of_islands_is_meshed_with_its_islands_carved() {
    use unamalla_core::carve::MIN_AREA_FRACTION;
    let reg = fixture("synthetic", "archipelago-500");
    let r = Mesher::new()
        .cells(20_000)
        .mesh(&reg)
        .expect("the sea is meshed");
    assert_verified(&r);
    assert_eq!(r.report.interior_singularities, 0);
    let (carved, dropped) = (&r.report.holes_carved, &r.report.holes_dropped);
    assert_eq!(carved.len() + dropped.len(), 500);
    assert_eq!(r.simplified.holes().len(), carved.len());
    // the cell area of the request, with a margin for the cells' spread of sizes
    let cell = reg.area() / 20_000.0;
    let big = (0..500)
        .filter(|&k| reg.holes()[k].area() >= 2.0 * MIN_AREA_FRACTION * cell)
        .collect::<Vec<_>>();
    let missed = big.iter().filter(|k| !carved.contains(k)).count();
    assert!(
        missed * 50 <= big.len(),
        "{missed} of {} large islands not carved",
        big.len()
    );
    assert!(
        r.report.mu_ge_0_8_percent >= 90.0,
        "{}",
        r.report.mu_ge_0_8_percent
    );
    assert!(
        r.report.notes.iter().any(|n| n.starts_with("carved ")),
        "{:?}",
        r.report.notes
    );
}

/// Carving from the start leaves the islands narrower than a cell out of the layout, which
/// changes every layout; on gulf-of-mexico at 100,000 cells the three layouts without its
/// 0.9-cell islet each left one cell outside the region. The mesh keeping every hole in the
/// layout is then made too (and passes): the run must not fail where the layout without
/// carving meets the guarantee.
#[test]
#[ignore = "meshes gulf-of-mexico at 100,000 cells four times (≈ 45 s in release): \
            cargo test --release -p unamalla-core --test layout_fallback -- --ignored"]
fn a_failure_after_carving_from_the_start_is_meshed_with_every_hole_in_the_layout() {
    let reg = region("gulf-of-mexico");
    let r = Mesher::new()
        .cells(100_000)
        .mesh(&reg)
        .expect("a valid mesh");
    assert_verified(&r);
    assert_eq!(non_convex_cells(r.mesh.global()).len(), 0);
    assert!(
        r.report
            .notes
            .iter()
            .any(|n| n.ends_with("made again with every hole in the layout")),
        "{:?}",
        r.report.notes
    );
    assert!(r.report.holes_dropped.is_empty() && r.report.holes_carved.is_empty());
    assert_eq!(r.simplified.holes().len(), reg.holes().len());
}
