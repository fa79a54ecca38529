//! Plain-text regions: one `x y` point per line, a blank line between rings.
//!
//! ```text
//! # outer ring (any orientation; closing point optional)
//! 0 0
//! 4 0
//! 4 3
//! 0 3
//!
//! # a hole
//! 1 1
//! 1 2
//! 2 2
//! ```
//!
//! The first ring is the outer boundary, the others are holes; orientation is normalised by
//! [`Region::new`]. A line may carry a third number (ignored, e.g. an elevation); `#` starts a
//! comment; lines that are empty apart from a comment do not separate rings; several blank
//! lines count as one separator. A final point equal to the first is dropped.
//! [`write_region_text`] writes the region's rings (open, outer counter-clockwise, holes
//! clockwise) in the shortest round-trip number form, so write → read is exact.

use std::path::Path;

use unamalla_mesh::{DVec2, Region};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::{read_text, STRING_SOURCE};
use crate::lex::parse_f64;

/// Reads the rings of a plain-text region file, as written (not validated).
pub fn read_rings_text(path: impl AsRef<Path>) -> Result<Vec<Vec<DVec2>>, IoError> {
    let path = path.as_ref();
    rings_at(&read_text(path)?, path)
}

/// Like [`read_rings_text`], for text held in memory.
pub fn parse_rings_text(text: &str) -> Result<Vec<Vec<DVec2>>, IoError> {
    rings_at(text, Path::new(STRING_SOURCE))
}

/// Reads a plain-text region file: ring 0 is the outer boundary, the others holes.
pub fn read_region_text(path: impl AsRef<Path>) -> Result<Region, IoError> {
    let path = path.as_ref();
    to_region(rings_at(&read_text(path)?, path)?, path)
}

/// Like [`read_region_text`], for text held in memory.
pub fn parse_region_text(text: &str) -> Result<Region, IoError> {
    let path = Path::new(STRING_SOURCE);
    to_region(rings_at(text, path)?, path)
}

fn to_region(mut rings: Vec<Vec<DVec2>>, path: &Path) -> Result<Region, IoError> {
    let holes = rings.split_off(1);
    let outer = rings.pop().unwrap_or_default();
    Region::new(outer, holes).map_err(|source| IoError::InvalidRegion {
        path: path.to_path_buf(),
        source,
    })
}

fn rings_at(text: &str, path: &Path) -> Result<Vec<Vec<DVec2>>, IoError> {
    let mut rings: Vec<Vec<DVec2>> = Vec::new();
    let mut cur: Vec<DVec2> = Vec::new();
    let close = |cur: &mut Vec<DVec2>, rings: &mut Vec<Vec<DVec2>>| {
        if cur.len() >= 2 && cur.first() == cur.last() {
            cur.pop();
        }
        if !cur.is_empty() {
            rings.push(std::mem::take(cur));
        }
    };
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let content = raw.split('#').next().unwrap_or("");
        if content.trim().is_empty() {
            if raw.trim().is_empty() {
                close(&mut cur, &mut rings);
            }
            continue;
        }
        let nums: Vec<&str> = content.split_whitespace().collect();
        let bad = |message: String| IoError::Malformed {
            path: path.to_path_buf(),
            line,
            message,
        };
        if !(2..=3).contains(&nums.len()) {
            return Err(bad(format!(
                "expected `x y` (or `x y z`), found {} value(s)",
                nums.len()
            )));
        }
        let mut xy = [0.0; 2];
        for (v, t) in xy.iter_mut().zip(&nums) {
            *v = parse_f64(t)
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad(format!("expected a finite number, found {t:?}")))?;
        }
        if let Some(t) = nums.get(2) {
            if parse_f64(t).is_none() {
                return Err(bad(format!("expected a number, found {t:?}")));
            }
        }
        cur.push(DVec2::new(xy[0], xy[1]));
    }
    close(&mut cur, &mut rings);
    if rings.is_empty() {
        return Err(IoError::Truncated {
            path: path.to_path_buf(),
            line: text.lines().count().max(1),
            expected: "at least one ring of `x y` points".into(),
        });
    }
    Ok(rings)
}

/// Writes a region as plain text: the outer ring, then each hole after a blank line.
pub fn write_region_text(path: impl AsRef<Path>, region: &Region) -> Result<(), IoError> {
    let path = path.as_ref();
    atomic_write(path, |w| {
        for (k, ring) in region.rings().enumerate() {
            if k > 0 {
                writeln!(w)?;
            }
            for p in ring.points() {
                writeln!(w, "{:?} {:?}", p.x, p.y)?;
            }
        }
        Ok(())
    })
}
