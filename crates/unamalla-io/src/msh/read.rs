//! The MSH 4.1 reader: nodes, elements, physical names and entities into an [`MshFile`].

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use unamalla_mesh::{DVec2, DVec3, HexMesh, QuadMesh};

use super::{EdgeGroup, FaceGroup, MSH_HEX, MSH_LINE, MSH_QUAD};
use crate::error::IoError;
use crate::geojson::STRING_SOURCE;
use crate::lex::{Lexer, MAX_PREALLOC};

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

/// Reads a Gmsh MSH 4.1 ASCII file (see the [module docs](crate::msh)).
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
