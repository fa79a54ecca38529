//! GeoJSON region reader: `parse_polygon_parts`, `parse_region_geojson` (strict and cleaned).
//! Oracle: no panic; a region that was read writes back (`region_to_geojson`) and reads back
//! with the same rings.
#![no_main]
use libfuzzer_sys::fuzz_target;
use unamalla_io::{
    parse_polygon_parts, parse_region_geojson, parse_region_geojson_cleaned, region_to_geojson,
    PartSelector,
};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = parse_polygon_parts(&text);
    let _ = parse_region_geojson_cleaned(&text, PartSelector::Index(1));
    if let Ok(region) = parse_region_geojson(&text, PartSelector::Largest) {
        let again = parse_region_geojson(&region_to_geojson(&region), PartSelector::Largest)
            .expect("a region written by region_to_geojson reads back");
        // the rings must be equal; `Region`'s input-index map is not compared, since the
        // written ring is already normalised (found by this target: a clockwise input maps
        // to reversed source indices, the re-read one to the identity)
        assert_eq!(
            again.outer(),
            region.outer(),
            "GeoJSON round trip changed the outer ring"
        );
        assert_eq!(
            again.holes(),
            region.holes(),
            "GeoJSON round trip changed the holes"
        );
    }
});
