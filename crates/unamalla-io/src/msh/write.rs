//! The MSH 4.1 writers: quads (one or several blocks) and hexahedra with named groups.

use std::io::{self, Write};
use std::path::Path;

use unamalla_mesh::{BlockMesh2, DVec3, HasHexCells, HasQuadCells};

use super::{EdgeGroup, FaceGroup, MSH_HEX, MSH_LINE, MSH_QUAD};
use crate::atomic::atomic_write;
use crate::error::IoError;

fn check_name(path: &Path, name: &str, seen: &mut Vec<String>) -> Result<(), IoError> {
    let bad = |reason: &str| IoError::InvalidGroup {
        path: path.to_path_buf(),
        name: name.to_string(),
        reason: reason.to_string(),
    };
    if name.trim().is_empty() {
        return Err(bad("the name is empty"));
    }
    if name.contains('"') || name.chars().any(char::is_control) {
        return Err(bad("the name contains '\"' or a control character"));
    }
    if seen.iter().any(|s| s == name) {
        return Err(bad("another group (or the domain) has the same name"));
    }
    seen.push(name.to_string());
    Ok(())
}

fn check_ids<const K: usize>(
    path: &Path,
    name: &str,
    elems: &[[usize; K]],
    nn: usize,
) -> Result<(), IoError> {
    for (e, ids) in elems.iter().enumerate() {
        if let Some(&v) = ids.iter().find(|&&v| v >= nn) {
            return Err(IoError::InvalidGroup {
                path: path.to_path_buf(),
                name: name.to_string(),
                reason: format!("element {e} uses node {v}, the mesh has {nn} nodes"),
            });
        }
    }
    Ok(())
}

/// Writes a 2D quad mesh (any [`HasQuadCells`]) as MSH 4.1 with the cells in the physical
/// group `domain` and each [`EdgeGroup`] as a physical group of line elements.
pub fn write_msh_quads<M: HasQuadCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    domain: &str,
    groups: &[EdgeGroup],
) -> Result<(), IoError> {
    write_quads_in_parts(path.as_ref(), mesh, &[], domain, groups)
}

/// The quad writer of [`write_msh_quads`] and [`write_msh_blocks`]: the names and node ids
/// checked, the nodes lifted to z = 0, the cells in `parts` consecutive entities (all in one
/// when `parts` is empty).
fn write_quads_in_parts<M: HasQuadCells + ?Sized>(
    path: &Path,
    mesh: &M,
    parts: &[usize],
    domain: &str,
    groups: &[EdgeGroup],
) -> Result<(), IoError> {
    let nn = mesh.num_nodes();
    let mut seen = Vec::new();
    check_name(path, domain, &mut seen)?;
    for g in groups {
        check_name(path, &g.name, &mut seen)?;
        check_ids(path, &g.name, &g.edges, nn)?;
    }
    let nodes: Vec<DVec3> = mesh
        .nodes()
        .iter()
        .map(|p| DVec3::new(p.x, p.y, 0.0))
        .collect();
    let cells: Vec<Vec<usize>> = (0..mesh.num_quads())
        .map(|c| mesh.quad(c).to_vec())
        .collect();
    let gs: Vec<(&str, Vec<Vec<usize>>)> = groups
        .iter()
        .map(|g| {
            (
                g.name.as_str(),
                g.edges.iter().map(|e| e.to_vec()).collect(),
            )
        })
        .collect();
    atomic_write(path, |w| {
        write_msh(w, 2, &nodes, &cells, parts, MSH_QUAD, domain, &gs, MSH_LINE)
    })
}

/// Writes a block-structured quad mesh as MSH 4.1 with **one surface entity per block**
/// (entity tag = block index + 1, the block's cells in its own element block, in the global
/// mesh's cell order), every surface in the physical group `domain` (tag 1) and in its own
/// physical surface `block-<b>` (tags after the edge groups), and each [`EdgeGroup`] (node ids
/// of the global mesh, e.g. from [`crate::patches::named_edge_groups`]) as a physical curve.
/// [`read_msh`](crate::msh::read_msh) reads it back as one quad mesh with the groups.
pub fn write_msh_blocks(
    path: impl AsRef<Path>,
    mesh: &BlockMesh2,
    domain: &str,
    groups: &[EdgeGroup],
) -> Result<(), IoError> {
    let parts: Vec<usize> = mesh.blocks().iter().map(|b| b.num_quads()).collect();
    write_quads_in_parts(path.as_ref(), mesh.global(), &parts, domain, groups)
}

/// Writes a hex mesh (any [`HasHexCells`]) as MSH 4.1 with the cells in the physical group
/// `domain` and each [`FaceGroup`] as a physical group of quad elements.
pub fn write_msh_hexes<M: HasHexCells + ?Sized>(
    path: impl AsRef<Path>,
    mesh: &M,
    domain: &str,
    groups: &[FaceGroup],
) -> Result<(), IoError> {
    let path = path.as_ref();
    let nn = mesh.num_nodes();
    let mut seen = Vec::new();
    check_name(path, domain, &mut seen)?;
    for g in groups {
        check_name(path, &g.name, &mut seen)?;
        check_ids(path, &g.name, &g.faces, nn)?;
    }
    let cells: Vec<Vec<usize>> = (0..mesh.num_hexes())
        .map(|c| mesh.hex(c).to_vec())
        .collect();
    let gs: Vec<(&str, Vec<Vec<usize>>)> = groups
        .iter()
        .map(|g| {
            (
                g.name.as_str(),
                g.faces.iter().map(|e| e.to_vec()).collect(),
            )
        })
        .collect();
    atomic_write(path, |w| {
        write_msh(
            w,
            3,
            mesh.nodes(),
            &cells,
            &[],
            MSH_HEX,
            domain,
            &gs,
            MSH_QUAD,
        )
    })
}

fn bbox(nodes: &[DVec3], ids: impl Iterator<Item = usize>) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for v in ids {
        lo = lo.min(nodes[v]);
        hi = hi.max(nodes[v]);
    }
    if lo.x > hi.x {
        (DVec3::ZERO, DVec3::ZERO)
    } else {
        (lo, hi)
    }
}

#[allow(clippy::too_many_arguments)]
fn write_msh(
    w: &mut dyn Write,
    dim: usize,
    nodes: &[DVec3],
    cells: &[Vec<usize>],
    parts: &[usize],
    cell_type: u32,
    domain: &str,
    groups: &[(&str, Vec<Vec<usize>>)],
    group_type: u32,
) -> io::Result<()> {
    // `parts`: cell counts of consecutive cell entities (empty: one entity, no block groups)
    let whole = [cells.len()];
    let (parts, block_groups) = if parts.is_empty() {
        (&whole[..], false)
    } else {
        (parts, true)
    };
    let nb = if block_groups { parts.len() } else { 0 };
    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    writeln!(w, "$PhysicalNames\n{}", groups.len() + 1 + nb)?;
    writeln!(w, "{dim} 1 \"{domain}\"")?;
    for (k, (name, _)) in groups.iter().enumerate() {
        writeln!(w, "{} {} \"{name}\"", dim - 1, k + 2)?;
    }
    for b in 0..nb {
        writeln!(w, "{dim} {} \"block-{b}\"", groups.len() + 2 + b)?;
    }
    writeln!(w, "$EndPhysicalNames")?;
    // Entities: (points, curves, surfaces, volumes).
    writeln!(w, "$Entities")?;
    let ng = groups.len();
    let np = parts.len();
    if dim == 2 {
        writeln!(w, "0 {ng} {np} 0")?;
    } else {
        writeln!(w, "0 0 {ng} {np}")?;
    }
    let fmt_box = |(lo, hi): (DVec3, DVec3)| {
        format!(
            "{:?} {:?} {:?} {:?} {:?} {:?}",
            lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
        )
    };
    for (k, (_, elems)) in groups.iter().enumerate() {
        let b = bbox(nodes, elems.iter().flatten().copied());
        writeln!(w, "{} {} 1 {} 0", k + 1, fmt_box(b), k + 2)?;
    }
    let mut start = 0;
    for (b, &len) in parts.iter().enumerate() {
        let cb = &cells[start..start + len];
        let bx = bbox(nodes, cb.iter().flatten().copied());
        if block_groups {
            writeln!(w, "{} {} 2 1 {} 0", b + 1, fmt_box(bx), ng + 2 + b)?;
        } else {
            writeln!(w, "1 {} 1 1 0", fmt_box(bbox(nodes, 0..nodes.len())))?;
        }
        start += len;
    }
    writeln!(w, "$EndEntities")?;
    let nn = nodes.len();
    writeln!(w, "$Nodes\n1 {nn} {} {nn}", nn.min(1))?;
    writeln!(w, "{dim} 1 0 {nn}")?;
    for v in 1..=nn {
        writeln!(w, "{v}")?;
    }
    for p in nodes {
        writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    writeln!(w, "$EndNodes")?;
    let total = cells.len() + groups.iter().map(|g| g.1.len()).sum::<usize>();
    writeln!(w, "$Elements\n{} {total} {} {total}", ng + np, total.min(1))?;
    let mut tag = 0usize;
    let mut block = |w: &mut dyn Write, edim: usize, ent: usize, ty: u32, els: &[Vec<usize>]| {
        writeln!(w, "{edim} {ent} {ty} {}", els.len())?;
        for e in els {
            tag += 1;
            write!(w, "{tag}")?;
            for v in e {
                write!(w, " {}", v + 1)?;
            }
            writeln!(w)?;
        }
        io::Result::Ok(())
    };
    let mut start = 0;
    for (b, &len) in parts.iter().enumerate() {
        block(w, dim, b + 1, cell_type, &cells[start..start + len])?;
        start += len;
    }
    for (k, (_, elems)) in groups.iter().enumerate() {
        block(w, dim - 1, k + 1, group_type, elems)?;
    }
    writeln!(w, "$EndElements")
}
