//! The file formats of UNAMALLA v2.0 ([González Flores, §A.5]): contours (`.con`), meshes in
//! "classic" XY and "recent" RED order, and the Geomview `MESH` surface file.
//!
//! All are ASCII. UNAMALLA writes numbers in Fortran `F11.4` and reads them in free format
//! (whitespace-separated, line breaks insignificant), so the readers here are token based and
//! also accept Fortran `D` exponents. The writers keep UNAMALLA's layout (fields right-aligned
//! in 11 columns, 7 values per line for XY/RED) but write every number in its **shortest
//! round-trip form** instead of `F11.4`, so that write → read is exact; UNAMALLA's free-format
//! reader reads those too.
//!
//! # Contours (`.con`)
//!
//! ```text
//! m ibflag nb1 nb2 nb3 nb4
//! x_1 y_1
//! …
//! x_m y_m          (= x_1 y_1: the contour is closed)
//! ```
//!
//! `m` counts the repeated closing point. `ibflag` ([`Ibflag`]): 0 = sides undefined, 1 = four
//! sides given, 13 = sides 1 and 3 are the same curve (a cut to a hole), 24 = sides 2 and 4 are.
//! `nb1..nb4` are the points per side, counting each corner in both adjacent sides, so
//! `nb1 + nb2 + nb3 + nb4 = (m − 1) + 4`; side 1 (bottom) starts at point 1 and the sides follow
//! counter-clockwise (bottom, right, top, left). [`Contour::region`] turns a contour into a
//! [`Region`]: the closed polyline for `ibflag` 0/1, the two loops (outer and hole, told apart by
//! area) for 13/24.
//!
//! # Meshes (XY, RED)
//!
//! Header line 1 is `m n` (points per horizontal grid line, per vertical grid line), line 2 a
//! file name. UNAMALLA's node `(i, j)` (column `i`, row `j`, 1-based) is node `(i − 1, j − 1)`
//! of a [`StructuredGrid2`]. XY lists `x y` pairs column by column (`j` fastest); RED lists the
//! boundary counter-clockwise from `(1, 1)` — bottom `i = 1..m`, right `j = 2..n`, top
//! `i = m−1..1`, left `j = n−1..2` — and then the interior column by column (`i = 2..m−1`, each
//! `j = 2..n−1`), so the interior starts at real offset `2(2m + 2n − 4)`.
//!
//! # Geomview `MESH`
//!
//! `MESH`, then `Nu Nv`, then `Nu·Nv` lines `x y z` with `u` varying fastest (Geomview's
//! definition). [`write_geomview_mesh`] writes `Nu = m`, `Nv = n` and the nodes in the grid's
//! order (`i` fastest), with `z` given per node (e.g. a PDE solution) or 0. The manual's MESH
//! files have the header `m n` with `j` fastest, which Geomview reads transposed when `m ≠ n`;
//! this writer follows Geomview's definition instead.

use std::path::Path;

use unamalla_mesh::region::signed_area;
use unamalla_mesh::{DVec2, DVec3, GeometryError, HasNodes, Region, StructuredGrid2};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::{read_text, STRING_SOURCE};
use crate::lex::{Lexer, MAX_PREALLOC};

/// How the four sides of a contour are defined (the `ibflag` of a `.con` file).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Ibflag {
    /// 0: the sides are not given; the mesher chooses them.
    Undefined,
    /// 1: the four sides are given by `nb1..nb4`.
    FourSides,
    /// 13: sides 1 and 3 are the same curve (a cut from the outer boundary to a hole).
    Cut13,
    /// 24: sides 2 and 4 are the same curve.
    Cut24,
}

impl Ibflag {
    /// The number written in the file.
    pub fn code(self) -> u32 {
        match self {
            Ibflag::Undefined => 0,
            Ibflag::FourSides => 1,
            Ibflag::Cut13 => 13,
            Ibflag::Cut24 => 24,
        }
    }

    /// The flag with this number, if it is one of 0, 1, 13, 24.
    pub fn from_code(code: i64) -> Option<Self> {
        Some(match code {
            0 => Ibflag::Undefined,
            1 => Ibflag::FourSides,
            13 => Ibflag::Cut13,
            24 => Ibflag::Cut24,
            _ => return None,
        })
    }
}

/// A UNAMALLA contour: a closed polyline with its side partition.
#[derive(Debug, Clone, PartialEq)]
pub struct Contour {
    points: Vec<DVec2>,
    ibflag: Ibflag,
    counts: [usize; 4],
}

impl Contour {
    /// Builds a contour from its points **closed** (the last point equal to the first, as in
    /// the file), its flag and its side counts `nb1..nb4` (ignored, and written as 0, when the
    /// flag is [`Ibflag::Undefined`]). Checks what the reader checks; the message says what is
    /// wrong.
    pub fn new(points: Vec<DVec2>, ibflag: Ibflag, counts: [usize; 4]) -> Result<Self, String> {
        let counts = if ibflag == Ibflag::Undefined {
            [0; 4]
        } else {
            counts
        };
        let c = Self {
            points,
            ibflag,
            counts,
        };
        c.check()?;
        Ok(c)
    }

    /// A contour with undefined sides from an open or closed ring.
    pub fn from_ring(ring: &[DVec2]) -> Result<Self, String> {
        let mut points = ring.to_vec();
        if points.len() >= 2 && points.first() != points.last() {
            points.push(points[0]);
        }
        Self::new(points, Ibflag::Undefined, [0; 4])
    }

    fn check(&self) -> Result<(), String> {
        let m = self.points.len();
        if m < 4 {
            return Err(format!(
                "{m} point(s); a closed contour needs at least 4 (a triangle and its closing point)"
            ));
        }
        if let Some(k) = self.points.iter().position(|p| !p.is_finite()) {
            return Err(format!("point {} is not finite", k + 1));
        }
        if self.points[0] != self.points[m - 1] {
            return Err("the last point must repeat the first (the contour is closed)".into());
        }
        if self.ibflag == Ibflag::Undefined {
            return Ok(());
        }
        if let Some(k) = self.counts.iter().position(|&c| c < 2) {
            return Err(format!(
                "side {} has {} point(s); at least 2 needed",
                k + 1,
                self.counts[k]
            ));
        }
        let sum = self.counts.iter().sum::<usize>();
        if sum != m + 3 {
            return Err(format!(
                "nb1 + nb2 + nb3 + nb4 = {sum}, but must be m + 3 = {} (corners count in both sides)",
                m + 3
            ));
        }
        let s = self.sides();
        let (cut_a, loop_a, cut_b, loop_b) = match self.ibflag {
            Ibflag::Cut13 => (0, 1, 2, 3),
            Ibflag::Cut24 => (1, 2, 3, 0),
            _ => return Ok(()),
        };
        let rev: Vec<DVec2> = s[cut_b].iter().rev().copied().collect();
        if s[cut_a] != rev.as_slice() {
            return Err(format!(
                "ibflag {}: side {} must be side {} reversed (the same cut)",
                self.ibflag.code(),
                cut_b + 1,
                cut_a + 1
            ));
        }
        for l in [loop_a, loop_b] {
            if s[l].len() < 4 || s[l].first() != s[l].last() {
                return Err(format!(
                    "ibflag {}: side {} must be a closed loop of at least 4 points",
                    self.ibflag.code(),
                    l + 1
                ));
            }
        }
        Ok(())
    }

    /// The points, closed (last = first).
    pub fn points(&self) -> &[DVec2] {
        &self.points
    }
    /// The side flag.
    pub fn ibflag(&self) -> Ibflag {
        self.ibflag
    }
    /// `nb1..nb4` (all 0 for [`Ibflag::Undefined`]).
    pub fn counts(&self) -> [usize; 4] {
        self.counts
    }

    /// The four sides as point slices (corners shared by adjacent sides); all empty for
    /// [`Ibflag::Undefined`].
    pub fn sides(&self) -> [&[DVec2]; 4] {
        if self.ibflag == Ibflag::Undefined {
            return [&[]; 4];
        }
        let mut start = 0usize;
        let mut out: [&[DVec2]; 4] = [&[]; 4];
        for (k, &c) in self.counts.iter().enumerate() {
            let end = (start + c).min(self.points.len());
            out[k] = self.points.get(start.min(end)..end).unwrap_or(&[]);
            start = (start + c).saturating_sub(1);
        }
        out
    }

    /// The region the contour bounds: for `ibflag` 0 and 1 the polyline itself; for 13 and 24
    /// the two loops, the one enclosing the larger area being the outer ring and the other the
    /// hole. Orientation is normalised by [`Region::new`].
    pub fn region(&self) -> Result<Region, GeometryError> {
        let open = |s: &[DVec2]| s[..s.len().saturating_sub(1)].to_vec();
        let loops = match self.ibflag {
            Ibflag::Cut13 => Some((1, 3)),
            Ibflag::Cut24 => Some((2, 0)),
            _ => None,
        };
        match loops {
            None => Region::new(open(&self.points), Vec::new()),
            Some((a, b)) => {
                let s = self.sides();
                let (la, lb) = (open(s[a]), open(s[b]));
                if signed_area(&la).abs() >= signed_area(&lb).abs() {
                    Region::new(la, vec![lb])
                } else {
                    Region::new(lb, vec![la])
                }
            }
        }
    }
}

/// Reads a `.con` contour file.
pub fn read_con(path: impl AsRef<Path>) -> Result<Contour, IoError> {
    let path = path.as_ref();
    parse_con_at(&read_text(path)?, path)
}

/// Like [`read_con`], for text held in memory (errors name `<string>`).
pub fn parse_con(text: &str) -> Result<Contour, IoError> {
    parse_con_at(text, Path::new(STRING_SOURCE))
}

/// Reads a `.con` file and returns its region ([`Contour::region`]).
pub fn read_region_con(path: impl AsRef<Path>) -> Result<Region, IoError> {
    let path = path.as_ref();
    read_con(path)?
        .region()
        .map_err(|source| IoError::InvalidRegion {
            path: path.to_path_buf(),
            source,
        })
}

fn parse_con_at(text: &str, path: &Path) -> Result<Contour, IoError> {
    let mut lx = Lexer::new(text, path);
    let (m, mline) = lx.usize("the number of points m")?;
    let (flag, fline) = lx.i64("ibflag")?;
    let ibflag = Ibflag::from_code(flag)
        .ok_or_else(|| lx.malformed(fline, format!("ibflag {flag}: expected 0, 1, 13 or 24")))?;
    let mut counts = [0usize; 4];
    for (k, c) in counts.iter_mut().enumerate() {
        *c = lx.usize(&format!("nb{}", k + 1))?.0;
    }
    let mut points = Vec::with_capacity(m.min(MAX_PREALLOC));
    for k in 0..m {
        let (x, _) = lx.f64(&format!("x of point {}", k + 1))?;
        let (y, _) = lx.f64(&format!("y of point {}", k + 1))?;
        points.push(DVec2::new(x, y));
    }
    let last = lx.line();
    if let Some((t, line)) = lx.next() {
        return Err(lx.malformed(
            line,
            format!("unexpected {t:?} after the {m} points announced on line {mline}"),
        ));
    }
    if ibflag != Ibflag::Undefined && counts.iter().sum::<usize>() != m + 3 {
        return Err(IoError::CountMismatch {
            path: path.to_path_buf(),
            line: mline,
            what: "nb1 + nb2 + nb3 + nb4 (must be m + 3: corners count in both sides)".into(),
            expected: m + 3,
            found: counts.iter().sum(),
        });
    }
    Contour::new(points, ibflag, counts).map_err(|message| IoError::Malformed {
        path: path.to_path_buf(),
        line: last,
        message,
    })
}

/// Right-aligned in 11 columns (UNAMALLA's field width) with at least one leading blank, so
/// fields stay separated when the shortest round-trip form is longer than 10 characters.
fn field(v: f64) -> String {
    format!(" {:>10}", format!("{v:?}"))
}

/// Writes a `.con` contour file (see the [module docs](self)).
pub fn write_con(path: impl AsRef<Path>, contour: &Contour) -> Result<(), IoError> {
    let path = path.as_ref();
    let [a, b, c, d] = contour.counts;
    atomic_write(path, |w| {
        writeln!(
            w,
            "{} {} {a} {b} {c} {d}",
            contour.points.len(),
            contour.ibflag.code()
        )?;
        for p in &contour.points {
            writeln!(w, "{}{}", field(p.x), field(p.y))?;
        }
        Ok(())
    })
}

/// A mesh read from an XY or RED file.
#[derive(Debug, Clone, PartialEq)]
pub struct LegacyMesh {
    /// The file name on line 2 (trimmed).
    pub name: String,
    /// The grid.
    pub grid: StructuredGrid2,
}

/// Node order of the XY format: `(i, j)` with `j` fastest.
fn xy_order(m: usize, n: usize) -> Vec<(usize, usize)> {
    (0..m).flat_map(|i| (0..n).map(move |j| (i, j))).collect()
}

/// Node order of the RED format: boundary counter-clockwise from (0, 0), then the interior
/// column by column.
fn red_order(m: usize, n: usize) -> Vec<(usize, usize)> {
    let mut v = Vec::with_capacity(m * n);
    v.extend((0..m).map(|i| (i, 0)));
    v.extend((1..n).map(|j| (m - 1, j)));
    v.extend((0..m - 1).rev().map(|i| (i, n - 1)));
    v.extend((1..n - 1).rev().map(|j| (0, j)));
    for i in 1..m - 1 {
        v.extend((1..n - 1).map(|j| (i, j)));
    }
    v
}

fn write_legacy_mesh(
    path: &Path,
    grid: &StructuredGrid2,
    name: &str,
    order: Vec<(usize, usize)>,
) -> Result<(), IoError> {
    if name.contains(['\n', '\r']) {
        return Err(IoError::Unrepresentable {
            path: path.to_path_buf(),
            reason: "the file name line must not contain a line break".into(),
        });
    }
    atomic_write(path, |w| {
        writeln!(w, "{} {}", grid.m(), grid.n())?;
        writeln!(w, "{name}")?;
        let values: Vec<f64> = order
            .iter()
            .flat_map(|&(i, j)| {
                let p = grid.node(i, j);
                [p.x, p.y]
            })
            .collect();
        for chunk in values.chunks(7) {
            let line: Vec<String> = chunk.iter().map(|&v| field(v)).collect();
            writeln!(w, "{}", line.join(""))?;
        }
        Ok(())
    })
}

/// Writes a grid in UNAMALLA's XY ("classic") order; `name` goes on line 2.
pub fn write_xy(path: impl AsRef<Path>, grid: &StructuredGrid2, name: &str) -> Result<(), IoError> {
    write_legacy_mesh(path.as_ref(), grid, name, xy_order(grid.m(), grid.n()))
}

/// Writes a grid in UNAMALLA's RED ("recent") order; `name` goes on line 2.
pub fn write_red(
    path: impl AsRef<Path>,
    grid: &StructuredGrid2,
    name: &str,
) -> Result<(), IoError> {
    write_legacy_mesh(path.as_ref(), grid, name, red_order(grid.m(), grid.n()))
}

/// Reads an XY ("classic") mesh file.
pub fn read_xy(path: impl AsRef<Path>) -> Result<LegacyMesh, IoError> {
    let path = path.as_ref();
    parse_legacy_at(&read_text(path)?, path, false)
}

/// Like [`read_xy`], for text held in memory.
pub fn parse_xy(text: &str) -> Result<LegacyMesh, IoError> {
    parse_legacy_at(text, Path::new(STRING_SOURCE), false)
}

/// Reads a RED ("recent") mesh file.
pub fn read_red(path: impl AsRef<Path>) -> Result<LegacyMesh, IoError> {
    let path = path.as_ref();
    parse_legacy_at(&read_text(path)?, path, true)
}

/// Like [`read_red`], for text held in memory.
pub fn parse_red(text: &str) -> Result<LegacyMesh, IoError> {
    parse_legacy_at(text, Path::new(STRING_SOURCE), true)
}

fn parse_legacy_at(text: &str, path: &Path, red: bool) -> Result<LegacyMesh, IoError> {
    let mut lx = Lexer::new(text, path);
    let (m, line) = lx.usize("m (points per horizontal line)")?;
    let (n, _) = lx.usize("n (points per vertical line)")?;
    if m < 2 || n < 2 {
        return Err(lx.malformed(line, format!("mesh size {m} × {n}: at least 2 × 2 needed")));
    }
    let count = lx.mul(m, n, line, "m × n")?;
    if count > (text.len() / 2).max(1) {
        // Every node needs at least 4 characters ("0 0 "): the file cannot hold them.
        return Err(IoError::Truncated {
            path: path.to_path_buf(),
            line,
            expected: format!("{count} nodes ({m} × {n})"),
        });
    }
    let name = match lx.next_line() {
        Some((l, _)) => l.trim().to_string(),
        None => {
            return Err(IoError::Truncated {
                path: path.to_path_buf(),
                line,
                expected: "the file name line".into(),
            })
        }
    };
    let order = if red { red_order(m, n) } else { xy_order(m, n) };
    let mut nodes = vec![DVec2::ZERO; count];
    for &(i, j) in &order {
        let (x, _) = lx.f64(&format!("x of node ({}, {})", i + 1, j + 1))?;
        let (y, _) = lx.f64(&format!("y of node ({}, {})", i + 1, j + 1))?;
        nodes[j * m + i] = DVec2::new(x, y);
    }
    lx.expect_end(&format!("the {count} nodes"))?;
    let grid = StructuredGrid2::new(m, n, nodes).map_err(|source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(LegacyMesh { name, grid })
}

/// A Geomview `MESH` surface: `nu × nv` points, `u` fastest.
#[derive(Debug, Clone, PartialEq)]
pub struct GeomviewMesh {
    /// Points per `u` line.
    pub nu: usize,
    /// Points per `v` line.
    pub nv: usize,
    /// The points, index `v * nu + u`.
    pub points: Vec<DVec3>,
}

impl GeomviewMesh {
    /// The planar grid (`x`, `y`; `z` dropped) with `m = nu`, `n = nv`.
    pub fn grid(&self) -> Result<StructuredGrid2, unamalla_mesh::MeshError> {
        StructuredGrid2::new(
            self.nu,
            self.nv,
            self.points.iter().map(|p| p.truncate()).collect(),
        )
    }
    /// The `z` of every point (e.g. the PDE solution UNAMALLA plots).
    pub fn heights(&self) -> Vec<f64> {
        self.points.iter().map(|p| p.z).collect()
    }
}

/// Writes a Geomview `MESH` file of the grid: `m n`, nodes in grid order (`i` fastest), `z`
/// from `z` (one value per node, finite) or 0.
pub fn write_geomview_mesh(
    path: impl AsRef<Path>,
    grid: &StructuredGrid2,
    z: Option<&[f64]>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    if let Some(z) = z {
        if z.len() != grid.num_nodes() {
            return Err(IoError::Unrepresentable {
                path: path.to_path_buf(),
                reason: format!("{} z values for {} nodes", z.len(), grid.num_nodes()),
            });
        }
        if let Some(k) = z.iter().position(|v| !v.is_finite()) {
            return Err(IoError::Unrepresentable {
                path: path.to_path_buf(),
                reason: format!("z of node {k} is not finite"),
            });
        }
    }
    atomic_write(path, |w| {
        writeln!(w, "MESH")?;
        writeln!(w, "{} {}", grid.m(), grid.n())?;
        for (k, p) in grid.nodes().iter().enumerate() {
            let zk = z.map_or(0.0, |z| z[k]);
            writeln!(w, "{}{}{}", field(p.x), field(p.y), field(zk))?;
        }
        Ok(())
    })
}

/// Reads a Geomview `MESH` file (plain `MESH` only; the `C`, `N`, `U`, `Z`, `4`, `u`/`v`-wrap
/// variants are [`IoError::Unsupported`]). `#` starts a comment.
pub fn read_geomview_mesh(path: impl AsRef<Path>) -> Result<GeomviewMesh, IoError> {
    let path = path.as_ref();
    parse_geomview_at(&read_text(path)?, path)
}

/// Like [`read_geomview_mesh`], for text held in memory.
pub fn parse_geomview_mesh(text: &str) -> Result<GeomviewMesh, IoError> {
    parse_geomview_at(text, Path::new(STRING_SOURCE))
}

fn parse_geomview_at(text: &str, path: &Path) -> Result<GeomviewMesh, IoError> {
    let mut lx = Lexer::new(text, path).with_comments('#');
    let (kw, line) = lx.token("the MESH keyword")?;
    if kw != "MESH" {
        return Err(if kw.ends_with("MESH") {
            IoError::Unsupported {
                path: path.to_path_buf(),
                line,
                what: format!("Geomview {kw} (only plain MESH is read)"),
            }
        } else {
            lx.malformed(line, format!("expected MESH, found {kw:?}"))
        });
    }
    let (nu, line) = lx.usize("Nu")?;
    let (nv, _) = lx.usize("Nv")?;
    let count = lx.mul(nu, nv, line, "Nu × Nv")?;
    let mut points = Vec::with_capacity(count.min(MAX_PREALLOC));
    for k in 0..count {
        let (x, _) = lx.f64(&format!("x of point {k}"))?;
        let (y, _) = lx.f64(&format!("y of point {k}"))?;
        let (z, _) = lx.f64(&format!("z of point {k}"))?;
        points.push(DVec3::new(x, y, z));
    }
    lx.expect_end(&format!("the {count} points"))?;
    Ok(GeomviewMesh { nu, nv, points })
}
