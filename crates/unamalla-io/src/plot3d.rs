//! Plot3D grid files (NASA Glenn, "PLOT3D File Format for Grid and Solution Files"),
//! multi-block "whole" grids, 2D and 3D, formatted ASCII or Fortran-unformatted binary.
//!
//! Layout (3D; 2D drops `nk` and `z`):
//!
//! ```text
//! nblocks
//! ni_1 nj_1 nk_1   ni_2 nj_2 nk_2   …
//! block 1: all x, then all y, then all z, each with i fastest, then j, then k
//! block 2: …
//! ```
//!
//! * **ASCII** ([`Plot3dFormat::Ascii`]): whitespace-separated, the block sizes one block per
//!   line, 5 numbers per line; numbers in the shortest round-trip form (the reader also accepts
//!   Fortran `D` exponents), so write → read is exact.
//! * **Fortran unformatted** ([`Plot3dFormat::FortranBinary`]), the common flavour: three kinds
//!   of sequential records, each framed by a 4-byte little-endian record length before and
//!   after: `nblocks` (`i32`), all block sizes (`i32`s), then one record per block with x, y (and
//!   z) as little-endian `f64`. No IBLANK. Records longer than `i32::MAX` bytes (Fortran
//!   sub-records) are not written ([`IoError::Unrepresentable`]) nor read.
//!
//! The format does not say whether it is 2D or 3D, so the reader is told ([`Plot3dDim`]).
//! The node order of a Plot3D block is the node order of [`StructuredGrid2`] /
//! [`StructuredGrid3`] (i fastest), so blocks map one to one. ASCII errors carry line numbers,
//! binary errors byte offsets ([`IoError::MalformedBinary`]); nothing panics on any input.

use std::io::Write;
use std::path::Path;

use unamalla_mesh::{DVec2, DVec3, HasNodes, StructuredGrid2, StructuredGrid3};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::STRING_SOURCE;
use crate::lex::{Lexer, MAX_PREALLOC};

/// ASCII or Fortran-unformatted binary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plot3dFormat {
    /// Formatted (text) file.
    Ascii,
    /// Fortran sequential unformatted file: 4-byte little-endian record markers, `i32` sizes,
    /// `f64` coordinates.
    FortranBinary,
}

/// Whether a file holds 2D (`ni nj`, x y) or 3D (`ni nj nk`, x y z) blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plot3dDim {
    /// 2D blocks.
    D2,
    /// 3D blocks.
    D3,
}

/// The blocks of a Plot3D file.
#[derive(Debug, Clone, PartialEq)]
pub enum Plot3dBlocks {
    /// 2D blocks.
    D2(Vec<StructuredGrid2>),
    /// 3D blocks.
    D3(Vec<StructuredGrid3>),
}

/// One block in a uniform shape for the writers: dims and coordinate arrays.
struct Block {
    dims: Vec<usize>,
    coords: Vec<Vec<f64>>,
}

fn blocks2(b: &[StructuredGrid2]) -> Vec<Block> {
    b.iter()
        .map(|g| Block {
            dims: vec![g.m(), g.n()],
            coords: vec![
                g.nodes().iter().map(|p| p.x).collect(),
                g.nodes().iter().map(|p| p.y).collect(),
            ],
        })
        .collect()
}

fn blocks3(b: &[StructuredGrid3]) -> Vec<Block> {
    b.iter()
        .map(|g| {
            let (m, n, p) = g.dims();
            Block {
                dims: vec![m, n, p],
                coords: vec![
                    g.nodes().iter().map(|q| q.x).collect(),
                    g.nodes().iter().map(|q| q.y).collect(),
                    g.nodes().iter().map(|q| q.z).collect(),
                ],
            }
        })
        .collect()
}

/// Writes 2D blocks (`ni nj`, x, y).
pub fn write_plot3d2(
    path: impl AsRef<Path>,
    blocks: &[StructuredGrid2],
    format: Plot3dFormat,
) -> Result<(), IoError> {
    write_blocks(path.as_ref(), &blocks2(blocks), format)
}

/// Writes 3D blocks (`ni nj nk`, x, y, z).
pub fn write_plot3d3(
    path: impl AsRef<Path>,
    blocks: &[StructuredGrid3],
    format: Plot3dFormat,
) -> Result<(), IoError> {
    write_blocks(path.as_ref(), &blocks3(blocks), format)
}

fn write_blocks(path: &Path, blocks: &[Block], format: Plot3dFormat) -> Result<(), IoError> {
    let too_big = |what: String| IoError::Unrepresentable {
        path: path.to_path_buf(),
        reason: what,
    };
    let i32_of = |v: usize, what: &str| {
        i32::try_from(v).map_err(|_| too_big(format!("{what} {v} does not fit an i32")))
    };
    match format {
        Plot3dFormat::Ascii => atomic_write(path, |w| {
            writeln!(w, "{}", blocks.len())?;
            for b in blocks {
                let d: Vec<String> = b.dims.iter().map(|d| d.to_string()).collect();
                writeln!(w, "{}", d.join(" "))?;
            }
            for b in blocks {
                for c in &b.coords {
                    for chunk in c.chunks(5) {
                        let s: Vec<String> = chunk.iter().map(|v| format!("{v:?}")).collect();
                        writeln!(w, "{}", s.join(" "))?;
                    }
                }
            }
            Ok(())
        }),
        Plot3dFormat::FortranBinary => {
            // Validate every size first.
            let nb = i32_of(blocks.len(), "number of blocks")?;
            let mut dims = Vec::new();
            for b in blocks {
                for &d in &b.dims {
                    dims.push(i32_of(d, "block size")?);
                }
            }
            let marker = |bytes: usize| {
                u32::try_from(bytes)
                    .ok()
                    .filter(|&b| b <= i32::MAX as u32)
                    .ok_or_else(|| {
                        too_big(format!(
                            "a record of {bytes} bytes exceeds the 2^31 − 1 byte record limit"
                        ))
                    })
            };
            let dims_len = marker(dims.len() * 4)?;
            let mut block_lens = Vec::with_capacity(blocks.len());
            for b in blocks {
                let n: usize = b.coords.iter().map(Vec::len).sum();
                block_lens.push(marker(n.saturating_mul(8))?);
            }
            atomic_write(path, |w| {
                let rec =
                    |w: &mut dyn Write,
                     len: u32,
                     body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>| {
                        w.write_all(&len.to_le_bytes())?;
                        body(w)?;
                        w.write_all(&len.to_le_bytes())
                    };
                rec(w, 4, &|w| w.write_all(&nb.to_le_bytes()))?;
                rec(w, dims_len, &|w| {
                    for d in &dims {
                        w.write_all(&d.to_le_bytes())?;
                    }
                    Ok(())
                })?;
                for (b, &len) in blocks.iter().zip(&block_lens) {
                    rec(w, len, &|w| {
                        for c in &b.coords {
                            for v in c {
                                w.write_all(&v.to_le_bytes())?;
                            }
                        }
                        Ok(())
                    })?;
                }
                Ok(())
            })
        }
    }
}

/// Reads a Plot3D grid file of the given dimension and format.
pub fn read_plot3d(
    path: impl AsRef<Path>,
    dim: Plot3dDim,
    format: Plot3dFormat,
) -> Result<Plot3dBlocks, IoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    match format {
        Plot3dFormat::FortranBinary => parse_binary_at(&bytes, dim, path),
        Plot3dFormat::Ascii => match std::str::from_utf8(&bytes) {
            Ok(t) => parse_ascii_at(t, dim, path),
            Err(e) => Err(IoError::Malformed {
                path: path.to_path_buf(),
                line: bytes[..e.valid_up_to()]
                    .iter()
                    .filter(|&&b| b == b'\n')
                    .count()
                    + 1,
                message: "not a text file (is it a binary Plot3D file?)".into(),
            }),
        },
    }
}

/// Parses an ASCII Plot3D file held in memory.
pub fn parse_plot3d_ascii(text: &str, dim: Plot3dDim) -> Result<Plot3dBlocks, IoError> {
    parse_ascii_at(text, dim, Path::new(STRING_SOURCE))
}

/// Parses a Fortran-unformatted Plot3D file held in memory.
pub fn parse_plot3d_binary(bytes: &[u8], dim: Plot3dDim) -> Result<Plot3dBlocks, IoError> {
    parse_binary_at(bytes, dim, Path::new(STRING_SOURCE))
}

fn nd(dim: Plot3dDim) -> usize {
    match dim {
        Plot3dDim::D2 => 2,
        Plot3dDim::D3 => 3,
    }
}

/// Number of nodes of a block, or a message.
fn block_nodes(d: &[usize]) -> Result<usize, String> {
    if d.iter().any(|&x| x < 2) {
        return Err(format!("block size {d:?}: every size must be at least 2"));
    }
    d.iter()
        .try_fold(1usize, |a, &x| a.checked_mul(x))
        .ok_or_else(|| format!("block size {d:?} too large"))
}

fn build(
    dim: Plot3dDim,
    dims: &[Vec<usize>],
    coords: Vec<Vec<f64>>,
) -> Result<Plot3dBlocks, unamalla_mesh::MeshError> {
    // `coords[b]` holds x…, y…(, z…) of block b.
    Ok(match dim {
        Plot3dDim::D2 => {
            let mut out = Vec::with_capacity(dims.len());
            for (d, c) in dims.iter().zip(coords) {
                let n = d[0] * d[1];
                let nodes = (0..n).map(|k| DVec2::new(c[k], c[n + k])).collect();
                out.push(StructuredGrid2::new(d[0], d[1], nodes)?);
            }
            Plot3dBlocks::D2(out)
        }
        Plot3dDim::D3 => {
            let mut out = Vec::with_capacity(dims.len());
            for (d, c) in dims.iter().zip(coords) {
                let n = d[0] * d[1] * d[2];
                let nodes = (0..n)
                    .map(|k| DVec3::new(c[k], c[n + k], c[2 * n + k]))
                    .collect();
                out.push(StructuredGrid3::new(d[0], d[1], d[2], nodes)?);
            }
            Plot3dBlocks::D3(out)
        }
    })
}

fn parse_ascii_at(text: &str, dim: Plot3dDim, path: &Path) -> Result<Plot3dBlocks, IoError> {
    let mut lx = Lexer::new(text, path);
    let k = nd(dim);
    let (nb, _) = lx.usize("number of blocks")?;
    let mut dims = Vec::with_capacity(nb.min(MAX_PREALLOC));
    for b in 0..nb {
        let mut d = Vec::with_capacity(k);
        let mut line = 0;
        for a in ["ni", "nj", "nk"].iter().take(k) {
            let (v, l) = lx.usize(&format!("{a} of block {}", b + 1))?;
            d.push(v);
            line = l;
        }
        block_nodes(&d).map_err(|m| lx.malformed(line, m))?;
        dims.push(d);
    }
    let mut coords = Vec::with_capacity(nb.min(MAX_PREALLOC));
    for (b, d) in dims.iter().enumerate() {
        let n = block_nodes(d).unwrap_or(0);
        let total = lx.mul(n, k, lx.line(), "block size")?;
        let mut c = Vec::with_capacity(total.min(MAX_PREALLOC));
        for _ in 0..total {
            c.push(lx.f64(&format!("coordinate of block {}", b + 1))?.0);
        }
        coords.push(c);
    }
    lx.expect_end("the last block")?;
    build(dim, &dims, coords).map_err(|source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    })
}

struct Bin<'a> {
    bytes: &'a [u8],
    pos: usize,
    path: &'a Path,
}

impl<'a> Bin<'a> {
    fn err(&self, offset: usize, message: String) -> IoError {
        IoError::MalformedBinary {
            path: self.path.to_path_buf(),
            offset: offset as u64,
            message,
        }
    }

    fn u32_at(&self, at: usize) -> Option<u32> {
        let b = self.bytes.get(at..at.checked_add(4)?)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// The next record's body and its offset.
    fn record(&mut self, what: &str) -> Result<(&'a [u8], usize), IoError> {
        let start = self.pos;
        let len = self.u32_at(start).ok_or_else(|| {
            self.err(
                start,
                format!("end of file where the record of {what} should start"),
            )
        })? as usize;
        let body = start + 4;
        let end = body
            .checked_add(len)
            .filter(|&e| e.checked_add(4).is_some_and(|t| t <= self.bytes.len()))
            .ok_or_else(|| {
                self.err(
                    start,
                    format!(
                        "record of {what} announces {len} bytes, but only {} remain",
                        self.bytes.len().saturating_sub(body)
                    ),
                )
            })?;
        let trailer = self.u32_at(end).unwrap_or(u32::MAX) as usize;
        if trailer != len {
            return Err(self.err(
                end,
                format!(
                    "record of {what}: trailing marker {trailer} differs from leading marker {len}"
                ),
            ));
        }
        self.pos = end + 4;
        Ok((&self.bytes[body..end], body))
    }
}

fn parse_binary_at(bytes: &[u8], dim: Plot3dDim, path: &Path) -> Result<Plot3dBlocks, IoError> {
    let mut r = Bin {
        bytes,
        pos: 0,
        path,
    };
    let k = nd(dim);
    let i32s = |b: &[u8]| -> Vec<i32> {
        b.chunks_exact(4)
            .map(|c| i32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let (rec, off) = r.record("the number of blocks")?;
    if rec.len() != 4 {
        return Err(r.err(
            off,
            format!(
                "the number-of-blocks record has {} bytes, expected 4",
                rec.len()
            ),
        ));
    }
    let nb = i32s(rec)[0];
    let nb =
        usize::try_from(nb).map_err(|_| r.err(off, format!("negative number of blocks {nb}")))?;
    let (rec, off) = r.record("the block sizes")?;
    let want = nb.saturating_mul(4 * k);
    if rec.len() != want {
        return Err(r.err(
            off,
            format!(
                "the block-size record has {} bytes, expected {want} ({nb} blocks × {k} i32) — is the dimension right?",
                rec.len()
            ),
        ));
    }
    let mut dims = Vec::with_capacity(nb);
    for (b, c) in i32s(rec).chunks_exact(k).enumerate() {
        let d: Vec<usize> = c.iter().map(|&v| usize::try_from(v).unwrap_or(0)).collect();
        block_nodes(&d).map_err(|m| r.err(off + b * 4 * k, m))?;
        dims.push(d);
    }
    let mut coords = Vec::with_capacity(nb);
    for (b, d) in dims.iter().enumerate() {
        let n = block_nodes(d).unwrap_or(0);
        let (rec, off) = r.record(&format!("block {}", b + 1))?;
        let want = n.saturating_mul(8 * k);
        if rec.len() != want {
            return Err(r.err(
                off,
                format!(
                    "block {} record has {} bytes, expected {want} ({n} nodes × {k} f64)",
                    b + 1,
                    rec.len()
                ),
            ));
        }
        let vals: Vec<f64> = rec
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
            .collect();
        if let Some(i) = vals.iter().position(|v| !v.is_finite()) {
            return Err(r.err(
                off + 8 * i,
                format!("block {}: non-finite coordinate", b + 1),
            ));
        }
        coords.push(vals);
    }
    if r.pos != bytes.len() {
        return Err(r.err(
            r.pos,
            format!(
                "{} unexpected bytes after the last block",
                bytes.len() - r.pos
            ),
        ));
    }
    build(dim, &dims, coords).map_err(|source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    })
}
