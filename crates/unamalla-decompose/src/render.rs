//! SVG pictures of a decomposition: blocks coloured, cuts drawn, corners marked, block ids.

use unamalla_mesh::svg::{Style, SvgCanvas};
use unamalla_mesh::{DVec2, Region};

use crate::decomposition::Decomposition;
use crate::geom::centroid;

const PALETTE: [&str; 12] = [
    "#8dd3c7", "#ffffb3", "#bebada", "#fb8072", "#80b1d3", "#fdb462", "#b3de69", "#fccde5",
    "#d9d9d9", "#bc80bd", "#ccebc5", "#ffed6f",
];

impl Decomposition {
    /// An SVG picture (1200 px wide): blocks filled with a palette colour chosen so that
    /// neighbours differ where possible, region boundary in black, cuts in red, corners as
    /// blue dots (inserted triangle-block corners in orange), block ids at the blocks' centres.
    pub fn to_svg(&self, region: &Region) -> String {
        let (lo, hi) = region.bounding_box();
        let mut c = SvgCanvas::new(lo, hi, 1200.0);
        // greedy colouring of the adjacency graph
        let mut colour = vec![usize::MAX; self.blocks.len()];
        for b in &self.blocks {
            let used: Vec<usize> = self.neighbours(b.id).iter().map(|&n| colour[n]).collect();
            colour[b.id] = (0..PALETTE.len())
                .find(|k| !used.contains(k))
                .unwrap_or(b.id % PALETTE.len());
        }
        for b in &self.blocks {
            let mut st = Style::fill_stroke(PALETTE[colour[b.id]], "#555555", 0.5);
            st.fill_opacity = 0.9;
            c.polygon(&b.ring, &st);
        }
        for ring in region.rings() {
            let mut pts = ring.points().to_vec();
            pts.push(pts[0]);
            c.polyline(&pts, &Style::stroke("black", 1.2));
        }
        for cut in &self.cuts {
            c.polyline(&[cut.a, cut.b], &Style::stroke("#d62728", 1.6));
        }
        for b in &self.blocks {
            for &k in &b.corners {
                let colour = if b.triangle { "#ff7f0e" } else { "#1f3fb4" };
                c.circle(b.ring[k], 2.5, &Style::fill(colour));
            }
        }
        for b in &self.blocks {
            let at = label_point(&b.ring);
            c.text(at, &b.id.to_string(), 11.0, "black");
        }
        c.finish()
    }
}

/// A point inside the block for its label: the centroid if inside, else the midpoint of the
/// longest horizontal chord through the centroid's height.
fn label_point(ring: &[DVec2]) -> DVec2 {
    let c = centroid(ring);
    if unamalla_mesh::geometry::locate_in_ring(ring, c) == unamalla_mesh::Location::Inside {
        return c;
    }
    let n = ring.len();
    let mut xs = Vec::new();
    for k in 0..n {
        let a = ring[k];
        let b = ring[(k + 1) % n];
        if (a.y <= c.y) != (b.y <= c.y) {
            xs.push(a.x + (c.y - a.y) / (b.y - a.y) * (b.x - a.x));
        }
    }
    xs.sort_by(f64::total_cmp);
    let best = xs
        .chunks(2)
        .filter(|p| p.len() == 2)
        .max_by(|p, q| (p[1] - p[0]).total_cmp(&(q[1] - q[0])));
    match best {
        Some(p) => DVec2::new(0.5 * (p[0] + p[1]), c.y),
        None => ring[0],
    }
}
