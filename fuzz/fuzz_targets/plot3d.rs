//! Plot3D reader, ASCII and Fortran-unformatted binary, 2D and 3D: every input is tried with all
//! four readings.
#![no_main]
use libfuzzer_sys::fuzz_target;
use unamalla_io::{parse_plot3d_ascii, parse_plot3d_binary, Plot3dDim};

fuzz_target!(|data: &[u8]| {
    for dim in [Plot3dDim::D2, Plot3dDim::D3] {
        let _ = parse_plot3d_binary(data, dim);
        if let Ok(text) = std::str::from_utf8(data) {
            let _ = parse_plot3d_ascii(text, dim);
        }
    }
});
