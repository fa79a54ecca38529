//! Pictures of meshes: each cell coloured by the "rectangles 2015" measure μ, as in the thesis
//! (seed 000 digest §1.4): blue μ ≥ 0.8, orange 0.4 ≤ μ < 0.8, red μ < 0.4 (non-convex cells
//! have μ ≤ 0 and are red). SVG through [`unamalla_mesh::svg`], PNG rasterized with
//! `tiny-skia` (pure Rust) and encoded by its PNG writer.

use unamalla_mesh::quality::mu;
use unamalla_mesh::svg::{Style, SvgCanvas};
use unamalla_mesh::{DVec2, HasQuadCells, Region};

use crate::CoreError;

/// Colour of μ ≥ 0.8.
pub const BLUE: [u8; 3] = [0x1f, 0x77, 0xb4];
/// Colour of 0.4 ≤ μ < 0.8.
pub const ORANGE: [u8; 3] = [0xff, 0x7f, 0x0e];
/// Colour of μ < 0.4.
pub const RED: [u8; 3] = [0xd6, 0x27, 0x28];

/// The band colour of a μ value.
pub fn mu_color(m: f64) -> [u8; 3] {
    if m >= 0.8 {
        BLUE
    } else if m >= 0.4 {
        ORANGE
    } else {
        RED
    }
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

fn bounds<M: HasQuadCells + ?Sized>(mesh: &M) -> (DVec2, DVec2) {
    mesh.nodes().iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// An SVG quality map of a quad mesh, `width_px` wide; cell edges are drawn when there are
/// fewer than 40,000 cells; the region's rings (if given) are drawn on top in black.
pub fn quality_svg<M: HasQuadCells + ?Sized>(
    mesh: &M,
    region: Option<&Region>,
    width_px: f64,
) -> String {
    let (lo, hi) = bounds(mesh);
    let mut c = SvgCanvas::new(lo, hi, width_px);
    let edges = mesh.num_quads() < 40_000;
    for k in 0..mesh.num_quads() {
        let q = mesh.quad_points(k);
        let col = hex(mu_color(mu(&q)));
        let style = if edges {
            Style::fill_stroke(&col, "#333333", 0.2)
        } else {
            Style::fill(&col)
        };
        c.polygon(&q, &style);
    }
    if let Some(r) = region {
        for ring in r.rings() {
            let mut pts = ring.points().to_vec();
            pts.push(pts[0]);
            c.polyline(&pts, &Style::stroke("black", 1.0));
        }
    }
    c.finish()
}

/// A PNG quality map (encoded bytes), `width_px` wide.
pub fn quality_png<M: HasQuadCells + ?Sized>(
    mesh: &M,
    region: Option<&Region>,
    width_px: u32,
) -> Result<Vec<u8>, CoreError> {
    use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};
    let (lo, hi) = bounds(mesh);
    let ext = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
    let margin = 10.0f64;
    let width = width_px.clamp(64, 8192) as f64;
    let scale = (width - 2.0 * margin) / ext.x.max(ext.y * 1e-3);
    let height = (ext.y * scale + 2.0 * margin).clamp(16.0, 16384.0);
    let mut pix = Pixmap::new(width as u32, height as u32)
        .ok_or_else(|| CoreError::Unsupported("image size out of range".into()))?;
    pix.fill(Color::WHITE);
    let px = |p: DVec2| {
        (
            (margin + (p.x - lo.x) * scale) as f32,
            (height - margin - (p.y - lo.y) * scale) as f32,
        )
    };
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    let draw_edges = mesh.num_quads() < 20_000;
    let edge_stroke = Stroke {
        width: 0.4,
        ..Stroke::default()
    };
    for k in 0..mesh.num_quads() {
        let q = mesh.quad_points(k);
        let mut pb = PathBuilder::new();
        let (x, y) = px(q[0]);
        pb.move_to(x, y);
        for p in &q[1..] {
            let (x, y) = px(*p);
            pb.line_to(x, y);
        }
        pb.close();
        let Some(path) = pb.finish() else { continue };
        let [r, g, b] = mu_color(mu(&q));
        paint.set_color_rgba8(r, g, b, 255);
        pix.fill_path(
            &path,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        if draw_edges {
            paint.set_color_rgba8(40, 40, 40, 160);
            pix.stroke_path(&path, &paint, &edge_stroke, Transform::identity(), None);
        }
    }
    if let Some(reg) = region {
        paint.set_color_rgba8(0, 0, 0, 255);
        let st = Stroke {
            width: 1.2,
            ..Stroke::default()
        };
        for ring in reg.rings() {
            let mut pb = PathBuilder::new();
            for (i, p) in ring.points().iter().enumerate() {
                let (x, y) = px(*p);
                if i == 0 {
                    pb.move_to(x, y);
                } else {
                    pb.line_to(x, y);
                }
            }
            pb.close();
            if let Some(path) = pb.finish() {
                pix.stroke_path(&path, &paint, &st, Transform::identity(), None);
            }
        }
    }
    pix.encode_png()
        .map_err(|e| CoreError::Unsupported(format!("PNG encoding failed: {e}")))
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::StructuredGrid2;

    use super::*;

    #[test]
    fn band_colours() {
        assert_eq!(mu_color(1.0), BLUE);
        assert_eq!(mu_color(0.8), BLUE);
        assert_eq!(mu_color(0.5), ORANGE);
        assert_eq!(mu_color(0.1), RED);
        assert_eq!(mu_color(-1.0), RED);
    }

    #[test]
    fn rectangle_grid_is_all_blue() {
        let g =
            StructuredGrid2::from_fn(4, 3, |i, j| DVec2::new(i as f64, 0.5 * j as f64)).unwrap();
        let svg = quality_svg(&g, None, 200.0);
        assert_eq!(svg.matches("<polygon").count(), 6);
        assert_eq!(svg.matches("#1f77b4").count(), 6);
        let png = quality_png(&g, None, 200).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        // decode the centre pixel of the first cell: it must be blue
        let pix = tiny_skia::Pixmap::decode_png(&png).unwrap();
        let scale = (200.0 - 20.0) / 3.0;
        let x = (10.0 + 0.5 * scale) as u32;
        let y = (pix.height() as f64 - 10.0 - 0.25 * scale) as u32;
        let c = pix.pixel(x, y).unwrap();
        assert_eq!([c.red(), c.green(), c.blue()], BLUE);
    }
}
