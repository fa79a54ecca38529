//! UNAMALLA `.con` contour reader: `parse_con`, then the contour's sides and region.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(c) = unamalla_io::parse_con(&text) {
        // sides are empty for ibflag 0 (undefined partition), so only "no panic" is checked
        let _ = c.sides();
        let _ = c.region();
    }
});
