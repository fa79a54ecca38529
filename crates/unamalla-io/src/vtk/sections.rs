//! The sections of a legacy file: `POINTS`, `CELLS`, `CELL_TYPES`, attribute data
//! (`SCALARS`, `FIELD`, and what is skipped).

use unamalla_mesh::DVec3;

use super::read::count_mismatch;
use super::write::{VTK_HEXAHEDRON, VTK_QUAD};
use crate::error::IoError;
use crate::lex::{Lexer, MAX_PREALLOC};

/// Named data arrays in file order.
pub(super) type Arrays = Vec<(String, Vec<f64>)>;

#[derive(Clone, Copy, PartialEq)]
pub(super) enum Dataset {
    Structured,
    Unstructured,
}

#[derive(Clone, Copy, PartialEq)]
pub(super) enum Attr {
    None,
    Cell(usize),
    Point(usize),
}

pub(super) struct Points {
    pub(super) nodes: Vec<DVec3>,
    pub(super) line: usize,
    /// First node with `z ≠ 0`: (node, line, z).
    pub(super) first_nonzero_z: Option<(usize, usize, f64)>,
}

pub(super) struct Cells {
    /// `offsets[c]..offsets[c + 1]` indexes `conn` for cell `c`.
    pub(super) offsets: Vec<usize>,
    pub(super) conn: Vec<usize>,
    /// Line where each cell starts.
    pub(super) lines: Vec<usize>,
    pub(super) header_line: usize,
}

pub(super) struct CellTypes {
    /// `VTK_QUAD` or `VTK_HEXAHEDRON` (`None` when there are no cells).
    pub(super) kind: Option<u8>,
    pub(super) count: usize,
    pub(super) line: usize,
}

/// `POINTS n type` followed by `3 n` numbers (any numeric type is read as `f64`).
pub(super) fn read_points(lx: &mut Lexer<'_>, line: usize) -> Result<Points, IoError> {
    let (n, _) = lx.usize("POINTS count")?;
    lx.token("POINTS data type")?;
    let mut nodes = Vec::with_capacity(n.min(MAX_PREALLOC));
    let mut first_nonzero_z = None;
    for v in 0..n {
        let (x, _) = lx.number("point x")?;
        let (y, _) = lx.number("point y")?;
        let (z, zline) = lx.number("point z")?;
        if z != 0.0 && first_nonzero_z.is_none() {
            first_nonzero_z = Some((v, zline, z));
        }
        nodes.push(DVec3::new(x, y, z));
    }
    if lx
        .peek()
        .is_some_and(|(t, _)| t.eq_ignore_ascii_case("METADATA"))
    {
        lx.skip_block_to_blank_line();
    }
    Ok(Points {
        nodes,
        line,
        first_nonzero_z,
    })
}

/// `CELLS n size` in the classic form (`k i1 … ik` per cell) or the VTK 5 form
/// (`OFFSETS type` + `n` offsets, `CONNECTIVITY type` + `size` ids; here `n` is cells + 1).
pub(super) fn read_cells(lx: &mut Lexer<'_>, header_line: usize) -> Result<Cells, IoError> {
    let (n, _) = lx.usize("CELLS count")?;
    let (size, _) = lx.usize("CELLS size")?;
    let path = lx.path();
    if lx
        .peek()
        .is_some_and(|(t, _)| t.eq_ignore_ascii_case("OFFSETS"))
    {
        lx.next();
        lx.token("OFFSETS data type")?;
        let mut offsets = Vec::with_capacity(n.min(MAX_PREALLOC));
        let mut lines = Vec::with_capacity(n.min(MAX_PREALLOC));
        for c in 0..n {
            let (o, line) = lx.usize("cell offset")?;
            let prev = offsets.last().copied();
            if (c == 0 && o != 0) || prev.is_some_and(|p| o < p) || o > size {
                return Err(lx.malformed(
                    line,
                    format!("offset {c} = {o}: offsets must start at 0, not decrease and not exceed {size}"),
                ));
            }
            offsets.push(o);
            lines.push(line);
        }
        let last = offsets.last().copied().unwrap_or(0);
        if last != size {
            return Err(count_mismatch(
                path,
                header_line,
                "last OFFSETS entry vs CONNECTIVITY size",
                size,
                last,
            ));
        }
        lx.keyword("CONNECTIVITY")?;
        lx.token("CONNECTIVITY data type")?;
        let mut conn = Vec::with_capacity(size.min(MAX_PREALLOC));
        for _ in 0..size {
            conn.push(lx.usize("node id")?.0);
        }
        // One line per cell, for the cells (offsets has one more entry than cells).
        lines.pop();
        if offsets.is_empty() {
            offsets.push(0);
        }
        return Ok(Cells {
            offsets,
            conn,
            lines,
            header_line,
        });
    }
    let mut offsets = Vec::with_capacity(n.min(MAX_PREALLOC).saturating_add(1));
    offsets.push(0);
    let mut lines = Vec::with_capacity(n.min(MAX_PREALLOC));
    let mut conn = Vec::with_capacity(size.min(MAX_PREALLOC));
    let mut consumed: usize = 0;
    for _ in 0..n {
        let (k, line) = lx.usize("number of nodes of a cell")?;
        consumed = consumed.saturating_add(k).saturating_add(1);
        if consumed > size {
            return Err(count_mismatch(
                path,
                header_line,
                "CELLS size (total number of integers)",
                size,
                consumed,
            ));
        }
        for _ in 0..k {
            conn.push(lx.usize("node id")?.0);
        }
        offsets.push(conn.len());
        lines.push(line);
    }
    if consumed != size {
        return Err(count_mismatch(
            path,
            header_line,
            "CELLS size (total number of integers)",
            size,
            consumed,
        ));
    }
    Ok(Cells {
        offsets,
        conn,
        lines,
        header_line,
    })
}

/// `CELL_TYPES n` and `n` integers, which must all be 9 or all be 12.
pub(super) fn read_cell_types(lx: &mut Lexer<'_>, line: usize) -> Result<CellTypes, IoError> {
    let (n, _) = lx.usize("CELL_TYPES count")?;
    let mut kind: Option<u8> = None;
    for c in 0..n {
        let (t, tline) = lx.token("cell type")?;
        let ty: i64 = t.parse().map_err(|_| {
            lx.malformed(
                tline,
                format!("cell type: expected an integer, found {t:?}"),
            )
        })?;
        let ok = match kind {
            None => ty == i64::from(VTK_QUAD) || ty == i64::from(VTK_HEXAHEDRON),
            Some(k) => ty == i64::from(k),
        };
        if !ok {
            return Err(IoError::UnsupportedCellType {
                path: lx.pb(),
                line: tline,
                cell: c,
                cell_type: ty,
            });
        }
        // `ty` is 9 or 12 here.
        kind = Some(if ty == i64::from(VTK_QUAD) {
            VTK_QUAD
        } else {
            VTK_HEXAHEDRON
        });
    }
    Ok(CellTypes {
        kind,
        count: n,
        line,
    })
}

/// An attribute inside `CELL_DATA`/`POINT_DATA` with `n` tuples; one-component `SCALARS` are
/// stored in `target`, everything else is consumed and dropped.
pub(super) fn read_attribute(
    lx: &mut Lexer<'_>,
    kw: &str,
    line: usize,
    n: usize,
    target: &mut Arrays,
) -> Result<(), IoError> {
    match kw {
        "SCALARS" => {
            let (name, _) = lx.token("SCALARS name")?;
            lx.token("SCALARS data type")?;
            // Optional number of components, on the same line.
            let mut ncomp = 1;
            if let Some((t, tl)) = lx.peek() {
                if tl == line {
                    ncomp = t.parse::<usize>().map_err(|_| {
                        lx.malformed(
                            tl,
                            format!("SCALARS: expected the number of components, found {t:?}"),
                        )
                    })?;
                    lx.next();
                    if !(1..=4).contains(&ncomp) {
                        return Err(lx.malformed(
                            tl,
                            format!("SCALARS with {ncomp} components (1 to 4 allowed)"),
                        ));
                    }
                }
            }
            if lx
                .peek()
                .is_some_and(|(t, _)| t.eq_ignore_ascii_case("LOOKUP_TABLE"))
            {
                lx.next();
                lx.token("LOOKUP_TABLE name")?;
            }
            let count = lx.mul(n, ncomp, line, "SCALARS")?;
            let values = lx.numbers(count, &format!("SCALARS {name} value"))?;
            if ncomp == 1 {
                target.push((name.to_string(), values));
            }
        }
        "LOOKUP_TABLE" => {
            // A table definition: name, size, then size RGBA tuples.
            lx.token("LOOKUP_TABLE name")?;
            let (size, _) = lx.usize("LOOKUP_TABLE size")?;
            let count = lx.mul(size, 4, line, "LOOKUP_TABLE")?;
            lx.numbers(count, "LOOKUP_TABLE value")?;
        }
        "COLOR_SCALARS" => {
            lx.token("COLOR_SCALARS name")?;
            let (nv, _) = lx.usize("COLOR_SCALARS number of values")?;
            let count = lx.mul(n, nv, line, "COLOR_SCALARS")?;
            lx.numbers(count, "COLOR_SCALARS value")?;
        }
        "TEXTURE_COORDINATES" => {
            lx.token("TEXTURE_COORDINATES name")?;
            let (dim, _) = lx.usize("TEXTURE_COORDINATES dimension")?;
            lx.token("TEXTURE_COORDINATES data type")?;
            let count = lx.mul(n, dim, line, "TEXTURE_COORDINATES")?;
            lx.numbers(count, "TEXTURE_COORDINATES value")?;
        }
        _ => {
            // VECTORS, NORMALS (3), TENSORS (9), TENSORS6 (6).
            let width = match kw {
                "TENSORS" => 9,
                "TENSORS6" => 6,
                _ => 3,
            };
            lx.token("attribute name")?;
            lx.token("attribute data type")?;
            let count = lx.mul(n, width, line, kw)?;
            lx.numbers(count, &format!("{kw} value"))?;
        }
    }
    if lx
        .peek()
        .is_some_and(|(t, _)| t.eq_ignore_ascii_case("METADATA"))
    {
        lx.skip_block_to_blank_line();
    }
    Ok(())
}

/// `FIELD name k` followed by `k` arrays `name ncomp ntuples type` + values. One-component
/// arrays with exactly the section's tuple count are kept when `keep` is given.
pub(super) fn read_field(
    lx: &mut Lexer<'_>,
    mut keep: Option<(usize, &mut Arrays)>,
) -> Result<(), IoError> {
    lx.token("FIELD name")?;
    let (k, _) = lx.usize("FIELD number of arrays")?;
    for _ in 0..k {
        let (name, aline) = lx.token("FIELD array name")?;
        let (ncomp, _) = lx.usize("FIELD array components")?;
        let (ntuples, _) = lx.usize("FIELD array tuples")?;
        lx.token("FIELD array data type")?;
        let count = lx.mul(ncomp, ntuples, aline, "FIELD array")?;
        let values = lx.numbers(count, &format!("FIELD array {name} value"))?;
        if let Some((n, target)) = keep.as_mut() {
            if ncomp == 1 && ntuples == *n {
                target.push((name.to_string(), values));
            }
        }
        if lx
            .peek()
            .is_some_and(|(t, _)| t.eq_ignore_ascii_case("METADATA"))
        {
            lx.skip_block_to_blank_line();
        }
    }
    Ok(())
}
