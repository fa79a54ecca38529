//! A minimal SVG scene builder for pictures of regions, decompositions and meshes.
//!
//! World coordinates (the region's units, y up) are mapped to SVG pixels (y down) by a uniform
//! scale that fits the given bounding box into `width_px` with a margin. Every stage that draws
//! (simplification overlays, decompositions, quality maps) uses this one builder.

use std::fmt::Write as _;

use glam::DVec2;

/// Stroke and fill of a shape. Colours are any SVG colour string (`"#1f77b4"`, `"red"`, …).
#[derive(Debug, Clone, PartialEq)]
pub struct Style {
    /// Fill colour, `None` for no fill.
    pub fill: Option<String>,
    /// Stroke colour, `None` for no stroke.
    pub stroke: Option<String>,
    /// Stroke width in pixels.
    pub stroke_width_px: f64,
    /// Opacity of the fill in `[0, 1]`.
    pub fill_opacity: f64,
}

impl Style {
    /// A stroke-only style.
    pub fn stroke(color: &str, width_px: f64) -> Self {
        Self {
            fill: None,
            stroke: Some(color.to_string()),
            stroke_width_px: width_px,
            fill_opacity: 1.0,
        }
    }
    /// A fill-only style.
    pub fn fill(color: &str) -> Self {
        Self {
            fill: Some(color.to_string()),
            stroke: None,
            stroke_width_px: 0.0,
            fill_opacity: 1.0,
        }
    }
    /// A filled shape with an outline.
    pub fn fill_stroke(fill: &str, stroke: &str, width_px: f64) -> Self {
        Self {
            fill: Some(fill.to_string()),
            stroke: Some(stroke.to_string()),
            stroke_width_px: width_px,
            fill_opacity: 1.0,
        }
    }
    fn attrs(&self) -> String {
        let mut s = String::new();
        match &self.fill {
            Some(f) => {
                let _ = write!(s, r#" fill="{}""#, escape(f));
                if self.fill_opacity < 1.0 {
                    let _ = write!(s, r#" fill-opacity="{:.3}""#, self.fill_opacity);
                }
            }
            None => s.push_str(r#" fill="none""#),
        }
        if let Some(c) = &self.stroke {
            let _ = write!(
                s,
                r#" stroke="{}" stroke-width="{:.3}" stroke-linejoin="round""#,
                escape(c),
                self.stroke_width_px
            );
        }
        s
    }
}

/// An SVG document under construction.
#[derive(Debug, Clone)]
pub struct SvgCanvas {
    origin: DVec2,
    scale: f64,
    width: f64,
    height: f64,
    margin: f64,
    body: String,
}

impl SvgCanvas {
    /// A canvas showing the world box `[min, max]` in an image `width_px` pixels wide (the
    /// height follows the aspect ratio), with a 10-pixel margin. A degenerate box is widened
    /// to a unit square.
    pub fn new(min: DVec2, max: DVec2, width_px: f64) -> Self {
        let margin = 10.0;
        let ext = (max - min).max(DVec2::splat(f64::MIN_POSITIVE));
        let ext = if ext.max_element() > 0.0 && ext.is_finite() {
            ext
        } else {
            DVec2::ONE
        };
        let width_px = width_px.max(2.0 * margin + 1.0);
        let scale = (width_px - 2.0 * margin) / ext.x.max(ext.y * 1e-3);
        let height = (ext.y * scale + 2.0 * margin).min(20.0 * width_px);
        Self {
            origin: min,
            scale,
            width: width_px,
            height,
            margin,
            body: String::new(),
        }
    }

    /// Maps a world point to SVG pixel coordinates.
    pub fn to_px(&self, p: DVec2) -> DVec2 {
        DVec2::new(
            self.margin + (p.x - self.origin.x) * self.scale,
            self.height - self.margin - (p.y - self.origin.y) * self.scale,
        )
    }

    fn points_attr(&self, pts: &[DVec2]) -> String {
        let mut s = String::with_capacity(pts.len() * 16);
        for p in pts {
            let q = self.to_px(*p);
            let _ = write!(s, "{:.2},{:.2} ", q.x, q.y);
        }
        s
    }

    /// A closed polygon.
    pub fn polygon(&mut self, pts: &[DVec2], style: &Style) {
        let _ = writeln!(
            self.body,
            r#"<polygon points="{}"{}/>"#,
            self.points_attr(pts),
            style.attrs()
        );
    }

    /// A polygon with holes, filled with the even-odd rule (outer ring first).
    pub fn polygon_with_holes(&mut self, rings: &[&[DVec2]], style: &Style) {
        let mut d = String::new();
        for ring in rings {
            for (k, p) in ring.iter().enumerate() {
                let q = self.to_px(*p);
                let _ = write!(
                    d,
                    "{}{:.2},{:.2} ",
                    if k == 0 { "M" } else { "L" },
                    q.x,
                    q.y
                );
            }
            d.push_str("Z ");
        }
        let _ = writeln!(
            self.body,
            r#"<path d="{d}" fill-rule="evenodd"{}/>"#,
            style.attrs()
        );
    }

    /// An open polyline.
    pub fn polyline(&mut self, pts: &[DVec2], style: &Style) {
        let mut st = style.clone();
        st.fill = None;
        let _ = writeln!(
            self.body,
            r#"<polyline points="{}"{}/>"#,
            self.points_attr(pts),
            st.attrs()
        );
    }

    /// A circle of radius `r_px` pixels centred at world point `c`.
    pub fn circle(&mut self, c: DVec2, r_px: f64, style: &Style) {
        let q = self.to_px(c);
        let _ = writeln!(
            self.body,
            r#"<circle cx="{:.2}" cy="{:.2}" r="{:.2}"{}/>"#,
            q.x,
            q.y,
            r_px,
            style.attrs()
        );
    }

    /// Text centred at world point `at`.
    pub fn text(&mut self, at: DVec2, text: &str, size_px: f64, fill: &str) {
        let q = self.to_px(at);
        let _ = writeln!(
            self.body,
            r#"<text x="{:.2}" y="{:.2}" font-size="{:.1}" font-family="sans-serif" text-anchor="middle" dominant-baseline="middle" fill="{}">{}</text>"#,
            q.x,
            q.y,
            size_px,
            escape(fill),
            escape(text)
        );
    }

    /// The finished SVG document.
    pub fn finish(self) -> String {
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" viewBox=\"0 0 {w:.2} {h:.2}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n{}</svg>\n",
            self.body,
            w = self.width,
            h = self.height
        )
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_world_box_with_y_flipped() {
        let c = SvgCanvas::new(DVec2::new(0., 0.), DVec2::new(10., 5.), 120.0);
        // scale = (120 − 20)/10 = 10 px per unit; height = 5·10 + 20 = 70
        assert_eq!(c.to_px(DVec2::new(0., 0.)), DVec2::new(10., 60.));
        assert_eq!(c.to_px(DVec2::new(10., 5.)), DVec2::new(110., 10.));
        let mut c = c;
        c.polygon(
            &[DVec2::ZERO, DVec2::X, DVec2::Y],
            &Style::fill_stroke("blue", "black", 1.0),
        );
        c.text(DVec2::new(5., 2.), "a<b", 10.0, "red");
        let s = c.finish();
        assert!(s.starts_with("<svg"));
        assert!(s.contains(r#"points="10.00,60.00 20.00,60.00 10.00,50.00 ""#));
        assert!(s.contains("a&lt;b"));
        assert!(s.trim_end().ends_with("</svg>"));
    }
}
