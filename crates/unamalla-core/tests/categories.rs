//! One regression test per shape category of block layouts, each failing with the thesis's layout
//! alone (Algorithm 1, [`Layout::Concavity`]) and passing with the mesher's layout choice
//! ([`choose_layout`]). The criteria are geometric, stated on the blocks, not on a file:
//!
//! - **elongated island**: no *longitudinal* cut — longer than twice the island's mean width
//!   W = area / length and within 30° of its principal axis (a cut along the island gives
//!   sliver blocks);
//! - **gulf with narrow arms**: over the eight gulfs and seas of the development set, fewer
//!   blocks keep an arm — a part extending at least [`ARM_SCORE`] chord widths
//!   beyond one of its chords ([`neck_score`]) — as with the concavity layout (not none: the
//!   concavity cuts inside the wide basins left by the chord layout still make a few long
//!   sliver blocks, e.g. in gulf-of-st-lawrence; docs/results.md);
//! - **sea with many islands**: a chain-shaped archipelago of 500 islands is decomposed with
//!   every hole kept and no interior singularity (the concavity layout gives up on a hole);
//! - **silhouette with a wedge-shaped body**: a concavity layout whose largest block is
//!   predicted below `RESPLIT_BELOW` is re-split by the prediction (a transverse cut) and the
//!   mesh's μ ≥ 0.8 share rises with it (before, only chord layouts were re-split: the
//!   crow's body block kept diagonal bands of sheared cells).

use std::path::Path;

use unamalla_core::decompose::chords::neck_score;
use unamalla_core::decompose::{decompose, DecomposeOptions, Decomposition, Layout, ARM_SCORE};
use unamalla_core::io::{self, PartSelector};
use unamalla_core::mesh::{DVec2, Region};
use unamalla_core::pipeline::{choose_layout, MeshSize, Mesher};

fn prepared(path: &Path, cells: usize) -> Region {
    let raw = io::read_region_geojson(path, PartSelector::Largest).unwrap();
    Mesher::new()
        .cells(cells)
        .prepare_region(&raw)
        .unwrap()
        .mesh_region
}

fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

fn options(region: &Region, cells: usize) -> DecomposeOptions {
    DecomposeOptions::default().cell_size(Some((region.area() / cells as f64).sqrt()))
}

fn concavity(region: &Region, cells: usize) -> Result<Decomposition, String> {
    let opts = options(region, cells).layout(Layout::Concavity);
    decompose(region, &opts).map_err(|e| e.to_string())
}

fn chosen(region: &Region, cells: usize) -> Decomposition {
    choose_layout(region, &options(region, cells), MeshSize::Cells(cells))
        .unwrap()
        .0
}

/// Principal axis (unit vector) of the outer ring's boundary, by edge-length-weighted PCA,
/// and the ring's length along it.
fn axis(region: &Region) -> (DVec2, f64) {
    let p = region.outer().points();
    let n = p.len();
    let (mut w, mut c) = (0.0, DVec2::ZERO);
    for k in 0..n {
        let l = p[k].distance(p[(k + 1) % n]);
        w += l;
        c += (p[k] + p[(k + 1) % n]) * 0.5 * l;
    }
    c /= w;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let l = p[k].distance(p[(k + 1) % n]);
        let d = (p[k] + p[(k + 1) % n]) * 0.5 - c;
        sxx += l * d.x * d.x;
        sxy += l * d.x * d.y;
        syy += l * d.y * d.y;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let u = DVec2::new(theta.cos(), theta.sin());
    let (lo, hi) = p.iter().fold((f64::MAX, f64::MIN), |(lo, hi), q| {
        (lo.min(q.dot(u)), hi.max(q.dot(u)))
    });
    (u, hi - lo)
}

fn longitudinal_cuts(d: &Decomposition, region: &Region) -> usize {
    let (u, length) = axis(region);
    let width = region.area() / length;
    d.cuts
        .iter()
        .filter(|c| {
            let v = c.b - c.a;
            let cos = (v.dot(u) / v.length()).abs();
            v.length() > 2.0 * width && cos > 30f64.to_radians().cos()
        })
        .count()
}

fn arms(d: &Decomposition) -> Vec<(usize, f64)> {
    d.blocks
        .iter()
        .map(|b| (b.id, neck_score(&b.ring)))
        .filter(|(_, s)| *s >= ARM_SCORE)
        .collect()
}

#[test]
fn an_elongated_island_is_cut_across_not_along() {
    let region = prepared(&fixture("regions/sakhalin.geojson"), 20_000);
    let old = concavity(&region, 20_000).unwrap();
    let new = chosen(&region, 20_000);
    let (lo, ln) = (
        longitudinal_cuts(&old, &region),
        longitudinal_cuts(&new, &region),
    );
    eprintln!("sakhalin longitudinal cuts: concavity {lo}, chosen {ln}");
    assert!(
        lo > 0,
        "the concavity layout has no longitudinal cut any more"
    );
    assert_eq!(ln, 0, "the chosen layout cuts along the island");
}

/// The gulfs and seas of the development set (every water body with a narrow arm or
/// channel), at the mesher's own simplification for 20,000 cells.
const GULFS: [&str; 8] = [
    "chesapeake-bay",
    "danish-straits",
    "gulf-of-finland",
    "gulf-of-mexico",
    "gulf-of-st-lawrence",
    "puget-sound",
    "adriatic-sea",
    "tyrrhenian-sea",
];

#[test]
fn fewer_blocks_keep_a_narrow_arm_of_a_gulf() {
    let (mut old_total, mut new_total) = (0, 0);
    for name in GULFS {
        let region = prepared(&fixture(&format!("regions/{name}.geojson")), 20_000);
        let old = arms(&concavity(&region, 20_000).unwrap());
        let new = arms(&chosen(&region, 20_000));
        eprintln!("{name}: blocks with arms: concavity {old:?}, chosen {new:?}");
        old_total += old.len();
        new_total += new.len();
    }
    eprintln!("blocks with arms: concavity {old_total}, chosen {new_total}");
    // measured 2026-12-02: concavity 16, chosen 12 (gulf-of-finland 3 → 0, puget-sound
    // 1 → 0, danish-straits 3 → 1; gulf-of-st-lawrence 2 → 3 and adriatic-sea 0 → 1 worse:
    // slivers between two long concavity cuts inside the wide basins, which an arm cut
    // between boundary points cannot reach)
    assert!(
        new_total < old_total,
        "the chosen layouts keep {new_total} arms, the concavity layouts {old_total}"
    );
}

#[test]
fn a_sea_with_500_islands_in_chains_is_decomposed() {
    let path = fixture("synthetic/archipelago-500.geojson");
    let raw = io::read_region_geojson(&path, PartSelector::Largest).unwrap();
    assert_eq!(raw.holes().len(), 500);
    // the islands are kept as they are (no simplification, no feature removal)
    let old = concavity(&raw, 20_000);
    eprintln!(
        "archipelago-500, concavity layout: {:?}",
        old.as_ref().map(|d| d.blocks.len())
    );
    assert!(
        old.is_err(),
        "the concavity layout decomposes the archipelago now"
    );
    let d = chosen(&raw, 20_000);
    d.validate(&raw).unwrap();
    assert_eq!(d.graph_cycles(), 500);
    assert!(d.cut_joints(&raw).is_empty());
}

/// A coast with barrier spits and lagoons (the Texas Gulf coast, 20,000 cells): the spits are
/// narrower than a cell, and without the neck cuts ([`Mesher::neck_factor`], on by default)
/// their blocks and the counts around them leave rows of near-degenerate cells in the smoothed
/// mesh. The criterion is the target, μ ≥ 0.8 on at least 90 % of the cells, with the
/// cuts and not without them (measured in release: 97.4 % in 1.4 s against 73.3 % in 14.8 s).
/// Slow in a debug build: `cargo test --release -p unamalla-core --test categories -- --ignored`.
#[test]
#[ignore = "meshes texas twice at 20,000 cells; run in release"]
fn a_coast_with_barrier_spits_meets_the_quality_target() {
    let cells = 20_000;
    let raw =
        io::read_region_geojson(fixture("regions/texas.geojson"), PartSelector::Largest).unwrap();
    let with = Mesher::new().cells(cells).prepare_region(&raw).unwrap();
    let without = Mesher::new()
        .cells(cells)
        .neck_factor(0.0)
        .prepare_region(&raw)
        .unwrap();
    assert!(!with.necks.is_empty(), "no neck cut on the texas coast");
    assert!(without.necks.is_empty());
    // the cuts change the area by what they report (spits lower it, inlets raise it)
    let signed: f64 = with
        .necks
        .iter()
        .map(|c| match c.kind {
            unamalla_core::contour::NeckKind::Spit => -c.area,
            unamalla_core::contour::NeckKind::Inlet => c.area,
        })
        .sum();
    let change = with.mesh_region.area() - without.mesh_region.area();
    assert!(
        (change - signed).abs() <= 1e-9 * raw.area(),
        "area change {change} against the cuts' {signed}"
    );
    let share = |m: Mesher| m.mesh(&raw).unwrap().report.mu_ge_0_8_percent;
    let old = share(Mesher::new().cells(cells).neck_factor(0.0));
    let new = share(Mesher::new().cells(cells));
    eprintln!("texas μ ≥ 0.8: without neck cuts {old:.1} %, with {new:.1} %");
    assert!(old < 90.0, "without neck cuts texas reaches {old} % now");
    assert!(new >= 90.0, "with neck cuts texas reaches only {new} %");
}

/// Silhouette with a wedge-shaped body (the crow at 5,000 cells): the concavity layout wins the
/// layout choice, and its body block — back and belly converging towards the tail — is
/// predicted below [`RESPLIT_BELOW`]; the re-split adds a transverse cut, raising the predicted
/// share by at least [`RESPLIT_GAIN`], and the smoothed mesh reaches μ ≥ 0.8 on at least 95 %
/// of its cells (91.0 % without the re-split, 98.1 % with it when this test was written: the
/// body's diagonal bands of sheared cells are gone; docs/results.md).
#[test]
fn a_wedge_shaped_body_is_resplit_across() {
    use unamalla_core::pipeline::{RESPLIT_BELOW, RESPLIT_GAIN};
    let cells = 5_000;
    let raw =
        io::read_region_geojson(fixture("regions/crow.geojson"), PartSelector::Largest).unwrap();
    let region = prepared(&fixture("regions/crow.geojson"), cells);
    let (d, choice) =
        choose_layout(&region, &options(&region, cells), MeshSize::Cells(cells)).unwrap();
    assert_eq!(choice.layout, "concavity");
    let conc = concavity(&region, cells).unwrap();
    let before = unamalla_core::predict::predict_mesh(&conc, MeshSize::Cells(cells)).unwrap();
    assert!(
        before.blocks.iter().any(|&p| p < RESPLIT_BELOW),
        "{:?}",
        before.blocks
    );
    assert!(choice.resplit_cuts >= 1, "{choice:?}");
    assert!(d.blocks.len() > conc.blocks.len());
    assert!(
        choice.predicted_percent >= 100.0 * (before.good_share + RESPLIT_GAIN) - 1e-9,
        "{} against {}",
        choice.predicted_percent,
        100.0 * before.good_share
    );
    let r = Mesher::new().cells(cells).mesh(&raw).unwrap();
    assert!(
        r.report.mu_ge_0_8_percent >= 95.0,
        "{}",
        r.report.mu_ge_0_8_percent
    );
}
