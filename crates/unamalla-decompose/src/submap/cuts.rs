//! Step 7: recursive decomposition by cut lines from Corner / Reversal nodes, shortest in
//! computational space ([Ruiz-Gironés & Sarrate, Fig 6]; taking the shortest over the whole piece,
//! the tie-break and the placement of the cut nodes are ours, the paper leaves them open).

use std::collections::HashMap;

use unamalla_compat_ilp::VertexKind;
use unamalla_mesh::DVec2;

use super::comp::Occ;
use super::{dir_step, CutLine, EdgeTag, NodeKind, Piece, SubmapError};

/// `Z_4` code of a unit step.
fn code_of(d: [i64; 2]) -> Option<i64> {
    match d {
        [1, 0] => Some(0),
        [0, 1] => Some(1),
        [-1, 0] => Some(2),
        [0, -1] => Some(3),
        _ => None,
    }
}

/// Per occurrence: outgoing direction code and interior angle in quarter turns (1..=4).
pub(crate) fn angles(lp: &[Occ]) -> Vec<(i64, i64)> {
    let n = lp.len();
    let out: Vec<i64> = (0..n)
        .map(|k| {
            let a = lp[k].c;
            let b = lp[(k + 1) % n].c;
            code_of([b[0] - a[0], b[1] - a[1]]).unwrap_or(0)
        })
        .collect();
    (0..n)
        .map(|k| {
            let d_in = out[(k + n - 1) % n];
            let s = (d_in + 2 - out[k]).rem_euclid(4);
            (out[k], if s == 0 { 4 } else { s })
        })
        .collect()
}

/// Direction `v` points strictly into the interior angle `(d_out, s)`.
fn strictly_inside(v: i64, d_out: i64, s: i64) -> bool {
    let t = (v - d_out).rem_euclid(4);
    t > 0 && t < s
}

struct Candidate {
    len: i64,
    phys: f64,
    p: usize,
    q: usize,
    dir: i64,
}

/// The best (shortest) cut of a piece, if it has a concave node; `Err` if a concave node exists
/// but no ray reaches the boundary from the inside.
fn best_cut(lp: &[Occ], nodes: &[DVec2]) -> Result<Option<Candidate>, SubmapError> {
    let ang = angles(lp);
    let concave: Vec<usize> = (0..lp.len()).filter(|&k| ang[k].1 >= 3).collect();
    if concave.is_empty() {
        return Ok(None);
    }
    let mut at: HashMap<[i64; 2], Vec<usize>> = HashMap::new();
    let (mut lo, mut hi) = ([i64::MAX; 2], [i64::MIN; 2]);
    for (k, o) in lp.iter().enumerate() {
        at.entry(o.c).or_default().push(k);
        for a in 0..2 {
            lo[a] = lo[a].min(o.c[a]);
            hi[a] = hi[a].max(o.c[a]);
        }
    }
    let limit = (hi[0] - lo[0]).max(hi[1] - lo[1]) + 1;
    let mut best: Option<Candidate> = None;
    for &p in &concave {
        let (d_out, s) = ang[p];
        for t in 1..s {
            let dir = (d_out + t).rem_euclid(4);
            let st = dir_step(dir);
            let back = (dir + 2).rem_euclid(4);
            for step in 1..=limit {
                let c = [lp[p].c[0] + step * st[0], lp[p].c[1] + step * st[1]];
                let Some(hits) = at.get(&c) else { continue };
                let q = hits
                    .iter()
                    .copied()
                    .find(|&q| q != p && strictly_inside(back, ang[q].0, ang[q].1));
                if let Some(q) = q {
                    let cand = Candidate {
                        len: step,
                        phys: nodes[lp[p].id].distance(nodes[lp[q].id]),
                        p,
                        q,
                        dir,
                    };
                    let better = match &best {
                        None => true,
                        Some(b) => {
                            (cand.len, cand.phys, cand.p, cand.dir)
                                .partial_cmp(&(b.len, b.phys, b.p, b.dir))
                                == Some(std::cmp::Ordering::Less)
                        }
                    };
                    if better {
                        best = Some(cand);
                    }
                }
                break;
            }
        }
    }
    match best {
        Some(b) => Ok(Some(b)),
        None => {
            let x = nodes[lp[concave[0]].id];
            Err(SubmapError::NoCut { x: x.x, y: x.y })
        }
    }
}

/// Splits pieces until every one is a computational rectangle; returns the pieces and the cuts.
pub(crate) fn decompose(
    start: Vec<Occ>,
    nodes: &mut Vec<DVec2>,
    kinds: &mut Vec<NodeKind>,
    max_pieces: usize,
) -> Result<(Vec<Piece>, Vec<CutLine>), SubmapError> {
    let mut stack = vec![start];
    let mut done: Vec<Vec<Occ>> = Vec::new();
    let mut cuts: Vec<CutLine> = Vec::new();
    while let Some(lp) = stack.pop() {
        if done.len() + stack.len() >= max_pieces {
            return Err(SubmapError::TooManyPieces(max_pieces));
        }
        let Some(cut) = best_cut(&lp, nodes)? else {
            done.push(lp);
            continue;
        };
        let n = lp.len();
        let cid = cuts.len();
        let (p, q) = (lp[cut.p], lp[cut.q]);
        let st = dir_step(cut.dir);
        let (xp, xq) = (nodes[p.id], nodes[q.id]);
        let mut inner: Vec<Occ> = Vec::new();
        for t in 1..cut.len {
            nodes.push(xp.lerp(xq, t as f64 / cut.len as f64));
            kinds.push(NodeKind::Cut);
            inner.push(Occ {
                id: nodes.len() - 1,
                c: [p.c[0] + t * st[0], p.c[1] + t * st[1]],
                tag: EdgeTag::Cut(cid),
            });
        }
        let ang_p = angles(&lp)[cut.p].1;
        cuts.push(CutLine {
            nodes: std::iter::once(p.id)
                .chain(inner.iter().map(|o| o.id))
                .chain(std::iter::once(q.id))
                .collect(),
            length: cut.len as usize,
            from: if ang_p == 4 {
                VertexKind::Reversal
            } else {
                VertexKind::Corner
            },
        });
        // piece A: p → … → q, then the cut back to p
        let mut a: Vec<Occ> = Vec::new();
        let mut k = cut.p;
        loop {
            a.push(lp[k]);
            if k == cut.q {
                break;
            }
            k = (k + 1) % n;
        }
        if let Some(last) = a.last_mut() {
            last.tag = EdgeTag::Cut(cid);
        }
        a.extend(inner.iter().rev().copied());
        // piece B: q → … → p, then the cut to q
        let mut b: Vec<Occ> = Vec::new();
        let mut k = cut.q;
        loop {
            b.push(lp[k]);
            if k == cut.p {
                break;
            }
            k = (k + 1) % n;
        }
        if let Some(last) = b.last_mut() {
            last.tag = EdgeTag::Cut(cid);
        }
        b.extend(inner.iter().copied());
        stack.push(b);
        stack.push(a);
    }
    let mut pieces = Vec::with_capacity(done.len());
    for (idx, lp) in done.into_iter().enumerate() {
        pieces.push(to_piece(idx, lp)?);
    }
    Ok((pieces, cuts))
}

/// A loop without concave nodes → four sides (bottom-left corner = the End whose outgoing edge is
/// `+i`).
fn to_piece(idx: usize, mut lp: Vec<Occ>) -> Result<Piece, SubmapError> {
    let ang = angles(&lp);
    let ends: Vec<usize> = (0..lp.len()).filter(|&k| ang[k].1 == 1).collect();
    let bl = ends.iter().copied().find(|&k| ang[k].0 == 0);
    let (4, Some(bl)) = (ends.len(), bl) else {
        return Err(SubmapError::NotRectangle {
            piece: idx,
            ends: ends.len(),
        });
    };
    lp.rotate_left(bl);
    let n = lp.len();
    let ang = angles(&lp);
    let corners: Vec<usize> = (0..n).filter(|&k| ang[k].1 == 1).collect();
    let run =
        |from: usize, to: usize| -> Vec<usize> { (from..=to).map(|k| lp[k % n].id).collect() };
    let bottom = run(corners[0], corners[1]);
    let right = run(corners[1], corners[2]);
    let mut top = run(corners[2], corners[3]);
    top.reverse();
    let mut left = run(corners[3], n);
    left.reverse();
    if bottom.len() != top.len() || left.len() != right.len() {
        return Err(SubmapError::NotRectangle {
            piece: idx,
            ends: 4,
        });
    }
    Ok(Piece {
        sides: [bottom, right, top, left],
        boundary: lp.iter().map(|o| o.id).collect(),
        tags: lp.iter().map(|o| o.tag).collect(),
        origin: lp[0].c,
    })
}
