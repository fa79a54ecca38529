//! Shapefile reader (`.shp` bytes): `parse_shapefile_parts`, then region validation of every part.
#![no_main]
use libfuzzer_sys::fuzz_target;
use unamalla_mesh::Region;

fuzz_target!(|data: &[u8]| {
    if let Ok(parts) = unamalla_io::parse_shapefile_parts(data) {
        for p in parts {
            let _ = Region::new(p.outer, p.holes);
        }
    }
});
