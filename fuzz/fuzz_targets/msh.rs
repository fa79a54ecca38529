//! Gmsh MSH 4.1 ASCII reader: `parse_msh`.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = unamalla_io::parse_msh(&text);
});
