//! Algorithm 4 ([Méndez 2023, §4.2.1]): a triangle cut off at a critical angle.

use super::Builder;
use crate::geom::ring_angle;
use crate::piece::{End, Piece, Pos, Tag};

impl Builder<'_> {
    /// Algorithm 4: cut a triangle around the sharpest critical angle.
    pub(super) fn critical_cut(&mut self, piece: &Piece) -> Option<(Piece, Piece, usize)> {
        let ring = &piece.outer;
        let n = ring.len();
        let theta = self.opts.tolerances.theta_minus;
        let mut acute: Vec<(f64, usize)> = (0..n)
            .map(|i| (ring_angle(&ring.pts, i), i))
            .filter(|x| x.0 < theta)
            .collect();
        acute.sort_by(|a, b| a.0.total_cmp(&b.0));
        let idx = piece.index();
        for (_, v) in acute {
            let ep = (v + n - 1) % n;
            if !matches!(ring.tags[ep], Tag::Boundary(_))
                || !matches!(ring.tags[v], Tag::Boundary(_))
            {
                continue;
            }
            let pv = ring.p(v);
            let prev = ring.prev(v);
            let next = ring.next(v);
            let mut d = 0.5 * pv.distance(prev).min(pv.distance(next));
            for _ in 0..4 {
                let p = pv + (prev - pv).normalize() * d;
                let q = pv + (next - pv).normalize() * d;
                let e1 = End {
                    ring: 0,
                    pos: Pos::OnEdge(ep, p),
                };
                let e2 = End {
                    ring: 0,
                    pos: Pos::OnEdge(v, q),
                };
                let tri_area = 0.5 * (pv - p).perp_dot(q - p).abs();
                if tri_area < self.min_triangle {
                    break;
                }
                if piece.admissible(&idx, e1, e2) {
                    let mut m = piece.clone();
                    let (x, y) = m.insert_ends(e1, e2);
                    let id = self.new_cut(m.outer.p(x), m.outer.p(y));
                    let (a, b) = m.split(x, y, id);
                    return Some((a, b, id));
                }
                d *= 0.5;
            }
        }
        None
    }
}
