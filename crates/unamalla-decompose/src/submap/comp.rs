//! Steps 4–6: edge classification, interval assignment ILP (3), boundary discretization and the
//! computational space ([Ruiz-Gironés & Sarrate, Fig 4, (2), (3), Fig 5]).

use std::collections::HashMap;

use unamalla_compat_ilp::{
    assign_intervals, Direction, IntervalEdge, IntervalOptions, IntervalProblem,
};
use unamalla_mesh::resample::{polyline_length, resample_arc_length};
use unamalla_mesh::DVec2;

use super::classify::{turning_angle, LPoint};
use super::{dir_step, CompEdge, EdgeTag, NodeKind, SubmapError, SubmapOptions};

/// One occurrence of a node on a boundary loop in computational space; `tag` is the unit edge
/// leaving it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Occ {
    pub id: usize,
    pub c: [i64; 2],
    pub tag: EdgeTag,
}

/// Output of [`build`].
pub(crate) struct Comp {
    pub edges: Vec<CompEdge>,
    pub objective: f64,
    pub nodes: Vec<DVec2>,
    pub node_kinds: Vec<NodeKind>,
    pub occurrences: Vec<Occ>,
}

/// Splits `n` intervals over pieces of lengths `lens` (each ≥ 1, `n ≥ lens.len()`), in proportion
/// to length (largest-remainder rounding).
fn distribute(n: usize, lens: &[f64]) -> Vec<usize> {
    let total: f64 = lens.iter().sum();
    let ideal: Vec<f64> = lens.iter().map(|l| n as f64 * l / total).collect();
    let mut k: Vec<usize> = ideal.iter().map(|x| (x.floor() as usize).max(1)).collect();
    loop {
        let s: usize = k.iter().sum();
        if s == n {
            break;
        }
        if s < n {
            let i = (0..k.len())
                .max_by(|&a, &b| (ideal[a] - k[a] as f64).total_cmp(&(ideal[b] - k[b] as f64)))
                .unwrap_or(0);
            k[i] += 1;
        } else {
            match (0..k.len())
                .filter(|&a| k[a] > 1)
                .max_by(|&a, &b| (k[a] as f64 - ideal[a]).total_cmp(&(k[b] as f64 - ideal[b])))
            {
                Some(i) => k[i] -= 1,
                None => break,
            }
        }
    }
    k
}

/// Edge classification, ILP (3), node placement and the computational walk.
pub(crate) fn build(mut points: Vec<LPoint>, options: &SubmapOptions) -> Result<Comp, SubmapError> {
    let sum: i64 = points.iter().map(|p| p.label).sum();
    if sum != 4 {
        return Err(SubmapError::Closure { sum });
    }
    let first = points
        .iter()
        .position(|p| p.label != 0 || p.brk)
        .ok_or(SubmapError::Closure { sum })?;
    points.rotate_left(first);
    let n = points.len();
    let breaks: Vec<usize> = (0..n)
        .filter(|&k| points[k].label != 0 || points[k].brk)
        .collect();
    let keep = options.keep_vertex_angle_deg.to_radians();

    // edges between consecutive breaks, directions by Z_4 propagation (first edge +i)
    struct Raw {
        from: usize,
        to: usize,
        subcurves: Vec<Vec<DVec2>>,
        length: f64,
        code: i64,
        tag: EdgeTag,
    }
    let mut raws = Vec::with_capacity(breaks.len());
    let mut code = 0i64;
    for (k, &b) in breaks.iter().enumerate() {
        let e = if k + 1 < breaks.len() {
            breaks[k + 1]
        } else {
            n
        };
        let poly: Vec<DVec2> = (b..=e).map(|i| points[i % n].pos).collect();
        let mut subcurves = vec![vec![poly[0]]];
        for i in 1..poly.len() {
            if let Some(last) = subcurves.last_mut() {
                last.push(poly[i]);
            }
            if i + 1 < poly.len()
                && turning_angle(poly[i] - poly[i - 1], poly[i + 1] - poly[i]).abs() > keep
            {
                subcurves.push(vec![poly[i]]);
            }
        }
        raws.push(Raw {
            from: b,
            to: e % n,
            length: polyline_length(&poly),
            subcurves,
            code,
            tag: points[b].tag,
        });
        code += points[e % n].label;
    }
    let h = options.target_size;
    let min_intervals: Vec<usize> = raws
        .iter()
        .map(|r| {
            ((r.length / h).round() as usize)
                .max(r.subcurves.len())
                .max(1)
        })
        .collect();
    let mut twins = Vec::new();
    let mut first_copy: HashMap<usize, usize> = HashMap::new();
    for (k, r) in raws.iter().enumerate() {
        if let EdgeTag::Virtual(v) = r.tag {
            if let Some(&j) = first_copy.get(&v) {
                twins.push((j, k));
            } else {
                first_copy.insert(v, k);
            }
        }
    }
    let problem = IntervalProblem {
        edges: raws
            .iter()
            .zip(&min_intervals)
            .enumerate()
            .map(|(k, (r, &nmin))| IntervalEdge {
                id: k,
                length: r.length,
                direction: Direction::from_code(r.code),
                min_intervals: Some(nmin),
            })
            .collect(),
        twins,
    };
    let iopts = IntervalOptions::new(h).include_max_term(options.include_max_term);
    let sol = assign_intervals(&problem, &iopts).map_err(SubmapError::Intervals)?;

    // nodes and the computational walk
    let mut nodes: Vec<DVec2> = Vec::new();
    let mut node_kinds: Vec<NodeKind> = Vec::new();
    let mut by_key: HashMap<usize, usize> = HashMap::new();
    let mut node_of_key =
        |key: usize, pos: DVec2, nodes: &mut Vec<DVec2>, kinds: &mut Vec<NodeKind>| {
            *by_key.entry(key).or_insert_with(|| {
                nodes.push(pos);
                kinds.push(NodeKind::Boundary);
                nodes.len() - 1
            })
        };
    let mut virtual_ids: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut occurrences = Vec::new();
    let mut edges = Vec::with_capacity(raws.len());
    let mut c = [0i64, 0i64];
    for (k, r) in raws.iter().enumerate() {
        let ne = sol.intervals[k];
        let start = node_of_key(
            points[r.from].key,
            points[r.from].pos,
            &mut nodes,
            &mut node_kinds,
        );
        let end = node_of_key(
            points[r.to].key,
            points[r.to].pos,
            &mut nodes,
            &mut node_kinds,
        );
        let twin_ids = match r.tag {
            EdgeTag::Virtual(v) => virtual_ids.get(&v).cloned(),
            _ => None,
        };
        let ids: Vec<usize> = match twin_ids {
            Some(mut t)
                if t.len() == ne + 1 && t.first() == Some(&end) && t.last() == Some(&start) =>
            {
                t.reverse();
                t
            }
            _ => {
                let lens: Vec<f64> = r.subcurves.iter().map(|s| polyline_length(s)).collect();
                let per = distribute(ne, &lens);
                let mut pos: Vec<DVec2> = Vec::with_capacity(ne + 1);
                for (s, &m) in r.subcurves.iter().zip(&per) {
                    let pts = resample_arc_length(s, m + 1)?;
                    let skip = usize::from(!pos.is_empty());
                    pos.extend_from_slice(&pts[skip..]);
                }
                let kind = if matches!(r.tag, EdgeTag::Virtual(_)) {
                    NodeKind::Virtual
                } else {
                    NodeKind::Boundary
                };
                let mut ids = vec![start];
                for p in &pos[1..pos.len().saturating_sub(1)] {
                    nodes.push(*p);
                    node_kinds.push(kind);
                    ids.push(nodes.len() - 1);
                }
                ids.push(end);
                ids
            }
        };
        if let EdgeTag::Virtual(v) = r.tag {
            virtual_ids.entry(v).or_insert_with(|| ids.clone());
        }
        let step = dir_step(r.code);
        for &id in &ids[..ids.len() - 1] {
            occurrences.push(Occ { id, c, tag: r.tag });
            c = [c[0] + step[0], c[1] + step[1]];
        }
        edges.push(CompEdge {
            points: (r.from..=(if r.to == 0 { n } else { r.to }))
                .map(|i| points[i % n].pos)
                .collect(),
            direction: Direction::from_code(r.code),
            length: r.length,
            min_intervals: min_intervals[k],
            intervals: ne,
            tag: r.tag,
        });
    }
    if c != [0, 0] {
        return Err(SubmapError::NotClosed { x: c[0], y: c[1] });
    }
    // the computational loop must be weakly simple: where it visits a position more than once
    // (junction points, the two copies of a virtual edge, the two walls of a slit ending in a
    // Reversal) the interior angles of the visits must not overlap. Each visit covers the quarter
    // sectors d_out, d_out + 1, …, d_out + s − 1 (s = interior angle in quarter turns). ILP (3)
    // balances only the global sums (2), so it can place a hole across the outer boundary
    // (a case the paper does not treat; compare its Fig 11); that shows up here as overlapping
    // sectors.
    let ang = super::cuts::angles(&occurrences);
    let mut seen: HashMap<[i64; 2], (u8, usize)> = HashMap::new();
    for (o, &(d_out, s)) in occurrences.iter().zip(&ang) {
        let mask = (0..s).fold(0u8, |m, t| m | 1 << (d_out + t).rem_euclid(4));
        let entry = seen.entry(o.c).or_insert((0, o.id));
        if entry.0 & mask != 0 {
            return Err(SubmapError::Overlap {
                a: nodes[entry.1],
                b: nodes[o.id],
            });
        }
        entry.0 |= mask;
    }
    Ok(Comp {
        edges,
        objective: sol.objective,
        nodes,
        node_kinds,
        occurrences,
    })
}

#[cfg(test)]
mod tests {
    use super::distribute;

    #[test]
    fn distribute_in_proportion() {
        // 10 over lengths 1, 3, 1: ideal 2, 6, 2
        assert_eq!(distribute(10, &[1.0, 3.0, 1.0]), vec![2, 6, 2]);
        // at least one each: 3 over 0.01, 1, 1
        assert_eq!(distribute(3, &[0.01, 1.0, 1.0]), vec![1, 1, 1]);
        // 4 over 1, 1, 1: one extra to the first largest remainder
        assert_eq!(distribute(4, &[1.0, 1.0, 1.0]).iter().sum::<usize>(), 4);
    }
}
