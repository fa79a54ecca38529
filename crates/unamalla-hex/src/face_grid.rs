//! The face-grid text format: a logically hexahedral region given as a directory of six files
//! `i_min.txt` … `k_max.txt`, one structured grid of boundary points per face (read, parse,
//! write).

use std::path::Path;

use unamalla_mesh::hexgen::{FaceGrid, HexFaceId, HexRegion};
use unamalla_mesh::DVec3;

use crate::HexError;

/// Reads a region given as a directory of six face grids `i_min.txt`, `i_max.txt`,
/// `j_min.txt`, `j_max.txt`, `k_min.txt`, `k_max.txt` and returns it validated
/// ([`HexRegion::from_face_grids`]).
///
/// Each file: optional `#` comment lines, a line `a b` (points along the face's first and
/// second directions: `(j, k)` on the `i` faces, `(i, k)` on the `j` faces, `(i, j)` on the
/// `k` faces), then `a·b` lines `x y z`, first direction fastest (the layout of
/// [`unamalla_mesh::HexFaces`]).
pub fn read_face_dir(dir: &Path) -> Result<HexRegion, HexError> {
    let mut grids = Vec::with_capacity(6);
    for id in HexFaceId::ALL {
        let path = dir.join(format!("{}.txt", id.name()));
        let text = std::fs::read_to_string(&path).map_err(|e| HexError::FaceFile {
            path: path.clone(),
            line: 0,
            reason: e.to_string(),
        })?;
        grids.push(parse_face_grid(&path, &text)?);
    }
    let faces: [FaceGrid; 6] = grids.try_into().map_err(|_| HexError::FaceFile {
        path: dir.to_path_buf(),
        line: 0,
        reason: "expected six face grids".into(),
    })?;
    Ok(HexRegion::from_face_grids(faces)?)
}

/// Parses one face-grid file (see [`read_face_dir`]); `path` is only used in errors.
pub fn parse_face_grid(path: &Path, text: &str) -> Result<FaceGrid, HexError> {
    let err = |line: usize, reason: String| HexError::FaceFile {
        path: path.to_path_buf(),
        line,
        reason,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (ln, head) = lines
        .next()
        .ok_or_else(|| err(0, "empty file; expected a line 'a b'".into()))?;
    let dims: Vec<usize> = head
        .split_whitespace()
        .map(|t| t.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| err(ln, format!("expected two point counts 'a b', got '{head}'")))?;
    let [a, b] = <[usize; 2]>::try_from(dims)
        .map_err(|_| err(ln, format!("expected two point counts 'a b', got '{head}'")))?;
    if a < 2 || b < 2 {
        return Err(err(
            ln,
            format!("a face grid needs at least 2 × 2 points, got {a} × {b}"),
        ));
    }
    let mut points = Vec::with_capacity(a.saturating_mul(b).min(1 << 24));
    for (ln, l) in lines {
        let v: Vec<f64> = l
            .split_whitespace()
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| err(ln, format!("expected 'x y z', got '{l}'")))?;
        let [x, y, z] = <[f64; 3]>::try_from(v)
            .map_err(|_| err(ln, format!("expected three coordinates 'x y z', got '{l}'")))?;
        points.push(DVec3::new(x, y, z));
    }
    if points.len() != a * b {
        return Err(err(
            0,
            format!(
                "{a} × {b} face needs {} points, found {}",
                a * b,
                points.len()
            ),
        ));
    }
    Ok(FaceGrid { a, b, points })
}

/// Writes the six faces of a region in the format of [`read_face_dir`] (atomically).
pub fn write_face_dir(region: &HexRegion, dir: &Path) -> Result<(), HexError> {
    let (m, n, p) = region.dims();
    for id in HexFaceId::ALL {
        let (a, b) = match id {
            HexFaceId::IMin | HexFaceId::IMax => (n, p),
            HexFaceId::JMin | HexFaceId::JMax => (m, p),
            HexFaceId::KMin | HexFaceId::KMax => (m, n),
        };
        let pts = region.face(id);
        let path = dir.join(format!("{}.txt", id.name()));
        unamalla_io::atomic_write(&path, |w| {
            writeln!(w, "# face {} of a {m} x {n} x {p} region", id.thesis_name())?;
            writeln!(w, "{a} {b}")?;
            for q in pts {
                writeln!(w, "{} {} {}", q.x, q.y, q.z)?;
            }
            Ok(())
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HexCase;
    use unamalla_mesh::HasNodes;

    #[test]
    fn face_files_round_trip_and_bad_files_name_the_line() {
        let g = HexCase::Cosin.initial_grid((4, 5, 6)).unwrap();
        let r = HexRegion::of_grid(&g);
        let dir = std::env::temp_dir().join(format!("unamalla-hexfaces-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_face_dir(&r, &dir).unwrap();
        let back = read_face_dir(&dir).unwrap();
        assert_eq!(back.dims(), (4, 5, 6));
        let t = back.tfi().unwrap();
        assert!(t
            .nodes()
            .iter()
            .zip(g.nodes())
            .all(|(a, b)| a.distance(*b) < 1e-9));
        let e = parse_face_grid(Path::new("f.txt"), "# c\n2 2\n0 0 0\n1 0 x\n").unwrap_err();
        assert!(e.to_string().contains("f.txt: line 4"), "{e}");
        let e = parse_face_grid(Path::new("f.txt"), "2 2\n0 0 0\n").unwrap_err();
        assert!(e.to_string().contains("needs 4 points, found 1"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
