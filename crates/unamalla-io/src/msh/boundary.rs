//! Boundary loops and groups of a quad mesh and the boundary faces of a hex mesh.

use std::collections::HashMap;

use unamalla_mesh::{HasHexCells, HasQuadCells, HEX_FACES};

use super::{BoundaryLoop, EdgeGroup};

/// The boundary of a quad mesh as closed loops: edges used by exactly one cell, oriented as in
/// that cell (so, for counter-clockwise cells, outer loops run counter-clockwise and holes
/// clockwise), chained node to node.
///
/// Order: the loop with the largest positive area (the outer boundary) first, then the others
/// in order of their first edge's cell. At a node where the boundary touches itself the chain
/// takes the first unused edge, so every boundary edge is in exactly one loop. A chain that
/// cannot be closed (only possible for meshes whose cells are not consistently oriented) is
/// returned as is.
pub fn boundary_loops<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<BoundaryLoop> {
    let nc = mesh.num_quads();
    // the boundary edges (used by one cell, sorted) from the mesh crate's edge census, then
    // oriented as their cell runs them, in cell order
    let boundary = unamalla_mesh::quality::quad_boundary_edges(mesh);
    let mut bedges: Vec<[usize; 2]> = Vec::new();
    for c in 0..nc {
        let q = mesh.quad(c);
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            if a != b && boundary.binary_search(&[a.min(b), a.max(b)]).is_ok() {
                bedges.push([a, b]);
            }
        }
    }
    let mut out_of: HashMap<usize, Vec<usize>> = HashMap::new();
    for (e, &[a, _]) in bedges.iter().enumerate() {
        out_of.entry(a).or_default().push(e);
    }
    let mut used = vec![false; bedges.len()];
    let nodes = mesh.nodes();
    let mut loops = Vec::new();
    for start in 0..bedges.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let first = bedges[start][0];
        let mut chain = vec![bedges[start]];
        let mut cur = bedges[start][1];
        while cur != first {
            let next = out_of
                .get(&cur)
                .and_then(|list| list.iter().copied().find(|&e| !used[e]));
            let Some(e) = next else { break };
            used[e] = true;
            chain.push(bedges[e]);
            cur = bedges[e][1];
        }
        let signed_area = 0.5
            * chain
                .iter()
                .map(|&[a, b]| nodes[a].perp_dot(nodes[b]))
                .sum::<f64>();
        loops.push(BoundaryLoop {
            edges: chain,
            signed_area,
        });
    }
    let outer = loops
        .iter()
        .enumerate()
        .filter(|(_, l)| l.signed_area > 0.0)
        .max_by(|a, b| a.1.signed_area.total_cmp(&b.1.signed_area))
        .map(|(k, _)| k);
    if let Some(k) = outer {
        let l = loops.remove(k);
        loops.insert(0, l);
    }
    loops
}

/// The boundary loops of [`boundary_loops`] as named groups: the first loop is `"outer"`, the
/// clockwise loops are `"hole-1"`, `"hole-2"`, … and further counter-clockwise loops (other
/// components of a disconnected mesh) are `"outer-2"`, `"outer-3"`, …
pub fn boundary_edge_groups<M: HasQuadCells + ?Sized>(mesh: &M) -> Vec<EdgeGroup> {
    let (mut holes, mut outers) = (0, 1);
    boundary_loops(mesh)
        .into_iter()
        .enumerate()
        .map(|(k, l)| {
            let name = if k == 0 && l.signed_area > 0.0 {
                "outer".to_string()
            } else if l.signed_area < 0.0 {
                holes += 1;
                format!("hole-{holes}")
            } else {
                outers += 1;
                format!("outer-{outers}")
            };
            EdgeGroup {
                name,
                edges: l.edges,
            }
        })
        .collect()
}

/// The boundary faces of a hex mesh (faces used by exactly one cell), in cell order, each
/// oriented with its normal pointing out of its cell ([`HEX_FACES`] order).
pub fn hex_boundary_faces<M: HasHexCells + ?Sized>(mesh: &M) -> Vec<[usize; 4]> {
    let nc = mesh.num_hexes();
    let key = |f: [usize; 4]| {
        let mut k = f;
        k.sort_unstable();
        k
    };
    let mut count: HashMap<[usize; 4], u32> = HashMap::with_capacity(nc * 3);
    let face = |h: [usize; 8], f: [usize; 4]| [h[f[0]], h[f[1]], h[f[2]], h[f[3]]];
    for c in 0..nc {
        let h = mesh.hex(c);
        for f in HEX_FACES {
            *count.entry(key(face(h, f))).or_insert(0) += 1;
        }
    }
    let mut out = Vec::new();
    for c in 0..nc {
        let h = mesh.hex(c);
        for f in HEX_FACES {
            let q = face(h, f);
            if count.get(&key(q)) == Some(&1) {
                out.push(q);
            }
        }
    }
    out
}
