//! The library API: the same guarantees without the CLI.

use std::path::Path;

use unamalla_core::io::{self, PartSelector};

use crate::harness::hostile;

/// The library API: the same guarantees without the CLI.
#[test]
fn library_api_cases() {
    use unamalla_core::pipeline::Mesher;
    use unamalla_core::CoreError;
    let read = |p: &Path| io::read_region_geojson(p, PartSelector::Largest).unwrap();
    // cells(0) refused
    let sq = read(&hostile("square.geojson"));
    let e = Mesher::new().cells(0).mesh(&sq).err().unwrap();
    assert!(e.to_string().contains("at least 1 cell"), "{e}");
    // a huge count refused before allocating
    let e = Mesher::new().cells(1 << 40).mesh(&sq).err().unwrap();
    assert!(matches!(e, CoreError::Preflight(_)), "{e}");
    // the hole 1e-9 from the outer ring: named
    let h = read(&hostile("hole-1e-9.geojson"));
    let e = Mesher::new().cells(300).mesh(&h).err().unwrap();
    assert!(e.to_string().contains("hole 0 is 1.000e-9"), "{e}");
    // the spike without simplification: refused before the work (a feature 2·10⁻⁷ wide), or
    // Ok with the failures when a best effort is allowed
    let s = read(&hostile("spike-1e-7.geojson"));
    let e = Mesher::new()
        .simplify(None)
        .cells(300)
        .mesh(&s)
        .err()
        .unwrap();
    assert!(
        matches!(
            e,
            CoreError::Preflight(unamalla_core::preflight::PreflightError::NarrowFeature { .. })
        ),
        "{e}"
    );
    let r = Mesher::new()
        .simplify(None)
        .cells(300)
        .allow_non_convex(true)
        .mesh(&s)
        .unwrap();
    // the spike's cells cannot all be convex and inside a 2·10⁻⁷-wide spike: folded cells, or
    // (since the smoother keeps them convex) centroids outside the region
    let v = &r.report.verification;
    assert!(!v.passed());
    assert!(
        v.non_convex_cells > 0 || v.centroids_outside.is_some_and(|n| n > 0),
        "{v}"
    );
    // a good run carries a passed verification
    let r = Mesher::new().cells(300).mesh(&sq).unwrap();
    assert!(r.report.verification.passed(), "{}", r.report.verification);
    assert_eq!(r.report.verification.region_holes, Some(0));
}
