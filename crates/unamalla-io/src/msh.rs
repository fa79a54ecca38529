//! Gmsh MSH 4.1 ASCII files (`gmsh.texi`, "MSH file format"), with named boundary groups.
//!
//! # Writing
//!
//! [`write_msh_quads`] (2D) and [`write_msh_hexes`] (3D) write
//!
//! * `$MeshFormat` `4.1 0 8`;
//! * `$PhysicalNames`: the cells' group (`domain`, dimension 2 or 3, physical tag 1) and every
//!   boundary group (dimension 1 or 2, physical tags 2, 3, … in the order given);
//! * `$Entities`: one surface (2D) or volume (3D) entity, tag 1, carrying the domain's physical
//!   tag, and one curve (2D) or surface (3D) entity per group, tags 1, 2, …, each carrying its
//!   group's physical tag, with bounding boxes;
//! * `$Nodes`: one block with every node (tags `1..=N` = node id + 1), classified on the domain
//!   entity, `z = 0` in 2D;
//! * `$Elements`: the cells (quads, type 3, or hexahedra, type 5, tags `1..=C`), then each
//!   group's line elements (type 1, 2D) or quads (type 3, 3D) on its own entity, tags continuing.
//!
//! The mesher passes its rings and cuts as groups: [`EdgeGroup`]s of node-id pairs in 2D
//! ([`boundary_edge_groups`] computes `outer`, `hole-1`, … from a quad mesh), [`FaceGroup`]s of
//! quads in 3D ([`hex_boundary_faces`] lists the boundary faces of a hex mesh). Groups are
//! validated before the file is touched ([`IoError::InvalidGroup`]): names non-empty, without
//! `"` or control characters, distinct from each other and from the domain name; node ids in
//! range. Files are replaced atomically; coordinates use the shortest round-trip decimal form.
//!
//! # Reading
//!
//! [`read_msh`] / [`parse_msh`] read MSH 4.1 ASCII (other versions and binary files are
//! [`IoError::Unsupported`]): `$MeshFormat`, `$PhysicalNames`, `$Entities`, `$Nodes`
//! (parametric coordinates are skipped), `$Elements`; other sections are skipped. Nodes keep
//! their file order (node id = position in `$Nodes`). If there are hexahedra (type 5) the mesh
//! is a [`HexMesh`] and quads (type 3) on entities with physical groups form [`FaceGroup`]s;
//! otherwise the quads form a [`QuadMesh`] (every `z` must be 0) and lines (type 1) on entities
//! with physical groups form [`EdgeGroup`]s. Groups are named by `$PhysicalNames` (unnamed
//! physical groups are called `physical-<tag>`) and ordered by physical tag. Points (type 15)
//! and boundary elements without a physical group are ignored; triangles, tetrahedra, prisms,
//! pyramids and higher-order elements are [`IoError::Unsupported`]. Errors carry line numbers.

use std::collections::{BTreeMap, HashMap};
use std::io::{self, Write};
use std::path::Path;

use unamalla_mesh::{
    BlockMesh2, DVec2, DVec3, HasHexCells, HasNodes, HasQuadCells, HexMesh, QuadMesh, HEX_FACES,
};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::STRING_SOURCE;
use crate::lex::{Lexer, MAX_PREALLOC};

/// Gmsh element type of a 2-node line.
pub const MSH_LINE: u32 = 1;
/// Gmsh element type of a 4-node quadrangle.
pub const MSH_QUAD: u32 = 3;
/// Gmsh element type of an 8-node hexahedron.
pub const MSH_HEX: u32 = 5;
/// Gmsh element type of a 1-node point.
pub const MSH_POINT: u32 = 15;

/// A named group of boundary edges of a 2D mesh (written as line elements, type 1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EdgeGroup {
    /// The physical group name, e.g. `"outer"`, `"hole-1"`, `"cut-3"`.
    pub name: String,
    /// The edges as node-id pairs (0-based ids of the mesh).
    pub edges: Vec<[usize; 2]>,
}

/// A named group of boundary faces of a 3D mesh (written as quad elements, type 3).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FaceGroup {
    /// The physical group name.
    pub name: String,
    /// The faces as 4 node ids (0-based), ideally ordered so the normal points out.
    pub faces: Vec<[usize; 4]>,
}

/// One closed chain of boundary edges of a quad mesh (see [`boundary_loops`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryLoop {
    /// The edges in order, each oriented as in its cell (domain on the left), so consecutive
    /// edges share a node and the last edge ends where the first starts.
    pub edges: Vec<[usize; 2]>,
    /// Signed area enclosed by the loop: positive for an outer boundary (counter-clockwise),
    /// negative for a hole (clockwise).
    pub signed_area: f64,
}

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
    let path = path.as_ref();
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
        write_msh(w, 2, &nodes, &cells, &[], MSH_QUAD, domain, &gs, MSH_LINE)
    })
}

/// Writes a block-structured quad mesh as MSH 4.1 with **one surface entity per block**
/// (entity tag = block index + 1, the block's cells in its own element block, in the global
/// mesh's cell order), every surface in the physical group `domain` (tag 1) and in its own
/// physical surface `block-<b>` (tags after the edge groups), and each [`EdgeGroup`] (node ids
/// of the global mesh, e.g. from [`crate::patches::named_edge_groups`]) as a physical curve.
/// [`read_msh`] reads it back as one quad mesh with the groups.
pub fn write_msh_blocks(
    path: impl AsRef<Path>,
    mesh: &BlockMesh2,
    domain: &str,
    groups: &[EdgeGroup],
) -> Result<(), IoError> {
    let path = path.as_ref();
    let global = mesh.global();
    let nn = global.num_nodes();
    let mut seen = Vec::new();
    check_name(path, domain, &mut seen)?;
    for g in groups {
        check_name(path, &g.name, &mut seen)?;
        check_ids(path, &g.name, &g.edges, nn)?;
    }
    let nodes: Vec<DVec3> = global
        .nodes()
        .iter()
        .map(|p| DVec3::new(p.x, p.y, 0.0))
        .collect();
    let cells: Vec<Vec<usize>> = (0..global.num_quads())
        .map(|c| global.quad(c).to_vec())
        .collect();
    let parts: Vec<usize> = mesh.blocks().iter().map(|b| b.num_quads()).collect();
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
        write_msh(
            w, 2, &nodes, &cells, &parts, MSH_QUAD, domain, &gs, MSH_LINE,
        )
    })
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

// ---------------------------------------------------------------------------------------------
// Reading

/// The mesh of an MSH file.
#[derive(Debug, Clone, PartialEq)]
pub enum MshMesh {
    /// Quads only (2D; every `z` is 0).
    Quads(QuadMesh),
    /// Hexahedra (3D).
    Hexes(HexMesh),
}

/// What [`read_msh`] extracts from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct MshFile {
    /// The mesh.
    pub mesh: MshMesh,
    /// The name of the cells' physical group (of the first cell block whose entity has one).
    pub domain: Option<String>,
    /// Boundary groups of a 2D mesh, ordered by physical tag.
    pub edge_groups: Vec<EdgeGroup>,
    /// Boundary groups of a 3D mesh, ordered by physical tag.
    pub face_groups: Vec<FaceGroup>,
}

impl MshFile {
    /// The edge group with this name.
    pub fn edge_group(&self, name: &str) -> Option<&EdgeGroup> {
        self.edge_groups.iter().find(|g| g.name == name)
    }
    /// The face group with this name.
    pub fn face_group(&self, name: &str) -> Option<&FaceGroup> {
        self.face_groups.iter().find(|g| g.name == name)
    }
}

/// Reads a Gmsh MSH 4.1 ASCII file (see the [module docs](self)).
pub fn read_msh(path: impl AsRef<Path>) -> Result<MshFile, IoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    match std::str::from_utf8(&bytes) {
        Ok(t) => parse_at(t, path),
        Err(e) => {
            // A binary MSH file has a text header: report it as unsupported if it says so.
            let valid = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or("");
            let mut words = valid.split_whitespace();
            if words.next() == Some("$MeshFormat") && words.nth(1) == Some("1") {
                return Err(IoError::Unsupported {
                    path: path.to_path_buf(),
                    line: 2,
                    what: "binary MSH files (only ASCII is read)".into(),
                });
            }
            Err(IoError::Malformed {
                path: path.to_path_buf(),
                line: valid.matches('\n').count() + 1,
                message: "the file is not valid UTF-8/ASCII text".into(),
            })
        }
    }
}

/// Like [`read_msh`], for text held in memory (errors name `<string>`).
pub fn parse_msh(text: &str) -> Result<MshFile, IoError> {
    parse_at(text, Path::new(STRING_SOURCE))
}

/// Number of nodes of a Gmsh element type, for the types this reader can skip or use.
fn nodes_per_element(ty: i64) -> Option<usize> {
    Some(match ty {
        1 => 2,
        2 => 3,
        3 => 4,
        4 => 4,
        5 => 8,
        6 => 6,
        7 => 5,
        15 => 1,
        _ => return None,
    })
}

struct ElemBlock {
    dim: i64,
    entity: i64,
    ty: i64,
    /// Node ids (already mapped to 0-based positions), `k` per element.
    conn: Vec<usize>,
}

fn parse_at(text: &str, path: &Path) -> Result<MshFile, IoError> {
    let mut lx = Lexer::new(text, path);
    let mut format_seen = false;
    let mut names: HashMap<(i64, i64), String> = HashMap::new();
    let mut entity_phys: HashMap<(i64, i64), Vec<i64>> = HashMap::new();
    let mut nodes: Option<Nodes> = None;
    let mut blocks: Vec<ElemBlock> = Vec::new();
    let mut elements_seen = false;

    while let Some((tok, line)) = lx.next() {
        let Some(section) = tok.strip_prefix('$') else {
            return Err(lx.malformed(line, format!("expected a $Section, found {tok:?}")));
        };
        if !format_seen && section != "MeshFormat" {
            return Err(lx.malformed(
                line,
                format!("expected $MeshFormat first, found ${section}"),
            ));
        }
        match section {
            "MeshFormat" => {
                if format_seen {
                    return Err(lx.malformed(line, "$MeshFormat given twice".into()));
                }
                let (ver, vline) = lx.token("the MSH version")?;
                let (ft, _) = lx.i64("file type")?;
                lx.token("data size")?;
                if ft != 0 {
                    return Err(IoError::Unsupported {
                        path: path.to_path_buf(),
                        line: vline,
                        what: "binary MSH files (only ASCII is read)".into(),
                    });
                }
                if !ver.starts_with("4.1") {
                    return Err(IoError::Unsupported {
                        path: path.to_path_buf(),
                        line: vline,
                        what: format!("MSH version {ver} (only 4.1 is read)"),
                    });
                }
                format_seen = true;
            }
            "PhysicalNames" => read_physical_names(&mut lx, &mut names)?,
            "Entities" => read_entities(&mut lx, &mut entity_phys)?,
            "Nodes" => {
                if nodes.is_some() {
                    return Err(lx.malformed(line, "$Nodes given twice".into()));
                }
                nodes = Some(read_nodes(&mut lx)?);
            }
            "Elements" => {
                if elements_seen {
                    return Err(lx.malformed(line, "$Elements given twice".into()));
                }
                let Some((_, index, _)) = &nodes else {
                    return Err(lx.malformed(line, "$Elements before $Nodes".into()));
                };
                blocks = read_elements(&mut lx, index)?;
                elements_seen = true;
            }
            _ => {
                // Skip an unknown section.
                let end = format!("$End{section}");
                loop {
                    let (t, _) = lx.token(&end)?;
                    if t == end {
                        break;
                    }
                }
                continue;
            }
        }
        lx.keyword(&format!("$End{section}"))?;
    }
    if !format_seen {
        return Err(IoError::Truncated {
            path: path.to_path_buf(),
            line: lx.line(),
            expected: "$MeshFormat".into(),
        });
    }
    let Some((nodes, _, nodes_line)) = nodes else {
        return Err(IoError::Truncated {
            path: path.to_path_buf(),
            line: lx.line(),
            expected: "$Nodes".into(),
        });
    };
    if !elements_seen {
        return Err(IoError::Truncated {
            path: path.to_path_buf(),
            line: lx.line(),
            expected: "$Elements".into(),
        });
    }
    build(path, nodes, nodes_line, &blocks, &names, &entity_phys)
}

fn read_physical_names(
    lx: &mut Lexer<'_>,
    names: &mut HashMap<(i64, i64), String>,
) -> Result<(), IoError> {
    // The count ends its line; each name is one whole line (names may contain spaces).
    let (n, _) = lx.usize("number of physical names")?;
    let mut read = 0;
    while read < n {
        let Some((l, line)) = lx.next_line() else {
            return Err(IoError::Truncated {
                path: lx.pb(),
                line: lx.line(),
                expected: "a physical name".into(),
            });
        };
        let l = l.trim();
        if l.is_empty() {
            continue;
        }
        let bad = || IoError::Malformed {
            path: lx.pb(),
            line,
            message: format!("expected `dim tag \"name\"`, found {l:?}"),
        };
        let mut it = l.splitn(3, char::is_whitespace);
        let dim: i64 = it.next().and_then(|t| t.parse().ok()).ok_or_else(bad)?;
        let tag: i64 = it.next().and_then(|t| t.parse().ok()).ok_or_else(bad)?;
        let rest = it.next().unwrap_or("").trim();
        let name = rest
            .strip_prefix('"')
            .and_then(|r| r.strip_suffix('"'))
            .ok_or_else(bad)?;
        names.insert((dim, tag), name.to_string());
        read += 1;
    }
    Ok(())
}

fn read_entities(
    lx: &mut Lexer<'_>,
    entity_phys: &mut HashMap<(i64, i64), Vec<i64>>,
) -> Result<(), IoError> {
    let mut counts = [0usize; 4];
    for (d, c) in counts.iter_mut().enumerate() {
        *c = lx.usize(&format!("number of entities of dimension {d}"))?.0;
    }
    for (d, &c) in counts.iter().enumerate() {
        for _ in 0..c {
            let (tag, _) = lx.i64("entity tag")?;
            let ncoord = if d == 0 { 3 } else { 6 };
            for _ in 0..ncoord {
                lx.f64("entity coordinate")?;
            }
            let (np, _) = lx.usize("number of physical tags")?;
            let mut phys = Vec::with_capacity(np.min(MAX_PREALLOC));
            for _ in 0..np {
                phys.push(lx.i64("physical tag")?.0);
            }
            if d > 0 {
                let (nb, _) = lx.usize("number of bounding entities")?;
                for _ in 0..nb {
                    lx.i64("bounding entity tag")?;
                }
            }
            entity_phys.insert((d as i64, tag), phys);
        }
    }
    Ok(())
}

/// The nodes, the map tag → position, and the line of the `$Nodes` header.
type Nodes = (Vec<DVec3>, HashMap<usize, usize>, usize);

/// Reads the body of `$Nodes`.
fn read_nodes(lx: &mut Lexer<'_>) -> Result<Nodes, IoError> {
    let (nblocks, hline) = lx.usize("number of node blocks")?;
    let (total, _) = lx.usize("number of nodes")?;
    lx.usize("minimum node tag")?;
    lx.usize("maximum node tag")?;
    let mut nodes = Vec::with_capacity(total.min(MAX_PREALLOC));
    let mut index = HashMap::with_capacity(total.min(MAX_PREALLOC));
    for _ in 0..nblocks {
        let (edim, _) = lx.i64("entity dimension")?;
        lx.i64("entity tag")?;
        let (param, pline) = lx.i64("parametric flag")?;
        let (n, _) = lx.usize("number of nodes in the block")?;
        let extra = match (param, edim) {
            (0, _) => 0,
            (1, d @ 0..=3) => d as usize,
            _ => {
                return Err(lx.malformed(
                    pline,
                    format!("parametric flag {param} on an entity of dimension {edim}"),
                ))
            }
        };
        let first = nodes.len();
        for k in 0..n {
            let (tag, tline) = lx.usize("node tag")?;
            if tag == 0 {
                return Err(lx.malformed(tline, "node tag 0 (tags start at 1)".into()));
            }
            if index.insert(tag, first + k).is_some() {
                return Err(lx.malformed(tline, format!("node tag {tag} given twice")));
            }
            if nodes.len() + (k + 1) > total {
                return Err(IoError::CountMismatch {
                    path: lx.pb(),
                    line: hline,
                    what: "number of nodes".into(),
                    expected: total,
                    found: first + k + 1,
                });
            }
        }
        for _ in 0..n {
            let (x, _) = lx.f64("x")?;
            let (y, _) = lx.f64("y")?;
            let (z, _) = lx.f64("z")?;
            for _ in 0..extra {
                lx.f64("parametric coordinate")?;
            }
            nodes.push(DVec3::new(x, y, z));
        }
    }
    if nodes.len() != total {
        return Err(IoError::CountMismatch {
            path: lx.pb(),
            line: hline,
            what: "number of nodes".into(),
            expected: total,
            found: nodes.len(),
        });
    }
    Ok((nodes, index, hline))
}

fn read_elements(
    lx: &mut Lexer<'_>,
    index: &HashMap<usize, usize>,
) -> Result<Vec<ElemBlock>, IoError> {
    let (nblocks, hline) = lx.usize("number of element blocks")?;
    let (total, _) = lx.usize("number of elements")?;
    lx.usize("minimum element tag")?;
    lx.usize("maximum element tag")?;
    let mut blocks = Vec::new();
    let mut seen = 0usize;
    for _ in 0..nblocks {
        let (dim, _) = lx.i64("entity dimension")?;
        let (entity, _) = lx.i64("entity tag")?;
        let (ty, tline) = lx.i64("element type")?;
        let (n, nline) = lx.usize("number of elements in the block")?;
        let k = nodes_per_element(ty).ok_or_else(|| IoError::Unsupported {
            path: lx.pb(),
            line: tline,
            what: format!("element type {ty}"),
        })?;
        seen = seen.saturating_add(n);
        if seen > total {
            return Err(IoError::CountMismatch {
                path: lx.pb(),
                line: nline,
                what: "number of elements".into(),
                expected: total,
                found: seen,
            });
        }
        let mut conn = Vec::with_capacity(n.saturating_mul(k).min(MAX_PREALLOC));
        for _ in 0..n {
            lx.usize("element tag")?;
            for _ in 0..k {
                let (tag, l) = lx.usize("node tag")?;
                let v = index.get(&tag).copied().ok_or_else(|| {
                    lx.malformed(l, format!("element uses unknown node tag {tag}"))
                })?;
                conn.push(v);
            }
        }
        blocks.push(ElemBlock {
            dim,
            entity,
            ty,
            conn,
        });
    }
    if seen != total {
        return Err(IoError::CountMismatch {
            path: lx.pb(),
            line: hline,
            what: "number of elements".into(),
            expected: total,
            found: seen,
        });
    }
    Ok(blocks)
}

fn build(
    path: &Path,
    nodes: Vec<DVec3>,
    nodes_line: usize,
    blocks: &[ElemBlock],
    names: &HashMap<(i64, i64), String>,
    entity_phys: &HashMap<(i64, i64), Vec<i64>>,
) -> Result<MshFile, IoError> {
    let unsupported = |ty: i64| IoError::Unsupported {
        path: path.to_path_buf(),
        line: nodes_line,
        what: format!(
            "element type {ty} (only quads (3), hexahedra (5), lines (1) and points (15))"
        ),
    };
    if let Some(b) = blocks.iter().find(|b| matches!(b.ty, 2 | 4 | 6 | 7)) {
        return Err(unsupported(b.ty));
    }
    let has_hex = blocks.iter().any(|b| b.ty == i64::from(MSH_HEX));
    let (cell_ty, cell_k, group_ty, group_k) = if has_hex {
        (MSH_HEX, 8, MSH_QUAD, 4)
    } else {
        (MSH_QUAD, 4, MSH_LINE, 2)
    };
    let phys_of = |b: &ElemBlock| {
        entity_phys
            .get(&(b.dim, b.entity))
            .cloned()
            .unwrap_or_default()
    };
    let mut cells: Vec<usize> = Vec::new();
    let mut domain = None;
    // physical tag → (dim, elements)
    let mut groups: BTreeMap<i64, (i64, Vec<usize>)> = BTreeMap::new();
    for b in blocks {
        let ty = u32::try_from(b.ty).unwrap_or(0);
        if ty == cell_ty {
            cells.extend_from_slice(&b.conn);
            if domain.is_none() {
                if let Some(&p) = phys_of(b).first() {
                    domain = Some(
                        names
                            .get(&(b.dim, p))
                            .cloned()
                            .unwrap_or_else(|| format!("physical-{p}")),
                    );
                }
            }
        } else if ty == group_ty {
            for p in phys_of(b) {
                groups
                    .entry(p)
                    .or_insert_with(|| (b.dim, Vec::new()))
                    .1
                    .extend_from_slice(&b.conn);
            }
        }
    }
    if cells.is_empty() && !blocks.iter().any(|b| b.ty == i64::from(cell_ty)) {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: nodes_line,
            what: "a file without quad (3) or hexahedron (5) elements".into(),
        });
    }
    let name_of = |dim: i64, p: i64| {
        names
            .get(&(dim, p))
            .cloned()
            .unwrap_or_else(|| format!("physical-{p}"))
    };
    let mesh_err = |source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    };
    if has_hex {
        let hexes: Vec<[usize; 8]> = cells
            .chunks_exact(cell_k)
            .map(|c| std::array::from_fn(|k| c[k]))
            .collect();
        let face_groups = groups
            .into_iter()
            .map(|(p, (dim, conn))| FaceGroup {
                name: name_of(dim, p),
                faces: conn
                    .chunks_exact(group_k)
                    .map(|c| [c[0], c[1], c[2], c[3]])
                    .collect(),
            })
            .collect();
        Ok(MshFile {
            mesh: MshMesh::Hexes(HexMesh::new(nodes, hexes).map_err(mesh_err)?),
            domain,
            edge_groups: Vec::new(),
            face_groups,
        })
    } else {
        if let Some((node, p)) = nodes.iter().enumerate().find(|(_, p)| p.z != 0.0) {
            return Err(IoError::NotPlanar {
                path: path.to_path_buf(),
                line: nodes_line,
                node,
                z: p.z,
            });
        }
        let nodes2: Vec<DVec2> = nodes.iter().map(|p| p.truncate()).collect();
        let quads: Vec<[usize; 4]> = cells
            .chunks_exact(cell_k)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        let edge_groups = groups
            .into_iter()
            .map(|(p, (dim, conn))| EdgeGroup {
                name: name_of(dim, p),
                edges: conn.chunks_exact(group_k).map(|c| [c[0], c[1]]).collect(),
            })
            .collect();
        Ok(MshFile {
            mesh: MshMesh::Quads(QuadMesh::new(nodes2, quads).map_err(mesh_err)?),
            domain,
            edge_groups,
            face_groups: Vec::new(),
        })
    }
}
