//! The overlay picture of an input region and its simplification.

use unamalla_mesh::svg::{Style, SvgCanvas};
use unamalla_mesh::{DVec2, Region};

/// An SVG (900 px wide) showing `original` (grey fill, dark grey outline) with `simplified`
/// drawn over it (red outline; vertices as red dots when it has at most 2000 of them), with a
/// caption giving both vertex counts.
pub fn overlay_svg(original: &Region, simplified: &Region) -> String {
    let (lo0, hi0) = original.bounding_box();
    let (lo1, hi1) = simplified.bounding_box();
    let (lo, hi) = (lo0.min(lo1), hi0.max(hi1));
    let pad = 0.06 * (hi - lo).max_element();
    let mut c = SvgCanvas::new(lo - DVec2::new(0.0, pad), hi, 900.0);
    let rings: Vec<&[DVec2]> = original.rings().map(|p| p.points()).collect();
    let mut base = Style::fill_stroke("#d9d9d9", "#555555", 1.0);
    base.fill_opacity = 0.8;
    c.polygon_with_holes(&rings, &base);
    for p in simplified.rings() {
        c.polygon(p.points(), &Style::stroke("#d62728", 1.5));
    }
    if simplified.num_vertices() <= 2000 {
        for p in simplified.rings() {
            for &v in p.points() {
                c.circle(v, 2.0, &Style::fill("#d62728"));
            }
        }
    }
    c.text(
        DVec2::new(0.5 * (lo.x + hi.x), lo.y - 0.5 * pad),
        &format!(
            "original: {} vertices (grey)   simplified: {} vertices (red)",
            original.num_vertices(),
            simplified.num_vertices()
        ),
        14.0,
        "#222222",
    );
    c.finish()
}
