//! Decomposition file reader: `Decomposition::from_json` against two fixed regions (a square
//! with a square hole, and an L shape), chosen by the input length's parity. A decomposition
//! that loads must validate against its region.
#![no_main]
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use unamalla_decompose::Decomposition;
use unamalla_mesh::{DVec2, Region};

fn regions() -> &'static [Region; 2] {
    static R: OnceLock<[Region; 2]> = OnceLock::new();
    R.get_or_init(|| {
        let p = |v: &[(f64, f64)]| v.iter().map(|&(x, y)| DVec2::new(x, y)).collect::<Vec<_>>();
        let square = Region::new(
            p(&[(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)]),
            vec![p(&[(1.0, 1.0), (1.0, 3.0), (3.0, 3.0), (3.0, 1.0)])],
        )
        .expect("fixed region");
        let ell = Region::new(
            p(&[
                (0.0, 0.0),
                (2.0, 0.0),
                (2.0, 1.0),
                (1.0, 1.0),
                (1.0, 2.0),
                (0.0, 2.0),
            ]),
            vec![],
        )
        .expect("fixed region");
        [square, ell]
    })
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let region = &regions()[data.len() % 2];
    if let Ok(d) = Decomposition::from_json(&text, region) {
        d.validate(region)
            .expect("a loaded decomposition validates");
    }
});
