//! B-spline maps of the blocks of a block-structured mesh ([Abelló et al., §1.2–§1.3]).
//!
//! Every block of a [`BlockMesh2`] (e.g. [`MeshResult::mesh`] from the pipeline) is a structured
//! `m × n` grid; its nodes are taken directly as a control net (node `(i, j)` ↦ `P_{i,j}`):
//!
//! * the **bilinear** map on knots (4)/(5) interpolates the block (Lemma 1: it carries the
//!   uniform parameter grid onto the mesh) and is injective when every cell is convex
//!   (Theorem 1) — which the pipeline's smoothing guarantees;
//! * the **biquadratic** map on knots (23)/(24) of the same net is smooth inside the block; it
//!   is kept only where **certified** (Theorem 2 or the Bernstein-coefficient test with
//!   subdivision). Its image is bounded by the quadratic B-spline curves of the block's sides
//!   (Lemma 4), i.e. it rounds the block's boundary polygon. Two blocks that share a whole side
//!   share its control points, and clamped uniform knots are symmetric under `t ↦ 1 − t`, so
//!   their biquadratic maps agree along that side; where a block side is split between two
//!   neighbours (a T-junction of the block layout) they do not, because a quadratic curve does
//!   not pass through its interior control points.
//!
//! Both maps also get a dense `det J` sample ([`unamalla_bspline::sample_det_j`]).

use unamalla_bspline::{
    certify_map, sample_det_j, theorem1, Certificates, ControlNet, Degree, JacobianSample,
    TensorMap, Theorem1Report,
};
use unamalla_mesh::BlockMesh2;

use crate::pipeline::MeshResult;
use crate::CoreError;

/// Options of [`block_maps`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct BlockMapOptions {
    /// Samples per direction of the dense `det J` sample of each map.
    pub samples: usize,
    /// Maximum subdivision depth of the Bernstein test.
    pub subdivision: usize,
    /// Also build and certify the biquadratic maps.
    pub biquadratic: bool,
}

impl Default for BlockMapOptions {
    fn default() -> Self {
        Self {
            samples: 200,
            subdivision: 4,
            biquadratic: true,
        }
    }
}

impl BlockMapOptions {
    /// Sets [`samples`](Self::samples): samples per direction of the dense `det J` sample of each
    /// map.
    #[must_use]
    pub fn samples(mut self, samples: usize) -> Self {
        self.samples = samples;
        self
    }

    /// Sets [`subdivision`](Self::subdivision): maximum subdivision depth of the Bernstein test.
    #[must_use]
    pub fn subdivision(mut self, subdivision: usize) -> Self {
        self.subdivision = subdivision;
        self
    }

    /// Sets [`biquadratic`](Self::biquadratic): also build and certify the biquadratic maps.
    #[must_use]
    pub fn biquadratic(mut self, biquadratic: bool) -> Self {
        self.biquadratic = biquadratic;
        self
    }
}

/// The maps of one block.
#[derive(Debug, Clone)]
pub struct BlockMap {
    /// Block index in the block mesh.
    pub block: usize,
    /// The bilinear map (always built).
    pub bilinear: TensorMap,
    /// Theorem 1 on the block's net.
    pub theorem1: Theorem1Report,
    /// Sampled `det J` of the bilinear map.
    pub bilinear_sample: JacobianSample,
    /// The certificates of the biquadratic map (`None` if not requested or the block has fewer
    /// than 3 × 3 nodes).
    pub biquadratic_certificates: Option<Certificates>,
    /// The biquadratic map, present only when certified.
    pub biquadratic: Option<TensorMap>,
}

impl BlockMap {
    /// The bilinear map is injective by Theorem 1.
    pub fn bilinear_certified(&self) -> bool {
        self.theorem1.holds
    }
}

/// The maps of every block of a block mesh (module docs).
pub fn block_maps(mesh: &BlockMesh2, opts: &BlockMapOptions) -> Result<Vec<BlockMap>, CoreError> {
    let mut out = Vec::with_capacity(mesh.blocks().len());
    for (b, g) in mesh.blocks().iter().enumerate() {
        let net = ControlNet::from_grid(g);
        let bilinear = TensorMap::new(Degree::Bilinear, net.clone())?;
        let t1 = theorem1(&net);
        let bilinear_sample = sample_det_j(&bilinear, opts.samples, opts.samples)?;
        let (cert, bq) = if opts.biquadratic && net.n() >= 3 && net.m() >= 3 {
            let map = TensorMap::new(Degree::Biquadratic, net)?;
            let c = certify_map(&map, opts.samples, opts.subdivision)?;
            let keep = c.certified;
            (Some(c), keep.then_some(map))
        } else {
            (None, None)
        };
        out.push(BlockMap {
            block: b,
            bilinear,
            theorem1: t1,
            bilinear_sample,
            biquadratic_certificates: cert,
            biquadratic: bq,
        });
    }
    Ok(out)
}

/// [`block_maps`] of a pipeline result's block mesh.
pub fn mesh_result_maps(
    result: &MeshResult,
    opts: &BlockMapOptions,
) -> Result<Vec<BlockMap>, CoreError> {
    block_maps(&result.mesh, opts)
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::{DVec2, StructuredGrid2};

    use super::*;

    /// Two blocks sharing a whole side: bilinear maps interpolate, both are certified, and the
    /// biquadratic maps agree along the shared side (symmetric clamped knots).
    #[test]
    fn two_blocks_share_their_side() {
        // a curved shared side x = 1 + 0.1 sin(πy)
        let side = |j: usize| {
            let y = j as f64 / 4.0;
            DVec2::new(1.0 + 0.1 * (std::f64::consts::PI * y).sin(), y)
        };
        let left = StructuredGrid2::from_fn(5, 5, |i, j| {
            let t = i as f64 / 4.0;
            (1.0 - t) * DVec2::new(0.0, j as f64 / 4.0) + t * side(j)
        })
        .unwrap();
        let right = StructuredGrid2::from_fn(4, 5, |i, j| {
            let t = i as f64 / 3.0;
            (1.0 - t) * side(j) + t * DVec2::new(2.0, j as f64 / 4.0)
        })
        .unwrap();
        let mesh = BlockMesh2::merge(vec![left, right], 1e-9).unwrap();
        let maps = block_maps(&mesh, &BlockMapOptions::default()).unwrap();
        assert_eq!(maps.len(), 2);
        for m in &maps {
            assert!(m.bilinear_certified());
            assert!(m.bilinear_sample.min > 0.0);
            assert!(m.biquadratic.is_some(), "block {} not certified", m.block);
        }
        // Lemma 1: the bilinear map of block 0 passes through its nodes
        assert!((maps[0].bilinear.eval(1.0, 0.5) - side(2)).length() < 1e-14);
        let (a, b) = (
            maps[0].biquadratic.as_ref().unwrap(),
            maps[1].biquadratic.as_ref().unwrap(),
        );
        for k in 0..=20 {
            let eta = k as f64 / 20.0;
            assert!((a.eval(1.0, eta) - b.eval(0.0, eta)).length() < 1e-14);
        }
    }
}
