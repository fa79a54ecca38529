//! VTK XML reader (`.vts` / `.vtu`): `parse_vtk_xml`, then the accessors of the result.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(f) = unamalla_io::parse_vtk_xml(&text) {
        let _ = (
            f.mesh.num_cells(),
            f.mesh.num_nodes(),
            f.cell_array("quality"),
        );
    }
});
