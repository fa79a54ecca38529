//! Logically hexahedral regions given by six structured face grids
//! ([Cortés Aguirre 2012, §2.1, Def 6]; the references are listed in `docs/references.md` of
//! the repository): opposite faces have the same size and faces sharing an edge coincide on it.

use glam::DVec3;

use super::error::HexGenError;
use crate::grid::StructuredGrid3;
use crate::tfi::{tfi3, HexFaces};

/// One of the six faces of a logically hexahedral region.
///
/// The thesis's numbering ([Cortés Aguirre 2012, §3.2, (3.16)]) is given by
/// [`HexFaceId::thesis_name`]: M1 = `j = 1`, M2 = `i = 1`, M3 = `j = n`, M4 = `i = m`,
/// M5 = `k = 1` (bottom), M6 = `k = p` (top), 1-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum HexFaceId {
    /// Face `i = 0` (M2, "left").
    IMin,
    /// Face `i = m−1` (M4, "right").
    IMax,
    /// Face `j = 0` (M1, "front").
    JMin,
    /// Face `j = n−1` (M3, "back").
    JMax,
    /// Face `k = 0` (M5, bottom).
    KMin,
    /// Face `k = p−1` (M6, top).
    KMax,
}

impl HexFaceId {
    /// All six, in the order of [`HexFaces`]'s fields.
    pub const ALL: [HexFaceId; 6] = [
        HexFaceId::IMin,
        HexFaceId::IMax,
        HexFaceId::JMin,
        HexFaceId::JMax,
        HexFaceId::KMin,
        HexFaceId::KMax,
    ];

    /// The file/field name (`"i_min"`, …, `"k_max"`).
    pub fn name(self) -> &'static str {
        match self {
            HexFaceId::IMin => "i_min",
            HexFaceId::IMax => "i_max",
            HexFaceId::JMin => "j_min",
            HexFaceId::JMax => "j_max",
            HexFaceId::KMin => "k_min",
            HexFaceId::KMax => "k_max",
        }
    }

    /// The name with the thesis's label, e.g. `"k_min (M5, bottom)"`, used in error messages.
    pub fn thesis_name(self) -> &'static str {
        match self {
            HexFaceId::IMin => "i_min (M2, left)",
            HexFaceId::IMax => "i_max (M4, right)",
            HexFaceId::JMin => "j_min (M1, front)",
            HexFaceId::JMax => "j_max (M3, back)",
            HexFaceId::KMin => "k_min (M5, bottom)",
            HexFaceId::KMax => "k_max (M6, top)",
        }
    }

    /// The face on the other side of the region.
    pub fn opposite(self) -> HexFaceId {
        match self {
            HexFaceId::IMin => HexFaceId::IMax,
            HexFaceId::IMax => HexFaceId::IMin,
            HexFaceId::JMin => HexFaceId::JMax,
            HexFaceId::JMax => HexFaceId::JMin,
            HexFaceId::KMin => HexFaceId::KMax,
            HexFaceId::KMax => HexFaceId::KMin,
        }
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(s: &str) -> Option<HexFaceId> {
        Self::ALL.into_iter().find(|f| f.name() == s)
    }
}

/// A structured surface grid of `a × b` points, stored at `y·a + x` ([Cortés Aguirre 2012,
/// §2.1, Def 5]). Which logical directions `x, y` are depends on the face (see [`HexFaces`]):
/// `(j, k)` on the `i` faces, `(i, k)` on the `j` faces, `(i, j)` on the `k` faces.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FaceGrid {
    /// Points along the first face direction.
    pub a: usize,
    /// Points along the second face direction.
    pub b: usize,
    /// The `a·b` points.
    pub points: Vec<DVec3>,
}

impl FaceGrid {
    /// A face grid from a function of the two face indices.
    pub fn from_fn(a: usize, b: usize, mut f: impl FnMut(usize, usize) -> DVec3) -> Self {
        let mut points = Vec::with_capacity(a * b);
        for y in 0..b {
            for x in 0..a {
                points.push(f(x, y));
            }
        }
        Self { a, b, points }
    }
}

/// A validated logically hexahedral region ([Cortés Aguirre 2012, §2.1, Def 6]).
#[derive(Debug, Clone, PartialEq)]
pub struct HexRegion {
    faces: HexFaces,
}

/// Default coincidence tolerance for shared edges, relative to the largest coordinate.
pub const EDGE_TOLERANCE: f64 = 1e-9;

impl HexRegion {
    /// Validates six face grids, given in the order of [`HexFaceId::ALL`]
    /// (`i_min, i_max, j_min, j_max, k_min, k_max`).
    ///
    /// Checks, with an error naming the face (and node) at fault:
    /// * every face has at least 2 × 2 points and as many points as its sizes say;
    /// * opposite faces have the same sizes ([`HexGenError::OppositeSizes`]), and the three
    ///   pairs agree on `m, n, p` (the `i` faces are `n × p`, the `j` faces `m × p`, the `k`
    ///   faces `m × n`; [`HexGenError::FaceSize`]);
    /// * all coordinates are finite;
    /// * faces sharing an edge coincide on it, within `EDGE_TOLERANCE × max |coordinate|`
    ///   ([`HexGenError::EdgeMismatch`]).
    ///
    /// ```
    /// use unamalla_mesh::hexgen::{FaceGrid, HexRegion};
    /// use unamalla_mesh::DVec3;
    /// // the faces of the unit cube with 3 × 4 × 5 nodes
    /// let (m, n, p) = (3usize, 4usize, 5usize);
    /// let at = |i: usize, j: usize, k: usize| DVec3::new(
    ///     i as f64 / (m - 1) as f64, j as f64 / (n - 1) as f64, k as f64 / (p - 1) as f64);
    /// let faces = [
    ///     FaceGrid::from_fn(n, p, |j, k| at(0, j, k)),
    ///     FaceGrid::from_fn(n, p, |j, k| at(m - 1, j, k)),
    ///     FaceGrid::from_fn(m, p, |i, k| at(i, 0, k)),
    ///     FaceGrid::from_fn(m, p, |i, k| at(i, n - 1, k)),
    ///     FaceGrid::from_fn(m, n, |i, j| at(i, j, 0)),
    ///     FaceGrid::from_fn(m, n, |i, j| at(i, j, p - 1)),
    /// ];
    /// let region = HexRegion::from_face_grids(faces).unwrap();
    /// let grid = region.tfi().unwrap();
    /// assert!((grid.node(1, 2, 3) - at(1, 2, 3)).length() < 1e-12);
    /// ```
    pub fn from_face_grids(faces: [FaceGrid; 6]) -> Result<Self, HexGenError> {
        let [imin, imax, jmin, jmax, kmin, kmax] = faces;
        let list = [&imin, &imax, &jmin, &jmax, &kmin, &kmax];
        for (f, id) in list.iter().zip(HexFaceId::ALL) {
            if f.a < 2 || f.b < 2 {
                return Err(HexGenError::TooSmall {
                    dims: (f.a, f.b, 0),
                    reason: "every face grid needs at least 2 × 2 points",
                });
            }
            if let Some(ix) = f.points.iter().position(|q| !q.is_finite()) {
                return Err(HexGenError::NonFinite {
                    what: id.thesis_name(),
                    index: ix,
                });
            }
        }
        for (x, y, ix, iy) in [
            (&imin, &imax, HexFaceId::IMin, HexFaceId::IMax),
            (&jmin, &jmax, HexFaceId::JMin, HexFaceId::JMax),
            (&kmin, &kmax, HexFaceId::KMin, HexFaceId::KMax),
        ] {
            if (x.a, x.b) != (y.a, y.b) {
                return Err(HexGenError::OppositeSizes {
                    face_a: ix.thesis_name(),
                    a0: x.a,
                    a1: x.b,
                    face_b: iy.thesis_name(),
                    b0: y.a,
                    b1: y.b,
                });
            }
        }
        // m, n, p from the k faces (m × n) and the i faces (n × p)
        let (m, n, p) = (kmin.a, kmin.b, imin.b);
        for (f, id, a, b) in [
            (&imin, HexFaceId::IMin, n, p),
            (&jmin, HexFaceId::JMin, m, p),
            (&kmin, HexFaceId::KMin, m, n),
        ] {
            if (f.a, f.b) != (a, b) || f.points.len() != a * b {
                return Err(HexGenError::FaceSize {
                    face: id.thesis_name(),
                    got: f.points.len(),
                    expected: a * b,
                    m,
                    n,
                    p,
                });
            }
        }
        for (f, id) in list.iter().zip(HexFaceId::ALL) {
            if f.points.len() != f.a * f.b {
                return Err(HexGenError::FaceSize {
                    face: id.thesis_name(),
                    got: f.points.len(),
                    expected: f.a * f.b,
                    m,
                    n,
                    p,
                });
            }
        }
        let faces = HexFaces {
            dims: (m, n, p),
            i_min: imin.points,
            i_max: imax.points,
            j_min: jmin.points,
            j_max: jmax.points,
            k_min: kmin.points,
            k_max: kmax.points,
        };
        Self::from_faces(faces)
    }

    /// Validates an existing [`HexFaces`] (sizes, finiteness, shared edges; see
    /// [`from_face_grids`](Self::from_face_grids)).
    pub fn from_faces(faces: HexFaces) -> Result<Self, HexGenError> {
        let (m, n, p) = faces.dims;
        if m < 2 || n < 2 || p < 2 {
            return Err(HexGenError::TooSmall {
                dims: faces.dims,
                reason: "a logically hexahedral region needs at least 2 × 2 × 2 nodes",
            });
        }
        let mut scale = 1.0f64;
        for id in HexFaceId::ALL {
            let (f, want) = face_of(&faces, id);
            if f.len() != want {
                return Err(HexGenError::FaceSize {
                    face: id.thesis_name(),
                    got: f.len(),
                    expected: want,
                    m,
                    n,
                    p,
                });
            }
            if let Some(ix) = f.iter().position(|q| !q.is_finite()) {
                return Err(HexGenError::NonFinite {
                    what: id.thesis_name(),
                    index: ix,
                });
            }
            scale = f.iter().fold(scale, |s, q| s.max(q.abs().max_element()));
        }
        let tol = EDGE_TOLERANCE * scale;
        // every node on two or three faces: compare the faces pairwise
        for k in 0..p {
            for j in 0..n {
                for i in 0..m {
                    let on: Vec<(HexFaceId, DVec3)> = HexFaceId::ALL
                        .into_iter()
                        .filter_map(|id| point_on(&faces, id, i, j, k).map(|q| (id, q)))
                        .collect();
                    for w in on.windows(2) {
                        let d = w[0].1.distance(w[1].1);
                        if d.is_nan() || d > tol {
                            return Err(HexGenError::EdgeMismatch {
                                face_a: w[0].0.thesis_name(),
                                face_b: w[1].0.thesis_name(),
                                i,
                                j,
                                k,
                                distance: d,
                            });
                        }
                    }
                }
            }
        }
        Ok(Self { faces })
    }

    /// The faces of an existing grid (always compatible).
    pub fn of_grid(g: &StructuredGrid3) -> Self {
        Self {
            faces: HexFaces::of_grid(g),
        }
    }

    /// Sizes `(m, n, p)` in nodes.
    pub fn dims(&self) -> (usize, usize, usize) {
        self.faces.dims
    }

    /// The validated faces.
    pub fn faces(&self) -> &HexFaces {
        &self.faces
    }

    /// The points of one face, in the layout of [`HexFaces`].
    pub fn face(&self, id: HexFaceId) -> &[DVec3] {
        face_of(&self.faces, id).0
    }

    /// The initial mesh by 3D transfinite interpolation ([Cortés Aguirre 2012, §2.2.1], which
    /// does not print the formula; the Boolean sum of [`tfi3`]); the boundary nodes are the face
    /// points exactly.
    pub fn tfi(&self) -> Result<StructuredGrid3, HexGenError> {
        Ok(tfi3(&self.faces)?)
    }
}

/// Face `id` of `f` and its expected number of points.
fn face_of(f: &HexFaces, id: HexFaceId) -> (&[DVec3], usize) {
    let (m, n, p) = f.dims;
    match id {
        HexFaceId::IMin => (&f.i_min, n * p),
        HexFaceId::IMax => (&f.i_max, n * p),
        HexFaceId::JMin => (&f.j_min, m * p),
        HexFaceId::JMax => (&f.j_max, m * p),
        HexFaceId::KMin => (&f.k_min, m * n),
        HexFaceId::KMax => (&f.k_max, m * n),
    }
}

/// The point of face `id` at volume node `(i, j, k)`, if the node lies on that face.
fn point_on(f: &HexFaces, id: HexFaceId, i: usize, j: usize, k: usize) -> Option<DVec3> {
    let (m, n, p) = f.dims;
    match id {
        HexFaceId::IMin if i == 0 => Some(f.i_min[k * n + j]),
        HexFaceId::IMax if i == m - 1 => Some(f.i_max[k * n + j]),
        HexFaceId::JMin if j == 0 => Some(f.j_min[k * m + i]),
        HexFaceId::JMax if j == n - 1 => Some(f.j_max[k * m + i]),
        HexFaceId::KMin if k == 0 => Some(f.k_min[j * m + i]),
        HexFaceId::KMax if k == p - 1 => Some(f.k_max[j * m + i]),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_faces(m: usize, n: usize, p: usize) -> [FaceGrid; 6] {
        let at = |i: usize, j: usize, k: usize| DVec3::new(i as f64, j as f64, k as f64);
        [
            FaceGrid::from_fn(n, p, |j, k| at(0, j, k)),
            FaceGrid::from_fn(n, p, |j, k| at(m - 1, j, k)),
            FaceGrid::from_fn(m, p, |i, k| at(i, 0, k)),
            FaceGrid::from_fn(m, p, |i, k| at(i, n - 1, k)),
            FaceGrid::from_fn(m, n, |i, j| at(i, j, 0)),
            FaceGrid::from_fn(m, n, |i, j| at(i, j, p - 1)),
        ]
    }

    #[test]
    fn compatible_faces_give_the_tfi_grid() {
        let r = HexRegion::from_face_grids(cube_faces(4, 5, 6)).unwrap();
        assert_eq!(r.dims(), (4, 5, 6));
        let g = r.tfi().unwrap();
        // TFI reproduces the trilinear (here: identity) map exactly
        for k in 0..6 {
            for j in 0..5 {
                for i in 0..4 {
                    let want = DVec3::new(i as f64, j as f64, k as f64);
                    assert!((g.node(i, j, k) - want).length() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn opposite_faces_of_different_size_are_rejected() {
        let mut f = cube_faces(4, 5, 6);
        f[1] = FaceGrid::from_fn(5, 7, |j, k| DVec3::new(3.0, j as f64, k as f64));
        let e = HexRegion::from_face_grids(f).unwrap_err();
        assert!(
            matches!(
                e,
                HexGenError::OppositeSizes {
                    face_a: "i_min (M2, left)",
                    a0: 5,
                    a1: 6,
                    b0: 5,
                    b1: 7,
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn inconsistent_pairs_are_rejected() {
        // j faces claim m = 5 while k faces have m = 4
        let mut f = cube_faces(4, 5, 6);
        f[2] = FaceGrid::from_fn(5, 6, |i, k| DVec3::new(i as f64, 0.0, k as f64));
        f[3] = FaceGrid::from_fn(5, 6, |i, k| DVec3::new(i as f64, 4.0, k as f64));
        let e = HexRegion::from_face_grids(f).unwrap_err();
        assert!(
            matches!(
                e,
                HexGenError::FaceSize {
                    face: "j_min (M1, front)",
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn a_moved_edge_point_names_both_faces_and_the_node() {
        let mut f = cube_faces(4, 5, 6);
        // the top face's point (i, j) = (3, 2) lies on the edge shared with i_max (i = m−1 = 3)
        f[5].points[2 * 4 + 3].z += 0.5;
        let e = HexRegion::from_face_grids(f).unwrap_err();
        match e {
            HexGenError::EdgeMismatch {
                face_a,
                face_b,
                i,
                j,
                k,
                distance,
            } => {
                assert_eq!((face_a, face_b), ("i_max (M4, right)", "k_max (M6, top)"));
                assert_eq!((i, j, k), (3, 2, 5));
                assert!((distance - 0.5).abs() < 1e-12);
            }
            other => panic!("{other}"),
        }
    }

    #[test]
    fn non_finite_points_are_rejected() {
        let mut f = cube_faces(3, 3, 3);
        f[4].points[4] = DVec3::new(f64::NAN, 0.0, 0.0);
        let e = HexRegion::from_face_grids(f).unwrap_err();
        assert_eq!(
            e,
            HexGenError::NonFinite {
                what: "k_min (M5, bottom)",
                index: 4
            }
        );
    }

    #[test]
    fn face_names_round_trip() {
        for id in HexFaceId::ALL {
            assert_eq!(HexFaceId::from_name(id.name()), Some(id));
            assert_eq!(id.opposite().opposite(), id);
        }
    }
}
