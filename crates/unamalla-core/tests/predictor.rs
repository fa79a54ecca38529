//! The layout predictor ([`unamalla_core::predict`]) correlates with the
//! quality the finished mesh reaches, block by block. `MeshReport::block_quality` holds both
//! numbers per block; the cell-weighted Pearson correlation over the blocks of a real region
//! must be clearly positive (≥ 0.5: the prediction explains at least a quarter of the
//! variance of the achieved per-block share).

use std::path::Path;

use unamalla_core::io::{self, PartSelector};
use unamalla_core::pipeline::Mesher;
use unamalla_core::predict::weighted_correlation as correlation;

#[test]
fn correlation_of_a_perfect_and_an_inverted_prediction() {
    let v = [(10.0, 20.0, 1.0), (20.0, 40.0, 2.0), (30.0, 60.0, 1.0)];
    assert!((correlation(&v) - 1.0).abs() < 1e-12);
    let u = [(10.0, 60.0, 1.0), (20.0, 40.0, 2.0), (30.0, 20.0, 1.0)];
    assert!((correlation(&u) + 1.0).abs() < 1e-12);
}

#[test]
fn the_layout_predictor_correlates_with_the_achieved_quality() {
    for name in ["puget-sound", "sakhalin"] {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/regions")
            .join(format!("{name}.geojson"));
        let region = io::read_region_geojson(p, PartSelector::Largest).unwrap();
        let r = Mesher::new().cells(6_000).mesh(&region).unwrap();
        let v: Vec<(f64, f64, f64)> = r
            .report
            .block_quality
            .iter()
            .map(|b| (b.predicted, b.achieved, b.cells as f64))
            .collect();
        assert!(v.len() >= 5, "{name}: {} blocks with a prediction", v.len());
        let c = correlation(&v);
        eprintln!(
            "{name}: per-block correlation {c:.3} over {} blocks",
            v.len()
        );
        assert!(c >= 0.5, "{name}: correlation {c:.3}");
    }
}
