//! Shapefile reader (`.shp` bytes): `parse_shapefile_parts`, then region validation of every
//! part. Oracles: a successful parse never returns more points than the input has 16-byte
//! `x y` pairs (no count is trusted beyond the bytes present); every part that validates as a
//! `Region` is encoded by `encode_region_shapefile` and read back as exactly one part with the
//! same outer ring and holes (as point sets; the writer closes and reorients the rings).
#![no_main]
use libfuzzer_sys::fuzz_target;
use unamalla_mesh::{DVec2, Region};

fn key(ring: &[DVec2]) -> Vec<[u64; 2]> {
    let mut k: Vec<[u64; 2]> = ring
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits()])
        .collect();
    k.sort_unstable();
    k
}

fn rings(r: &Region) -> (Vec<[u64; 2]>, Vec<Vec<[u64; 2]>>) {
    let mut holes: Vec<_> = r.holes().iter().map(|h| key(h.points())).collect();
    holes.sort();
    (key(r.outer().points()), holes)
}

fuzz_target!(|data: &[u8]| {
    let Ok(parts) = unamalla_io::parse_shapefile_parts(data) else {
        return;
    };
    let points: usize = parts.iter().map(|p| p.num_vertices()).sum();
    assert!(
        points * 16 <= data.len(),
        "{points} points from {} bytes",
        data.len()
    );
    for p in parts {
        let Ok(region) = Region::new(p.outer, p.holes) else {
            continue;
        };
        let (shp, _shx) =
            unamalla_io::encode_region_shapefile(&region).expect("a valid region encodes");
        let back = unamalla_io::parse_shapefile_parts(&shp).expect("our own file reads back");
        assert_eq!(back.len(), 1, "one part written, {} read", back.len());
        let b = back.into_iter().next().unwrap();
        let again = Region::new(b.outer, b.holes).expect("the written region validates again");
        assert_eq!(rings(&again), rings(&region));
    }
});
