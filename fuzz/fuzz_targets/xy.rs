//! UNAMALLA XY mesh reader: `parse_xy`, then the size of the structured grid it describes.
#![no_main]
use libfuzzer_sys::fuzz_target;
use unamalla_mesh::HasNodes;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(m) = unamalla_io::parse_xy(&text) {
        // the grid was validated by the reader: its node count is m·n
        assert_eq!(m.grid.nodes().len(), m.grid.m() * m.grid.n());
    }
});
