//! ESRI Shapefile polygons: files assembled byte by byte here (independent of our writer,
//! following the layout of the ESRI whitepaper as summarised in `unamalla_io::shp`) load as
//! regions with holes attached and orientation normalised; part selection; `Z`/`M` variants;
//! our writer round-trips; typed errors with exact byte offsets for truncated and lying
//! headers; no panic and no allocation beyond the file size on mutated inputs (proptest).

mod common;

use common::*;
use proptest::prelude::*;
use unamalla_io::*;
use unamalla_mesh::{DVec2, Region};

// ---------------------------------------------------------------------------------------------
// A hand-written `.shp` assembler. Layout (ESRI Shapefile Technical Description, 1998):
// header 100 bytes = file code 9994 (BE) | 5 unused i32 | file length in 16-bit words (BE) |
// version 1000 (LE) | shape type (LE) | 8 f64 bounding box (LE); each record = record number
// (BE) | content length in words (BE) | content (LE).

fn be(out: &mut Vec<u8>, v: i32) {
    out.extend_from_slice(&v.to_be_bytes());
}
fn le(out: &mut Vec<u8>, v: i32) {
    out.extend_from_slice(&v.to_le_bytes());
}
fn f(out: &mut Vec<u8>, v: f64) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// Content of a polygon-like record (type 3, 5, 13, 15, 23, 25): type, bbox (zeros: readers
/// must not depend on it), NumParts, NumPoints, part starts, x y pairs; for the Z types a Z
/// range and one Z per point (value 7), for the M types an M range and one M per point (9).
/// Rings are written as given (the caller closes them). `pad` zero bytes are appended.
fn poly_content(shape_type: i32, rings: &[Vec<(f64, f64)>], pad: usize) -> Vec<u8> {
    let n: usize = rings.iter().map(Vec::len).sum();
    let mut c = Vec::new();
    le(&mut c, shape_type);
    for _ in 0..4 {
        f(&mut c, 0.0);
    }
    le(&mut c, rings.len() as i32);
    le(&mut c, n as i32);
    let mut start = 0;
    for r in rings {
        le(&mut c, start);
        start += r.len() as i32;
    }
    for &(x, y) in rings.iter().flatten() {
        f(&mut c, x);
        f(&mut c, y);
    }
    let extra = |c: &mut Vec<u8>, v: f64| {
        f(c, v);
        f(c, v);
        for _ in 0..n {
            f(c, v);
        }
    };
    if matches!(shape_type, 13 | 15) {
        extra(&mut c, 7.0);
    }
    if matches!(shape_type, 13 | 15 | 23 | 25) {
        extra(&mut c, 9.0);
    }
    c.extend(vec![0u8; pad]);
    c
}

fn null_content() -> Vec<u8> {
    0i32.to_le_bytes().to_vec()
}

/// A whole `.shp` file: header with the true length, then one record per content.
fn shp_file(header_type: i32, contents: &[Vec<u8>]) -> Vec<u8> {
    let len: usize = 100 + contents.iter().map(|c| 8 + c.len()).sum::<usize>();
    let mut b = Vec::new();
    be(&mut b, 9994);
    b.extend_from_slice(&[0u8; 20]);
    be(&mut b, (len / 2) as i32);
    le(&mut b, 1000);
    le(&mut b, header_type);
    for _ in 0..8 {
        f(&mut b, 0.0);
    }
    assert_eq!(b.len(), 100);
    for (k, c) in contents.iter().enumerate() {
        assert_eq!(c.len() % 2, 0, "contents are whole 16-bit words");
        be(&mut b, k as i32 + 1);
        be(&mut b, (c.len() / 2) as i32);
        b.extend_from_slice(c);
    }
    b
}

/// Closes a ring (repeats the first point).
fn closed(v: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p = v.to_vec();
    p.push(v[0]);
    p
}

fn pts(v: &[(f64, f64)]) -> Vec<DVec2> {
    v.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

fn point_set(v: &[DVec2]) -> Vec<[u64; 2]> {
    let mut b: Vec<[u64; 2]> = v.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect();
    b.sort();
    b
}

/// ESRI orientation: outer rings clockwise, holes counter-clockwise.
const SQUARE: [(f64, f64); 4] = [(0., 0.), (0., 10.), (10., 10.), (10., 0.)];
const HOLE: [(f64, f64); 4] = [(4., 4.), (6., 4.), (6., 6.), (4., 6.)];
const TRI: [(f64, f64); 3] = [(20., 0.), (20., 1.), (21., 0.)];
const FAR_HOLE: [(f64, f64); 4] = [(31., 1.), (32., 1.), (32., 2.), (31., 2.)];
const FAR: [(f64, f64); 4] = [(30., 0.), (30., 5.), (35., 5.), (35., 0.)];

/// Two polygon shapes: shape 0 a 10 × 10 square with a 2 × 2 hole, shape 1 a small triangle,
/// then a hole, then a second outer ring containing that hole (listed *after* it, to check
/// containment-based assignment).
fn test_file() -> Vec<u8> {
    shp_file(
        5,
        &[
            poly_content(5, &[closed(&SQUARE), closed(&HOLE)], 0),
            poly_content(5, &[closed(&TRI), closed(&FAR_HOLE), closed(&FAR)], 0),
        ],
    )
}

fn malformed_at(r: Result<Vec<PolygonRings>, IoError>) -> (u64, String) {
    match r {
        Err(IoError::MalformedBinary {
            offset, message, ..
        }) => (offset, message),
        other => panic!("expected MalformedBinary, got {other:?}"),
    }
}

#[test]
fn polygons_assembled_by_hand_load_as_regions() {
    let dir = Scratch::new("shp");
    let p = dir.path("regions.shp");
    std::fs::write(&p, test_file()).unwrap();
    let parts = read_shapefile_parts(&p).unwrap();
    assert_eq!(parts.len(), 3);
    assert_eq!(
        parts[0].outer,
        pts(&SQUARE),
        "opened, file orientation kept"
    );
    assert_eq!(parts[0].holes, vec![pts(&HOLE)]);
    assert_eq!(
        parts[1].holes.len(),
        0,
        "the far hole is not inside the triangle"
    );
    assert_eq!(parts[2].holes, vec![pts(&FAR_HOLE)]);
    assert_eq!(parts[2].json_path, "shape 1");
    assert_eq!(
        parts.iter().map(|p| p.part).collect::<Vec<_>>(),
        vec![0, 1, 2]
    );

    // Default: the largest part, the square with its hole.
    let r = read_region_shapefile(&p, PartSelector::Largest).unwrap();
    assert_eq!(r.area(), 100.0 - 4.0);
    assert!(
        r.outer().signed_area() > 0.0,
        "outer normalised to counter-clockwise"
    );
    assert!(
        r.holes()[0].signed_area() < 0.0,
        "hole normalised to clockwise"
    );
    assert_eq!(point_set(r.holes()[0].points()), point_set(&pts(&HOLE)));
    let r = read_region_shapefile(&p, PartSelector::Index(2)).unwrap();
    assert_eq!(r.area(), 25.0 - 1.0);
    let e = read_region_shapefile(&p, PartSelector::Index(3)).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::PartOutOfRange {
                index: 3,
                parts: 3,
                ..
            }
        ),
        "{e}"
    );
}

/// `PolygonZ` (with and without the optional `M` block: type 15 content as written by
/// `poly_content` has both) and `PolygonM` read the same `x y` as `Polygon`; null shapes and
/// polylines are skipped, and padding after a record's data is skipped by the declared length.
#[test]
fn z_m_null_polyline_and_padding() {
    let sq = closed(&SQUARE);
    let file = shp_file(
        15,
        &[
            null_content(),
            poly_content(3, &[vec![(0., 0.), (1., 1.)]], 0),
            poly_content(15, std::slice::from_ref(&sq), 0),
            poly_content(25, std::slice::from_ref(&sq), 6),
            poly_content(5, std::slice::from_ref(&sq), 10),
        ],
    );
    let parts = parse_shapefile_parts(&file).unwrap();
    assert_eq!(parts.len(), 3);
    for (k, p) in parts.iter().enumerate() {
        assert_eq!(p.outer, pts(&SQUARE));
        assert_eq!(p.json_path, format!("shape {}", k + 2));
    }
    // PolygonZ without M: the content ends after the Z array (44 + 4 + 16·5 + 16 + 8·5 bytes)
    let mut c = poly_content(5, std::slice::from_ref(&sq), 0);
    c[..4].copy_from_slice(&15i32.to_le_bytes());
    for v in [0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0] {
        f(&mut c, v);
    }
    assert_eq!(c.len(), 44 + 4 + 16 * 5 + 16 + 8 * 5);
    let parts = parse_shapefile_parts(&shp_file(15, &[c])).unwrap();
    assert_eq!(parts[0].outer, pts(&SQUARE));
}

#[test]
fn our_writer_round_trips() {
    let dir = Scratch::new("shp-rt");
    let r = Region::new(
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 0.1),
            DVec2::new(2.5, 2.0),
            DVec2::new(0.2, 1.0 / 3.0 + 1.0),
        ],
        vec![vec![
            DVec2::new(1.0, 0.5),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.5, 0.75),
        ]],
    )
    .unwrap();
    let p = dir.path("r.shp");
    write_region_shapefile(&p, &r).unwrap();
    assert_eq!(dir.entries(), vec!["r.shp", "r.shx"]);
    let back = read_region_shapefile(&p, PartSelector::Largest).unwrap();
    assert_eq!(back.area(), r.area());
    assert_eq!(
        point_set(back.outer().points()),
        point_set(r.outer().points())
    );
    assert_eq!(
        point_set(back.holes()[0].points()),
        point_set(r.holes()[0].points())
    );
    // The raw file keeps the ESRI orientation: outer clockwise, hole counter-clockwise.
    let parts = read_shapefile_parts(&p).unwrap();
    let area2 = |o: &[DVec2]| -> f64 {
        (0..o.len())
            .map(|k| o[k].perp_dot(o[(k + 1) % o.len()]))
            .sum()
    };
    assert!(area2(&parts[0].outer) < 0.0);
    assert!(area2(&parts[0].holes[0]) > 0.0);

    // Byte layout: 2 rings closed = 5 + 4 = 9 points; content 44 + 4·2 + 16·9 = 196 bytes
    // = 98 words; file 100 + 8 + 196 = 304 bytes = 152 words; index 108 bytes = 54 words.
    let shp = std::fs::read(&p).unwrap();
    assert_eq!(shp.len(), 304);
    assert_eq!(shp[0..4], 9994i32.to_be_bytes());
    assert_eq!(shp[24..28], 152i32.to_be_bytes());
    assert_eq!(shp[28..32], 1000i32.to_le_bytes());
    assert_eq!(shp[32..36], 5i32.to_le_bytes());
    // header bbox = the region's: x in [0, 3] (vertices (0, 0), (3, 0.1)), y in [0, 2]
    // (vertices (0, 0), (2.5, 2))
    assert_eq!(shp[36..44], 0.0f64.to_le_bytes());
    assert_eq!(shp[52..60], 3.0f64.to_le_bytes());
    assert_eq!(shp[60..68], 2.0f64.to_le_bytes());
    assert_eq!(shp[100..104], 1i32.to_be_bytes(), "record number 1");
    assert_eq!(shp[104..108], 98i32.to_be_bytes());
    assert_eq!(shp[144..148], 2i32.to_le_bytes(), "NumParts");
    assert_eq!(shp[148..152], 9i32.to_le_bytes(), "NumPoints");
    assert_eq!(shp[152..156], 0i32.to_le_bytes());
    assert_eq!(
        shp[156..160],
        5i32.to_le_bytes(),
        "hole starts after 5 points"
    );
    let shx = std::fs::read(dir.path("r.shx")).unwrap();
    assert_eq!(shx.len(), 108);
    assert_eq!(shx[24..28], 54i32.to_be_bytes());
    assert_eq!(shx[100..104], 50i32.to_be_bytes(), "record at word 50");
    assert_eq!(shx[104..108], 98i32.to_be_bytes());
}

#[test]
fn errors_and_truncation() {
    let dir = Scratch::new("shp-bad");
    let p = dir.path("lines.shp");
    std::fs::write(
        &p,
        shp_file(3, &[poly_content(3, &[vec![(0., 0.), (1., 1.)]], 0)]),
    )
    .unwrap();
    let e = read_region_shapefile(&p, PartSelector::Largest).unwrap_err();
    match &e {
        IoError::NoPolygon { found, .. } => assert_eq!(found, &["Polyline"]),
        _ => panic!("{e}"),
    }

    let q = dir.path("not.shp");
    std::fs::write(&q, "this is not a shapefile at all, but long enough to have a header ......................................................................................").unwrap();
    assert!(matches!(
        read_shapefile_parts(&q),
        Err(IoError::Shapefile { .. })
    ));

    let bytes = test_file();
    let t = dir.path("trunc.shp");
    for k in 0..bytes.len() {
        std::fs::write(&t, &bytes[..k]).unwrap();
        let e = read_region_shapefile(&t, PartSelector::Largest).unwrap_err();
        assert!(
            matches!(e, IoError::MalformedBinary { .. }),
            "prefix {k}: {e}"
        );
    }
    assert!(matches!(
        read_region_shapefile(dir.path("missing.shp"), PartSelector::Largest),
        Err(IoError::Io { .. })
    ));
}

/// Offsets in the one-record file `shp_file(5, [square])`: record header at 100 (number
/// 100..104, content length 104..108), content from 108: type 108, bbox 112..144, NumParts
/// 144, NumPoints 148, part starts from 152, points from 156. The square has 5 points (closed),
/// so the content is 44 + 4 + 80 = 128 bytes and the file 236 bytes.
fn one_square() -> Vec<u8> {
    let b = shp_file(5, &[poly_content(5, &[closed(&SQUARE)], 0)]);
    assert_eq!(b.len(), 236);
    b
}

#[test]
fn lying_and_truncated_headers_have_exact_offsets() {
    let good = one_square();
    assert_eq!(parse_shapefile_parts(&good).unwrap().len(), 1);

    // shorter than the header
    let (off, _) = malformed_at(parse_shapefile_parts(&good[..60]));
    assert_eq!(off, 60);
    // declared file length below the header size (40 words = 80 bytes)
    let mut b = good.clone();
    b[24..28].copy_from_slice(&40i32.to_be_bytes());
    assert_eq!(malformed_at(parse_shapefile_parts(&b)).0, 24);
    // declared length 2 bytes longer than the file: the file ends after the record, the next
    // record header (at 236) does not fit in the file
    let mut b = good.clone();
    b[24..28].copy_from_slice(&119i32.to_be_bytes());
    let (off, msg) = malformed_at(parse_shapefile_parts(&b));
    assert_eq!(off, 236, "{msg}");
    assert!(msg.contains("end of the file"), "{msg}");
    // declared length ends inside the record: its content runs past the declared length
    let mut b = good.clone();
    b[24..28].copy_from_slice(&110i32.to_be_bytes());
    let (off, msg) = malformed_at(parse_shapefile_parts(&b));
    assert_eq!(off, 104, "{msg}");
    assert!(msg.contains("declared in the header"), "{msg}");
    // declared length shorter than the file: trailing bytes are ignored
    let mut b = good.clone();
    b.extend_from_slice(&[0xff; 30]);
    assert_eq!(parse_shapefile_parts(&b).unwrap()[0].outer, pts(&SQUARE));
    // unknown shape type in the header / in the record
    let mut b = good.clone();
    b[32..36].copy_from_slice(&7i32.to_le_bytes());
    assert_eq!(malformed_at(parse_shapefile_parts(&b)).0, 32);
    let mut b = good.clone();
    b[108..112].copy_from_slice(&(-5i32).to_le_bytes());
    assert_eq!(malformed_at(parse_shapefile_parts(&b)).0, 108);
    // negative content length
    let mut b = good.clone();
    b[104..108].copy_from_slice(&(-1i32).to_be_bytes());
    assert_eq!(malformed_at(parse_shapefile_parts(&b)).0, 104);
    // content length smaller than the polygon's fixed fields (20 words = 40 bytes < 44);
    // the rest of the old content is then read as a record header, but we stop first
    let mut b = good.clone();
    b[104..108].copy_from_slice(&20i32.to_be_bytes());
    let (off, msg) = malformed_at(parse_shapefile_parts(&b));
    assert_eq!(off, 104, "{msg}");
    assert!(msg.contains("too short"), "{msg}");
}

#[test]
fn lying_counts_are_rejected_before_allocation() {
    let good = one_square();
    let with = |at: usize, v: i32| {
        let mut b = good.clone();
        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        parse_shapefile_parts(&b)
    };
    // NumParts / NumPoints negative
    assert_eq!(malformed_at(with(144, -1)).0, 144);
    assert_eq!(malformed_at(with(148, -1)).0, 148);
    // 2³¹ − 1 points would need 32 GiB: reported at NumParts (the counts' offset) with the
    // needed size 44 + 4·1 + 16·(2³¹ − 1) = 34359738400 bytes
    let (off, msg) = malformed_at(with(148, i32::MAX));
    assert_eq!(off, 144);
    assert!(msg.contains("34359738400"), "{msg}");
    // one point more than the record holds: 44 + 4 + 16·6 = 144 > 128
    let (_, msg) = malformed_at(with(148, 6));
    assert!(msg.contains("need 144 bytes, the record has 128"), "{msg}");
    // one point fewer is fine (trailing bytes of the record are skipped): a 4-point ring
    let parts = parse_shapefile_parts(&{
        let mut b = good.clone();
        b[148..152].copy_from_slice(&4i32.to_le_bytes());
        b
    })
    .unwrap();
    assert_eq!(parts[0].outer, pts(&SQUARE));
    // first part index not 0
    let (off, msg) = malformed_at(with(152, 1));
    assert_eq!(off, 152);
    assert!(msg.contains("part 0"), "{msg}");
}

#[test]
fn part_indices_must_be_ordered_and_in_range() {
    // two rings: square (5 points) and hole (5 points); part starts at 152 and 156
    let b = shp_file(5, &[poly_content(5, &[closed(&SQUARE), closed(&HOLE)], 0)]);
    assert_eq!(parse_shapefile_parts(&b).unwrap()[0].holes.len(), 1);
    let with = |v: i32| {
        let mut c = b.clone();
        c[156..160].copy_from_slice(&v.to_le_bytes());
        parse_shapefile_parts(&c)
    };
    // beyond NumPoints = 10
    let (off, msg) = malformed_at(with(11));
    assert_eq!(off, 156);
    assert!(
        msg.contains("part 1 starts at point 11, expected 0..=10"),
        "{msg}"
    );
    assert_eq!(malformed_at(with(-3)).0, 156);
    // = NumPoints: an empty last ring; it is kept (a zero-area ring counts as outer) and
    // region validation rejects it later, not the reader
    let parts = with(10).unwrap();
    assert_eq!(parts.len(), 2);
    assert!(parts[1].outer.is_empty());
}

#[test]
fn null_shape_must_be_four_bytes() {
    let mut content = null_content();
    content.extend_from_slice(&[0; 4]);
    let b = shp_file(5, &[content, poly_content(5, &[closed(&SQUARE)], 0)]);
    let (off, msg) = malformed_at(parse_shapefile_parts(&b));
    assert_eq!(off, 104, "{msg}");
    // a file of null shapes only has no polygon
    let b = shp_file(5, &[null_content(), null_content()]);
    assert!(matches!(
        parse_shapefile_parts(&b),
        Err(IoError::NoPolygon { found, .. }) if found.is_empty()
    ));
}

/// A shape made only of counter-clockwise rings (holes, in ESRI terms) gives one part per
/// ring; a region read from it is normalised to counter-clockwise.
#[test]
fn shape_of_holes_only() {
    let b = shp_file(
        5,
        &[poly_content(5, &[closed(&HOLE), closed(&FAR_HOLE)], 0)],
    );
    let parts = parse_shapefile_parts(&b).unwrap();
    assert_eq!(parts.len(), 2);
    assert_eq!(parts[1].outer, pts(&FAR_HOLE));
    assert_eq!(parts[1].part, 1);
}

/// Non-finite coordinates are read as they are; region validation reports them.
#[test]
fn non_finite_coordinates_reach_region_validation() {
    let mut sq = closed(&SQUARE);
    sq[2].0 = f64::NAN;
    let dir = Scratch::new("shp-nan");
    let p = dir.path("nan.shp");
    std::fs::write(&p, shp_file(5, &[poly_content(5, &[sq], 0)])).unwrap();
    let e = read_region_shapefile(&p, PartSelector::Index(0)).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::Geometry {
                source: unamalla_mesh::GeometryError::NonFinite { .. },
                ..
            }
        ),
        "{e}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    /// Any byte overwritten in a valid two-shape file, and any truncation: no panic, and a
    /// successful read never yields more points than the file has 16-byte pairs (no count is
    /// trusted beyond the bytes present).
    #[test]
    fn mutated_files_never_panic(
        edits in proptest::collection::vec((0usize..400, any::<u8>()), 1..8),
        cut in 0usize..400,
    ) {
        let mut b = test_file();
        let n = b.len();
        for (at, v) in edits {
            b[at % n] = v;
        }
        b.truncate(cut.max(n / 2));
        if let Ok(parts) = parse_shapefile_parts(&b) {
            let points: usize = parts.iter().map(PolygonRings::num_vertices).sum();
            prop_assert!(points * 16 <= b.len());
        }
    }
}

/// In-memory encoding round-trips far from the origin: a 6 × 4 rectangle with a 1 × 1 hole
/// offset to (10¹², 10¹²) (coordinates exact in binary: 10¹² + small integers < 2⁵³). The
/// outer ring is written clockwise and the hole counter-clockwise (decided exactly by
/// `orient2d`, the same test the reader uses), so the file reads back as one part with one
/// hole and the same points; area 24 − 1 = 23.
#[test]
fn encoded_bytes_round_trip_far_from_the_origin() {
    let o = 1e12;
    let q = |x: f64, y: f64| DVec2::new(o + x, o + y);
    let r = Region::new(
        vec![q(0., 0.), q(6., 0.), q(6., 4.), q(0., 4.)],
        vec![vec![q(2., 2.), q(2., 3.), q(3., 3.), q(3., 2.)]],
    )
    .unwrap();
    let (shp, shx) = encode_region_shapefile(&r).unwrap();
    // 5 + 5 points, 2 parts: content 44 + 8 + 160 = 212 bytes, file 320 bytes; index 108
    assert_eq!(shp.len(), 320);
    assert_eq!(shx.len(), 108);
    let parts = parse_shapefile_parts(&shp).unwrap();
    assert_eq!(parts.len(), 1);
    assert_eq!(parts[0].holes.len(), 1);
    let back = Region::new(parts[0].outer.clone(), parts[0].holes.clone()).unwrap();
    assert_eq!(back.area(), 23.0);
    assert_eq!(
        point_set(back.outer().points()),
        point_set(r.outer().points())
    );
    assert_eq!(
        point_set(back.holes()[0].points()),
        point_set(r.holes()[0].points())
    );
}
