//! Named boundary patches: boundary-condition names for stretches of a region's boundary,
//! carried to every mesh output.
//!
//! # Convention (GeoJSON)
//!
//! * The polygon feature that becomes the region may carry `"patch": "<name>"` in its
//!   `properties`: the name of its **outer ring**, and `"hole_patch"`: one name for every hole,
//!   or an array with one name (or `null`) per hole in file order.
//! * Any `LineString` or `MultiLineString` feature of the same `FeatureCollection` with
//!   `"patch": "<name>"` in its `properties` names the **stretch of boundary it lies on**, from
//!   its first to its last position, in the direction it is written (e.g. `open-sea` along the
//!   edge of the clipping box). Every position must lie on one ring of the region (within
//!   10⁻⁶ of the region's bounding-box diagonal); later stretches override earlier ones and
//!   every stretch overrides the ring's name. A closed line string names its whole ring.
//! * Boundary not named by either keeps the default names of [`crate::boundary_edge_groups`]:
//!   `outer` and `hole-<k>` (`k` = 1-based hole index in the input).
//!
//! From the library the same names are a [`BoundaryNames`] value.
//!
//! # How names survive simplification and decomposition
//!
//! The names are attached to the **input** boundary, which the mesher simplifies and whose
//! small features it removes. [`named_edge_groups`] classifies each boundary edge of the final
//! mesh by the point of the input boundary nearest to the edge's midpoint: the ring it lies on
//! and its arc-length position `s` on that ring. An edge takes the name of the last stretch
//! whose arc-length interval `[s₀, s₁]` (cyclic on the ring) contains `s`, else the ring's
//! name. The simplified boundary stays within the simplification tolerance of the input
//! (Hausdorff distance in `report.json`), so an edge is misnamed only within about that
//! distance of a stretch's end, where the patch boundary snaps to a mesh node.

use std::collections::HashMap;

use unamalla_mesh::{DVec2, HasQuadCells, Region};

use crate::error::IoError;
use crate::msh::{boundary_loops, EdgeGroup};

/// A named stretch of the boundary: a polyline lying on one ring of the region.
#[derive(Debug, Clone, PartialEq)]
pub struct Stretch {
    /// The patch name (e.g. `inlet`, `open-sea`).
    pub name: String,
    /// The polyline, from the stretch's start to its end along the boundary.
    pub points: Vec<DVec2>,
}

/// Boundary-condition names of a region (see the module docs for the convention).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BoundaryNames {
    /// Name of the outer ring (default `outer`).
    pub outer: Option<String>,
    /// Names of the holes in input order (missing or `None`: `hole-<k>`).
    pub holes: Vec<Option<String>>,
    /// Named stretches, later ones overriding earlier ones.
    pub stretches: Vec<Stretch>,
}

impl BoundaryNames {
    /// No name given at all (the outputs then use the default groups).
    pub fn is_empty(&self) -> bool {
        self.outer.is_none() && self.holes.iter().all(Option::is_none) && self.stretches.is_empty()
    }

    /// The same names with every stretch point mapped by `f` (e.g. a map projection).
    pub fn map_points(&self, mut f: impl FnMut(DVec2) -> DVec2) -> Self {
        Self {
            outer: self.outer.clone(),
            holes: self.holes.clone(),
            stretches: self
                .stretches
                .iter()
                .map(|s| Stretch {
                    name: s.name.clone(),
                    points: s.points.iter().map(|&p| f(p)).collect(),
                })
                .collect(),
        }
    }

    /// The name of ring `r` of a region (0 outer, `k ≥ 1` hole `k`).
    pub fn ring_name(&self, r: usize) -> String {
        if r == 0 {
            self.outer.clone().unwrap_or_else(|| "outer".to_string())
        } else {
            self.holes
                .get(r - 1)
                .cloned()
                .flatten()
                .unwrap_or_else(|| format!("hole-{r}"))
        }
    }
}

/// A position on a region's boundary: ring index, arc length from the ring's vertex 0 and the
/// distance of the located point from it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct BoundaryPos {
    ring: usize,
    s: f64,
    dist: f64,
}

/// The rings of `region` with their cumulative arc lengths.
struct RingTable {
    rings: Vec<(Vec<DVec2>, Vec<f64>)>,
}

impl RingTable {
    fn new(region: &Region) -> Self {
        let rings = region
            .rings()
            .map(|p| {
                let pts = p.points().to_vec();
                let n = pts.len();
                let mut cum = Vec::with_capacity(n + 1);
                cum.push(0.0);
                for k in 0..n {
                    let l = cum[k] + (pts[(k + 1) % n] - pts[k]).length();
                    cum.push(l);
                }
                (pts, cum)
            })
            .collect();
        Self { rings }
    }

    fn length(&self, r: usize) -> f64 {
        self.rings[r].1.last().copied().unwrap_or(0.0)
    }

    /// The nearest boundary position to `p` (on the first ring at ties).
    fn locate(&self, p: DVec2) -> BoundaryPos {
        let mut best = BoundaryPos {
            ring: 0,
            s: 0.0,
            dist: f64::INFINITY,
        };
        for (r, (pts, cum)) in self.rings.iter().enumerate() {
            let n = pts.len();
            for k in 0..n {
                let (a, b) = (pts[k], pts[(k + 1) % n]);
                let d = b - a;
                let l2 = d.length_squared();
                let t = if l2 > 0.0 {
                    ((p - a).dot(d) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let dist = (a + d * t - p).length();
                if dist < best.dist {
                    best = BoundaryPos {
                        ring: r,
                        s: cum[k] + t * (cum[k + 1] - cum[k]),
                        dist,
                    };
                }
            }
        }
        best
    }
}

/// A stretch resolved to a cyclic arc-length interval `[s0, s0 + len]` on one ring.
#[derive(Debug, Clone)]
struct Interval {
    ring: usize,
    s0: f64,
    len: f64,
}

impl Interval {
    fn contains(&self, ring: usize, s: f64, ring_len: f64) -> bool {
        ring == self.ring && (s - self.s0).rem_euclid(ring_len) <= self.len
    }
}

fn resolve(table: &RingTable, st: &Stretch, tol: f64) -> Result<Interval, IoError> {
    let bad = |reason: String| IoError::InvalidPatch {
        name: st.name.clone(),
        reason,
    };
    if st.points.len() < 2 {
        return Err(bad(format!(
            "a stretch needs at least 2 points, found {}",
            st.points.len()
        )));
    }
    let pos: Vec<BoundaryPos> = st.points.iter().map(|&p| table.locate(p)).collect();
    let ring = pos[0].ring;
    for (k, q) in pos.iter().enumerate() {
        if q.dist > tol {
            return Err(bad(format!(
                "point {k} ({}, {}) is {:.3e} away from the region's boundary (tolerance {tol:.3e})",
                st.points[k].x, st.points[k].y, q.dist
            )));
        }
        if q.ring != ring {
            return Err(bad(format!(
                "point {k} lies on ring {}, point 0 on ring {ring}: a stretch lies on one ring",
                q.ring
            )));
        }
    }
    let total = table.length(ring);
    let closed = st.points.first() == st.points.last();
    // signed travel along the ring, each step taken the short way round
    let mut travel = 0.0;
    for w in pos.windows(2) {
        let mut d = (w[1].s - w[0].s).rem_euclid(total);
        if d > 0.5 * total {
            d -= total;
        }
        travel += d;
    }
    if closed || travel.abs() >= total * (1.0 - 1e-12) {
        return Ok(Interval {
            ring,
            s0: 0.0,
            len: total,
        });
    }
    let (first, last) = (pos[0].s, pos[pos.len() - 1].s);
    Ok(if travel >= 0.0 {
        Interval {
            ring,
            s0: first,
            len: (last - first).rem_euclid(total),
        }
    } else {
        Interval {
            ring,
            s0: last,
            len: (first - last).rem_euclid(total),
        }
    })
}

/// Checks the names (non-empty, no `"` or control characters) and every stretch (on one ring
/// of `input`), without a mesh: the errors [`named_edge_groups`] would give.
pub fn validate_names(input: &Region, names: &BoundaryNames) -> Result<(), IoError> {
    let table = RingTable::new(input);
    let tol = tolerance(input);
    let all = names
        .outer
        .iter()
        .chain(names.holes.iter().flatten())
        .chain(names.stretches.iter().map(|s| &s.name));
    for n in all {
        check_patch_name(n)?;
    }
    if names.holes.len() > input.holes().len() {
        return Err(IoError::InvalidPatch {
            name: names
                .holes
                .iter()
                .flatten()
                .last()
                .cloned()
                .unwrap_or_default(),
            reason: format!(
                "{} hole names given, the region has {} holes",
                names.holes.len(),
                input.holes().len()
            ),
        });
    }
    for st in &names.stretches {
        resolve(&table, st, tol)?;
    }
    Ok(())
}

fn tolerance(region: &Region) -> f64 {
    let (lo, hi) = region.bounding_box();
    1e-6 * (hi - lo).length()
}

/// Checks one patch name: non-empty, no `"`, `;`, whitespace inside or control characters (the
/// names become Gmsh physical names, SU2 marker tags, OpenFOAM patch names and CGNS node names).
pub fn check_patch_name(name: &str) -> Result<(), IoError> {
    let bad = |reason: &str| IoError::InvalidPatch {
        name: name.to_string(),
        reason: reason.to_string(),
    };
    if name.is_empty() {
        return Err(bad("the name is empty"));
    }
    if name.len() > 32 {
        return Err(bad("longer than 32 characters (the CGNS name limit)"));
    }
    if name
        .chars()
        .any(|c| c.is_whitespace() || c.is_control() || matches!(c, '"' | ';' | '/' | '{' | '}'))
    {
        return Err(bad(
            "contains whitespace, a control character or one of \" ; / { }",
        ));
    }
    Ok(())
}

/// The boundary edges of `mesh` grouped by patch name (see the module docs): the mesh's
/// boundary loops ([`boundary_loops`], edges oriented with the domain on the left), each edge
/// named after the input boundary point nearest to its midpoint. Groups are listed in order of
/// first appearance along the loops, each group's edges in loop order.
///
/// With empty `names` this is the same as [`crate::boundary_edge_groups`] only up to the
/// numbering of holes (here: the input's hole numbers, also for holes the mesher dropped).
///
/// Errors: [`IoError::InvalidPatch`] for a bad name or a stretch off the boundary.
pub fn named_edge_groups<M: HasQuadCells + ?Sized>(
    mesh: &M,
    input: &Region,
    names: &BoundaryNames,
) -> Result<Vec<EdgeGroup>, IoError> {
    validate_names(input, names)?;
    let table = RingTable::new(input);
    let tol = tolerance(input);
    let intervals: Vec<(Interval, &str)> = names
        .stretches
        .iter()
        .map(|st| resolve(&table, st, tol).map(|i| (i, st.name.as_str())))
        .collect::<Result<_, _>>()?;
    let nodes = mesh.nodes();
    let mut groups: Vec<EdgeGroup> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    for l in boundary_loops(mesh) {
        for e in l.edges {
            let mid = 0.5 * (nodes[e[0]] + nodes[e[1]]);
            let pos = table.locate(mid);
            let total = table.length(pos.ring);
            let name = intervals
                .iter()
                .rev()
                .find(|(i, _)| i.contains(pos.ring, pos.s, total))
                .map(|(_, n)| n.to_string())
                .unwrap_or_else(|| names.ring_name(pos.ring));
            let k = *index.entry(name.clone()).or_insert_with(|| {
                groups.push(EdgeGroup {
                    name,
                    edges: Vec::new(),
                });
                groups.len() - 1
            });
            groups[k].edges.push(e);
        }
    }
    Ok(groups)
}

/// The patch name of every boundary edge, keyed by the edge's node pair `(min, max)`: a lookup
/// for writers that visit the boundary block by block (CGNS, OpenFOAM).
pub fn edge_names(groups: &[EdgeGroup]) -> HashMap<(usize, usize), usize> {
    let mut m = HashMap::new();
    for (g, group) in groups.iter().enumerate() {
        for &[a, b] in &group.edges {
            m.insert((a.min(b), a.max(b)), g);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::{HasNodes, QuadMesh, StructuredGrid2};

    fn square_grid(n: usize) -> QuadMesh {
        let g = StructuredGrid2::from_fn(n + 1, n + 1, |i, j| {
            DVec2::new(i as f64 / n as f64, j as f64 / n as f64)
        })
        .unwrap();
        QuadMesh::from_grid(&g)
    }

    fn unit_square() -> Region {
        Region::new(
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(1.0, 1.0),
                DVec2::new(0.0, 1.0),
            ],
            vec![],
        )
        .unwrap()
    }

    #[test]
    fn a_stretch_names_exactly_the_edges_along_it() {
        // 4×4 cells on the unit square; "inlet" is the left side written top to bottom
        // (against the counter-clockwise ring), "wall" names the ring.
        let mesh = square_grid(4);
        let names = BoundaryNames {
            outer: Some("wall".into()),
            holes: vec![],
            stretches: vec![Stretch {
                name: "inlet".into(),
                points: vec![DVec2::new(0.0, 1.0), DVec2::new(0.0, 0.0)],
            }],
        };
        let g = named_edge_groups(&mesh, &unit_square(), &names).unwrap();
        let count = |n: &str| g.iter().find(|x| x.name == n).map_or(0, |x| x.edges.len());
        assert_eq!(count("inlet"), 4);
        assert_eq!(count("wall"), 12);
        for &[a, b] in &g.iter().find(|x| x.name == "inlet").unwrap().edges {
            assert_eq!(mesh.nodes()[a].x, 0.0);
            assert_eq!(mesh.nodes()[b].x, 0.0);
        }
    }

    #[test]
    fn a_stretch_across_vertex_zero_wraps_around() {
        // from (0.5, 1) along the top and left side and the bottom to (0.5, 0): the ring's
        // vertex 0 at (0,0) is inside the stretch; bottom half 2 + left 4 + top half 2 = 8 edges
        let mesh = square_grid(4);
        let names = BoundaryNames {
            outer: None,
            holes: vec![],
            stretches: vec![Stretch {
                name: "open-sea".into(),
                points: vec![
                    DVec2::new(0.5, 1.0),
                    DVec2::new(0.0, 1.0),
                    DVec2::new(0.0, 0.0),
                    DVec2::new(0.5, 0.0),
                ],
            }],
        };
        let g = named_edge_groups(&mesh, &unit_square(), &names).unwrap();
        assert_eq!(g.len(), 2);
        let sea = g.iter().find(|x| x.name == "open-sea").unwrap();
        assert_eq!(sea.edges.len(), 8);
        assert!(sea.edges.iter().all(|&[a, b]| {
            let m = 0.5 * (mesh.nodes()[a] + mesh.nodes()[b]);
            m.x < 0.5
        }));
        assert_eq!(g.iter().find(|x| x.name == "outer").unwrap().edges.len(), 8);
    }

    #[test]
    fn names_follow_a_moved_boundary() {
        // the mesh boundary is the input square shrunk by 1 %: edges still find their stretch
        let mut mesh = square_grid(4);
        let shrunk: Vec<DVec2> = mesh
            .nodes()
            .iter()
            .map(|&p| DVec2::splat(0.5) + 0.99 * (p - DVec2::splat(0.5)))
            .collect();
        mesh = QuadMesh::new(shrunk, mesh.cells().to_vec()).unwrap();
        let names = BoundaryNames {
            stretches: vec![Stretch {
                name: "outlet".into(),
                points: vec![DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0)],
            }],
            ..BoundaryNames::default()
        };
        let g = named_edge_groups(&mesh, &unit_square(), &names).unwrap();
        assert_eq!(
            g.iter().find(|x| x.name == "outlet").unwrap().edges.len(),
            4
        );
    }

    #[test]
    fn a_stretch_off_the_boundary_is_an_error_naming_it() {
        let names = BoundaryNames {
            stretches: vec![Stretch {
                name: "inlet".into(),
                points: vec![DVec2::new(0.0, 0.0), DVec2::new(0.5, 0.5)],
            }],
            ..BoundaryNames::default()
        };
        let e = named_edge_groups(&square_grid(2), &unit_square(), &names).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("inlet") && msg.contains("point 1"), "{msg}");
        assert!(check_patch_name("open sea").is_err());
        assert!(check_patch_name("").is_err());
        assert!(check_patch_name("open-sea").is_ok());
    }

    #[test]
    fn hole_names_and_defaults() {
        let names = BoundaryNames {
            outer: None,
            holes: vec![None, Some("island".into())],
            stretches: vec![],
        };
        assert_eq!(names.ring_name(0), "outer");
        assert_eq!(names.ring_name(1), "hole-1");
        assert_eq!(names.ring_name(2), "island");
        assert!(!names.is_empty());
        assert!(BoundaryNames::default().is_empty());
    }
}
