//! The decomposition file (JSON): save any result, override any part of it.
//!
//! # Format
//!
//! ```json
//! {
//!   "format": "unamalla-decomposition",
//!   "version": 1,
//!   "blocks": [
//!     { "id": 0, "ring": [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]],
//!       "corners": [0, 1, 2, 3], "triangle": false,
//!       "edges": [{"kind": "boundary", "ring": 0}, {"kind": "cut", "cut": 0, "neighbour": 1}, …] }
//!   ],
//!   "cuts": [ { "id": 0, "a": [2.0, 0.0], "b": [2.0, 1.0], "blocks": [0, 1] } ],
//!   "complete": false
//! }
//! ```
//!
//! * `format` and `version` are optional on input; if present they must be
//!   `"unamalla-decomposition"` and `1`.
//! * `cuts` (required): each with endpoints `a`, `b`, either as points `[x, y]` or as boundary
//!   vertex references `{"ring": r, "vertex": i}` (ring 0 = outer ring, ring k = hole k−1, vertex
//!   indices in the region's stored, normalised ring: outer counter-clockwise, holes clockwise).
//!   `id` is optional (defaults to the position; ids must be 0..n−1); `blocks` is optional on
//!   input and checked when given.
//! * `blocks` (optional): each with `id` (0..n−1), `ring` (`[x, y]` pairs, counter-clockwise,
//!   open) and `corners` (four indices into `ring` in counter-clockwise order; optional — missing
//!   corners are chosen automatically). `edges` and `triangle` are written for the reader's
//!   convenience; on input `edges` is ignored (it is recomputed from the geometry).
//!
//! **Two ways to load.** With `blocks`, the file is a complete decomposition: it is validated
//! against the region (every block edge a cut or a piece of the boundary, cuts inside the region
//! and disjoint, each cut shared by exactly two blocks, boundary covered once, areas adding up,
//! four non-reflex corners in order) and used as is. Without `blocks`, the region is split by
//! the listed cuts in order (a cut joining a hole to the outer boundary bridges it, a cut
//! between two points of the same boundary splits), corners are selected automatically, and if
//! `"complete": true` the automatic decomposition then continues on every piece; otherwise every
//! hole must be separated by the given cuts. A `tree` member written by [`Decomposition::to_json`]
//! is informative and ignored on input.

use serde::{Deserialize, Serialize};
use unamalla_mesh::{DVec2, Region};

use crate::auto::DecomposeOptions;
use crate::builder::{choose_corners, Applied, Builder};
use crate::decomposition::{
    boundary_tol, check_corners, check_cuts, classify, Block, Cut, Decomposition, EdgeKind, Step,
    TreeNode,
};
use crate::error::DecomposeError;

const FORMAT: &str = "unamalla-decomposition";

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileDoc {
    #[serde(default)]
    format: Option<String>,
    #[serde(default)]
    version: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    blocks: Option<Vec<FileBlock>>,
    cuts: Vec<FileCut>,
    #[serde(default)]
    complete: bool,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    tree: Vec<TreeNode>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileBlock {
    id: usize,
    ring: Vec<[f64; 2]>,
    #[serde(default)]
    corners: Option<Vec<usize>>,
    #[serde(default)]
    triangle: bool,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    edges: Vec<EdgeKind>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileCut {
    #[serde(default)]
    id: Option<usize>,
    a: FilePoint,
    b: FilePoint,
    #[serde(default)]
    blocks: Option<[usize; 2]>,
}

#[derive(Serialize, Deserialize, Clone, Copy)]
#[serde(untagged)]
enum FilePoint {
    Xy([f64; 2]),
    Vertex { ring: usize, vertex: usize },
}

fn xy(p: DVec2) -> [f64; 2] {
    [p.x, p.y]
}

impl Decomposition {
    /// Serialises the decomposition in the documented JSON format (complete form, with blocks).
    pub fn to_json(&self) -> String {
        let doc = FileDoc {
            format: Some(FORMAT.into()),
            version: Some(1),
            blocks: Some(
                self.blocks
                    .iter()
                    .map(|b| FileBlock {
                        id: b.id,
                        ring: b.ring.iter().map(|&p| xy(p)).collect(),
                        corners: Some(b.corners.to_vec()),
                        triangle: b.triangle,
                        edges: b.edges.clone(),
                    })
                    .collect(),
            ),
            cuts: self
                .cuts
                .iter()
                .map(|c| FileCut {
                    id: Some(c.id),
                    a: FilePoint::Xy(xy(c.a)),
                    b: FilePoint::Xy(xy(c.b)),
                    blocks: Some(c.blocks),
                })
                .collect(),
            complete: false,
            tree: self.tree.clone(),
        };
        serde_json::to_string_pretty(&doc).unwrap_or_default()
    }

    /// Loads a decomposition file (see the module docs) and validates it against `region`,
    /// with default options for anything computed automatically.
    pub fn from_json(text: &str, region: &Region) -> Result<Decomposition, DecomposeError> {
        Self::from_json_with(text, region, &DecomposeOptions::default())
    }

    /// [`Decomposition::from_json`] with explicit options for the automatic parts.
    pub fn from_json_with(
        text: &str,
        region: &Region,
        opts: &DecomposeOptions,
    ) -> Result<Decomposition, DecomposeError> {
        let doc: FileDoc = serde_json::from_str(text).map_err(|e| DecomposeError::Json {
            line: e.line(),
            column: e.column(),
            message: e.to_string(),
        })?;
        if let Some(f) = &doc.format {
            if f != FORMAT {
                return Err(DecomposeError::Format(format!(
                    "format is \"{f}\", expected \"{FORMAT}\""
                )));
            }
        }
        if let Some(v) = doc.version {
            if v != 1 {
                return Err(DecomposeError::Format(format!(
                    "version {v} is not supported (1 is)"
                )));
            }
        }
        // cuts
        let rings: Vec<&[DVec2]> = region.rings().map(|p| p.points()).collect();
        let mut cuts = Vec::with_capacity(doc.cuts.len());
        let mut seen = vec![false; doc.cuts.len()];
        for (k, c) in doc.cuts.iter().enumerate() {
            let id = c.id.unwrap_or(k);
            if id >= doc.cuts.len() || seen[id] {
                return Err(DecomposeError::BadId {
                    what: "cut",
                    id,
                    count: doc.cuts.len(),
                });
            }
            seen[id] = true;
            let resolve = |p: FilePoint, name: char| -> Result<DVec2, DecomposeError> {
                match p {
                    FilePoint::Xy([x, y]) => {
                        let v = DVec2::new(x, y);
                        if !v.is_finite() {
                            return Err(DecomposeError::NonFinite {
                                what: format!("cut {id} endpoint {name}"),
                            });
                        }
                        Ok(v)
                    }
                    FilePoint::Vertex { ring, vertex } => {
                        rings.get(ring).and_then(|r| r.get(vertex)).copied().ok_or(
                            DecomposeError::VertexOutOfRange {
                                cut: id,
                                ring,
                                vertex,
                            },
                        )
                    }
                }
            };
            cuts.push(Cut {
                id,
                a: resolve(c.a, 'a')?,
                b: resolve(c.b, 'b')?,
                blocks: c.blocks.unwrap_or([usize::MAX; 2]),
            });
        }
        cuts.sort_by_key(|c| c.id);
        match doc.blocks {
            Some(fb) => load_complete(region, fb, cuts, opts),
            None => load_cuts(region, cuts, doc.complete, opts),
        }
    }
}

fn load_complete(
    region: &Region,
    fb: Vec<FileBlock>,
    mut cuts: Vec<Cut>,
    opts: &DecomposeOptions,
) -> Result<Decomposition, DecomposeError> {
    let count = fb.len();
    let mut slots: Vec<Option<FileBlock>> = (0..count).map(|_| None).collect();
    for b in fb {
        if b.id >= count || slots[b.id].is_some() {
            return Err(DecomposeError::BadId {
                what: "block",
                id: b.id,
                count,
            });
        }
        let id = b.id;
        slots[id] = Some(b);
    }
    let fb: Vec<FileBlock> = slots.into_iter().flatten().collect();
    let mut blocks = Vec::with_capacity(count);
    for b in &fb {
        let ring: Vec<DVec2> = b.ring.iter().map(|&[x, y]| DVec2::new(x, y)).collect();
        if let Some(k) = ring.iter().position(|p| !p.is_finite()) {
            return Err(DecomposeError::NonFinite {
                what: format!("block {}, ring point {k}", b.id),
            });
        }
        blocks.push(Block {
            id: b.id,
            ring,
            corners: [0, 1, 2, 3],
            edges: Vec::new(),
            triangle: b.triangle,
        });
    }
    let (edges, sides) = classify(region, &blocks, &cuts)?;
    for c in &mut cuts {
        c.blocks = sides[c.id];
    }
    let theta = opts.tolerances.theta_minus;
    for (b, (f, e)) in blocks.iter_mut().zip(fb.iter().zip(edges)) {
        match &f.corners {
            Some(c) => {
                let c: [usize; 4] =
                    c.as_slice()
                        .try_into()
                        .map_err(|_| DecomposeError::BadCorners {
                            block: b.id,
                            reason: format!(
                                "needs exactly four corners, the file gives {}",
                                c.len()
                            ),
                        })?;
                check_corners(b.id, &b.ring, &c)?;
                b.corners = c;
                b.edges = e;
            }
            None => {
                let (ring, e2, c, tri) = choose_corners(b.id, &b.ring, &e, theta, opts)?;
                b.ring = ring;
                b.edges = e2;
                b.corners = c;
                b.triangle = tri;
            }
        }
    }
    let d = Decomposition {
        blocks,
        cuts,
        tree: Vec::new(),
    };
    d.validate(region)?;
    Ok(d)
}

fn load_cuts(
    region: &Region,
    cuts: Vec<Cut>,
    complete: bool,
    opts: &DecomposeOptions,
) -> Result<Decomposition, DecomposeError> {
    check_cuts(region, &cuts)?;
    let tol = boundary_tol(region);
    let mut b = Builder::new(region, opts);
    for c in &cuts {
        match b.apply_cut(c.a, c.b, tol, Step::User) {
            Applied::Split | Applied::Bridged => {}
            Applied::JoinsTwoHoles => {
                return Err(DecomposeError::Format(format!(
                    "cut {}: joins two holes; join each hole to the outer boundary (or to a hole already joined to it)",
                    c.id
                )))
            }
            Applied::NoPiece => {
                return Err(DecomposeError::Format(format!(
                    "cut {}: does not lie inside one piece of the decomposition made by the cuts before it \
                     (it must join two boundary points of one piece)",
                    c.id
                )))
            }
        }
    }
    b.protected_cuts = b.cuts.len();
    b.auto_repair = complete;
    if complete {
        b.run_auto_on_leaves()?;
    }
    b.finish()
}
