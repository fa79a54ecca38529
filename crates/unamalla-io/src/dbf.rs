//! dBASE III attribute tables (`.dbf`), the attribute part of a shapefile, read as text.
//!
//! Layout (dBASE III+ file structure, as used by the ESRI Shapefile Technical Description):
//! a 32-byte header — byte 0 version, bytes 4..8 the record count (`u32` LE), 8..10 the header
//! length (`u16` LE), 10..12 the record length (`u16` LE) — then 32-byte field descriptors
//! (name: 11 bytes, NUL-padded; type at byte 11; length at byte 16) ended by `0x0D`; then the
//! records, each a deletion flag (`*` = deleted, kept here so record `k` is shape `k`) and the
//! fields' fixed-width text. Values are returned trimmed of blanks; bytes that are not UTF-8
//! are replaced (U+FFFD). Every offset is checked against the file's length.

use std::path::Path;

use crate::error::IoError;

/// The records of a `.dbf` file: per record, `(field name, trimmed value)` in field order.
pub fn read_dbf(path: impl AsRef<Path>) -> Result<Vec<Vec<(String, String)>>, IoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_dbf_at(&bytes, path)
}

/// Like [`read_dbf`] for the bytes of a `.dbf` file held in memory.
pub fn parse_dbf(bytes: &[u8]) -> Result<Vec<Vec<(String, String)>>, IoError> {
    parse_dbf_at(bytes, Path::new(crate::geojson::STRING_SOURCE))
}

fn parse_dbf_at(b: &[u8], path: &Path) -> Result<Vec<Vec<(String, String)>>, IoError> {
    let bad = |offset: usize, problem: &str| IoError::MalformedBinary {
        path: path.to_path_buf(),
        offset: offset as u64,
        message: problem.to_string(),
    };
    if b.len() < 32 {
        return Err(bad(0, "a .dbf file has a 32-byte header"));
    }
    let nrec = u32::from_le_bytes([b[4], b[5], b[6], b[7]]) as usize;
    let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
    let rlen = u16::from_le_bytes([b[10], b[11]]) as usize;
    if hlen > b.len() || hlen < 33 {
        return Err(bad(8, "header length outside the file"));
    }
    let mut fields: Vec<(String, usize)> = Vec::new();
    let mut off = 32;
    while off + 32 <= hlen && b[off] != 0x0D {
        let name = &b[off..off + 11];
        let end = name.iter().position(|&c| c == 0).unwrap_or(11);
        let name = String::from_utf8_lossy(&name[..end]).trim().to_string();
        fields.push((name, b[off + 16] as usize));
        off += 32;
    }
    if 1 + fields.iter().map(|f| f.1).sum::<usize>() > rlen {
        return Err(bad(10, "record length shorter than its fields"));
    }
    if nrec.saturating_mul(rlen) > b.len() - hlen {
        return Err(bad(4, "more records than the file holds"));
    }
    let mut out = Vec::with_capacity(nrec);
    for r in 0..nrec {
        let mut pos = hlen + r * rlen + 1;
        let mut rec = Vec::with_capacity(fields.len());
        for (name, len) in &fields {
            let v = String::from_utf8_lossy(&b[pos..pos + len])
                .trim()
                .to_string();
            rec.push((name.clone(), v));
            pos += len;
        }
        out.push(rec);
    }
    Ok(out)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A `.dbf` with character fields (`name`, width) and the given rows.
    pub(crate) fn encode(fields: &[(&str, usize)], rows: &[Vec<&str>]) -> Vec<u8> {
        let rlen = 1 + fields.iter().map(|f| f.1).sum::<usize>();
        let hlen = 32 + 32 * fields.len() + 1;
        let mut b = vec![0u8; 32];
        b[0] = 3;
        b[4..8].copy_from_slice(&(rows.len() as u32).to_le_bytes());
        b[8..10].copy_from_slice(&(hlen as u16).to_le_bytes());
        b[10..12].copy_from_slice(&(rlen as u16).to_le_bytes());
        for (name, len) in fields {
            let mut d = vec![0u8; 32];
            d[..name.len()].copy_from_slice(name.as_bytes());
            d[11] = b'C';
            d[16] = *len as u8;
            b.extend(d);
        }
        b.push(0x0D);
        for row in rows {
            b.push(b' ');
            for ((_, len), v) in fields.iter().zip(row) {
                let mut cell = v.as_bytes().to_vec();
                cell.resize(*len, b' ');
                b.extend(cell);
            }
        }
        b.push(0x1A);
        b
    }

    #[test]
    fn records_read_back_trimmed() {
        let b = encode(
            &[("NAME", 10), ("ID", 3)],
            &[vec!["Texas", "48"], vec!["Utah", "49"]],
        );
        let r = parse_dbf(&b).unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!(
            r[1],
            vec![("NAME".into(), "Utah".into()), ("ID".into(), "49".into())]
        );
        let mut short = b.clone();
        short.truncate(60);
        assert!(parse_dbf(&short).is_err());
        assert!(parse_dbf(&b[..10]).is_err());
    }
}
