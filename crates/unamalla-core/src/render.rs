//! Pictures of meshes: each cell coloured by the "rectangles 2015" measure μ, as in the thesis
//! ([Méndez 2023, §2.2]): blue μ ≥ 0.8, orange 0.4 ≤ μ < 0.8, red μ < 0.4 (non-convex cells
//! have μ ≤ 0 and are red) — or, for a nodal field such as a PDE solution ([`field_png`],
//! [`field_svg`]), by a continuous colour scale ([`field_color`]). SVG through
//! [`unamalla_mesh::svg`], PNG rasterized with `tiny-skia` (pure Rust) and encoded by its PNG
//! writer; both kinds share one drawing routine per format.

use unamalla_mesh::quality::mu;
use unamalla_mesh::svg::{Style, SvgCanvas};
use unamalla_mesh::{DVec2, HasQuadCells, Region};

/// Why a picture could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// A nodal field has the wrong length.
    #[error("a nodal field needs one value per node: {values} values for {nodes} nodes")]
    FieldLength {
        /// Values given.
        values: usize,
        /// Nodes of the mesh.
        nodes: usize,
    },
    /// A nodal field value is NaN or infinite.
    #[error("the nodal field is not finite at node {node}")]
    FieldNotFinite {
        /// The first such node.
        node: usize,
    },
    /// The picture would be empty or too large for the rasterizer.
    #[error("image size out of range")]
    ImageSize,
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
}

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
    cells_svg(mesh, region, width_px, &|_, q| mu_color(mu(q)))
}

/// The colour of `t ∈ [0, 1]` on a blue → green → yellow scale (piecewise-linear through five
/// stops of matplotlib's *viridis*, perceptually ordered and readable in grey); `t` outside
/// `[0, 1]` is clamped, NaN gives the low end.
pub fn field_color(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * 4.0;
    let k = (x.floor() as usize).min(3);
    let f = x - k as f64;
    std::array::from_fn(|c| (STOPS[k][c] * (1.0 - f) + STOPS[k + 1][c] * f).round() as u8)
}

/// Per-cell colours of a nodal field: each cell gets [`field_color`] of the mean of its four
/// node values, scaled so that the field's minimum is 0 and its maximum 1.
fn field_cell_colour(values: &[f64]) -> impl Fn(usize, &[DVec2; 4], [usize; 4]) -> [u8; 3] + '_ {
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = if hi > lo { hi - lo } else { 1.0 };
    move |_, _, ids| {
        let mean = ids.iter().map(|&k| values[k]).sum::<f64>() / 4.0;
        field_color((mean - lo) / span)
    }
}

fn check_field<M: HasQuadCells + ?Sized>(mesh: &M, values: &[f64]) -> Result<(), RenderError> {
    if values.len() != mesh.num_nodes() {
        return Err(RenderError::FieldLength {
            values: values.len(),
            nodes: mesh.num_nodes(),
        });
    }
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(RenderError::FieldNotFinite { node: k });
    }
    Ok(())
}

/// An SVG colour plot of a nodal field (e.g. a PDE solution) on a quad mesh: cells coloured
/// by [`field_color`] of the mean of their node values, min → dark blue, max → yellow.
pub fn field_svg<M: HasQuadCells + ?Sized>(
    mesh: &M,
    values: &[f64],
    region: Option<&Region>,
    width_px: f64,
) -> Result<String, RenderError> {
    check_field(mesh, values)?;
    let col = field_cell_colour(values);
    Ok(cells_svg(mesh, region, width_px, &|c, q| {
        col(c, q, mesh.quad(c))
    }))
}

/// A PNG colour plot of a nodal field (encoded bytes), `width_px` wide (see [`field_svg`]).
pub fn field_png<M: HasQuadCells + ?Sized>(
    mesh: &M,
    values: &[f64],
    region: Option<&Region>,
    width_px: u32,
) -> Result<Vec<u8>, RenderError> {
    check_field(mesh, values)?;
    let col = field_cell_colour(values);
    cells_png(mesh, region, width_px, &|c, q| col(c, q, mesh.quad(c)))
}

/// Cells filled with `colour(cell, points)`, edges when there are fewer than 40,000 cells,
/// region rings on top.
fn cells_svg<M: HasQuadCells + ?Sized>(
    mesh: &M,
    region: Option<&Region>,
    width_px: f64,
    colour: &dyn Fn(usize, &[DVec2; 4]) -> [u8; 3],
) -> String {
    let (lo, hi) = bounds(mesh);
    let mut c = SvgCanvas::new(lo, hi, width_px);
    let edges = mesh.num_quads() < 40_000;
    for k in 0..mesh.num_quads() {
        let q = mesh.quad_points(k);
        let col = hex(colour(k, &q));
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
) -> Result<Vec<u8>, RenderError> {
    cells_png(mesh, region, width_px, &|_, q| mu_color(mu(q)))
}

/// Rasterizes cells filled with `colour(cell, points)` (tiny-skia), edges when there are
/// fewer than 20,000 cells, region rings on top; returns the encoded PNG.
fn cells_png<M: HasQuadCells + ?Sized>(
    mesh: &M,
    region: Option<&Region>,
    width_px: u32,
    colour: &dyn Fn(usize, &[DVec2; 4]) -> [u8; 3],
) -> Result<Vec<u8>, RenderError> {
    use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};
    let (lo, hi) = bounds(mesh);
    let ext = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
    let margin = 10.0f64;
    let width = width_px.clamp(64, 8192) as f64;
    let scale = (width - 2.0 * margin) / ext.x.max(ext.y * 1e-3);
    let height = (ext.y * scale + 2.0 * margin).clamp(16.0, 16384.0);
    let mut pix = Pixmap::new(width as u32, height as u32).ok_or(RenderError::ImageSize)?;
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
        let [r, g, b] = colour(k, &q);
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
        .map_err(|e| RenderError::Png(e.to_string()))
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
    fn field_plot_colours_follow_the_values() {
        assert_eq!(field_color(0.0), [68, 1, 84]);
        assert_eq!(field_color(0.5), [33, 145, 140]);
        assert_eq!(field_color(1.0), [253, 231, 37]);
        assert_eq!(field_color(f64::NAN), [68, 1, 84]);
        // two unit cells, field u = x ∈ [0, 2]: the left cell's mean 0.5 maps to t = 0.25
        // (stop 1, #3b528b), the right cell's mean 1.5 to t = 0.75 (stop 3, #5ec962)
        let g = StructuredGrid2::from_fn(3, 2, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
        let u: Vec<f64> = (0..6).map(|k| (k % 3) as f64).collect();
        let svg = field_svg(&g, &u, None, 200.0).unwrap();
        assert!(svg.contains("#3b528b") && svg.contains("#5ec962"), "{svg}");
        let png = field_png(&g, &u, None, 200).unwrap();
        let pix = tiny_skia::Pixmap::decode_png(&png).unwrap();
        let scale = (200.0 - 20.0) / 2.0;
        let c = pix
            .pixel(
                (10.0 + 0.5 * scale) as u32,
                (pix.height() as f64 - 10.0 - 0.5 * scale) as u32,
            )
            .unwrap();
        assert_eq!([c.red(), c.green(), c.blue()], [59, 82, 139]);
        assert!(field_png(&g, &u[..5], None, 200).is_err());
        assert!(field_svg(&g, &[f64::NAN; 6], None, 200.0).is_err());
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
