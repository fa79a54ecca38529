//! The simplification the end-to-end mesher (`unamalla_core::Mesher`, default settings) applies
//! before decomposing, reproduced without depending on `unamalla-core` (which depends on this
//! crate): `simplify_for_mesh` — `simplify_region` with `SimplifyOptions::default()` (modified
//! areas, clean preset), ε halved while the area changes by more than 1 % —
//! then `remove_features_below(ζ < c·h²)` with `c = 5` (`DEFAULT_FEATURE_FACTOR`) and
//! `h = √(area / 20 000)` (the default `MeshSize::Cells(20_000)`, area of the simplified region).
//! Keep in sync with `crates/unamalla-core/src/pipeline.rs` (`Mesher::mesh_observed`, step 1).

use unamalla_contour::{remove_features_below, simplify_region, SimplifyOptions};
use unamalla_mesh::Region;

/// The default cell count of the mesher.
pub const CELLS: f64 = 20_000.0;
/// The default feature factor of the mesher.
pub const FEATURE_FACTOR: f64 = 5.0;

/// Simplifies `region` exactly as the default mesher does before the decomposition.
pub fn pipeline_simplify(region: &Region) -> Region {
    // `simplify_for_mesh`: halve ε while the area changes by more than 1 %
    let opts = SimplifyOptions::default();
    let mut r = simplify_region(region, &opts).expect("default simplification");
    for _ in 0..6 {
        if r.relative_area_change.abs() <= 0.01 {
            break;
        }
        let smaller = opts.clone().epsilon(Some(0.5 * r.epsilon));
        r = simplify_region(region, &smaller).expect("default simplification");
    }
    let simplified = r.region;
    let h = (simplified.area() / CELLS).sqrt();
    remove_features_below(&simplified, FEATURE_FACTOR * h * h).expect("feature removal")
}
