//! Seeded random perturbation of the free (interior) nodes, to create folded starts
//! ([Cortés Aguirre 2012, §2.2.3]: initial meshes may be perturbed to get a wider range of
//! starts; the Esfera example is perturbed until 22 cells are non-convex, §3.4.3. The references
//! are listed in `docs/references.md` of the repository).
//!
//! Each free node `v` moves by `s·h_v·u`, where `h_v` is the length of the shortest mesh edge
//! at `v` and `u` is uniform in the unit ball (rejection sampling of the cube `[−1, 1]³`).
//! Scaling by `h_v` makes `s` a dimensionless amplitude: `s < ½` can never move a node past
//! the midpoint of its shortest edge. The random numbers come from **SplitMix64**
//! (Steele, Lea and Flood, 2014: `z += 0x9E3779B97F4A7C15`, then two xor-shift-multiply
//! rounds), written out here (12 lines) rather than pulled from `rand`, so the perturbed
//! meshes of a given seed are stable across dependency upgrades; uniform doubles take the
//! top 53 bits.

use glam::DVec3;

use super::error::HexGenError;
use crate::quality::hex_non_convex_count;
use crate::traits::{FreeNodes, HasHexCells};

/// The 12 edges of a hexahedron in VTK order.
pub const HEX_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 0],
    [4, 5],
    [5, 6],
    [6, 7],
    [7, 4],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];

/// The SplitMix64 generator (see the module documentation).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator with the given seed.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)` (53 random bits).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in the unit ball.
    pub fn in_unit_ball(&mut self) -> DVec3 {
        loop {
            let u = DVec3::new(
                2.0 * self.next_f64() - 1.0,
                2.0 * self.next_f64() - 1.0,
                2.0 * self.next_f64() - 1.0,
            );
            if u.length_squared() <= 1.0 {
                return u;
            }
        }
    }
}

/// Length of the shortest edge at every node (`+∞` for nodes of no cell).
pub fn shortest_edges<M: HasHexCells + ?Sized>(mesh: &M) -> Vec<f64> {
    let x = mesh.nodes();
    let mut h = vec![f64::INFINITY; x.len()];
    for c in 0..mesh.num_hexes() {
        let v = mesh.hex(c);
        for [a, b] in HEX_EDGES {
            let l = x[v[a]].distance(x[v[b]]);
            h[v[a]] = h[v[a]].min(l);
            h[v[b]] = h[v[b]].min(l);
        }
    }
    h
}

/// Moves every free node by `amplitude·h_v·u` (see the module documentation), in increasing
/// node order, with the generator seeded by `seed`. Returns how many nodes moved.
///
/// ```
/// use unamalla_mesh::hexgen::{ball_grid, perturb_interior};
/// let mut g = ball_grid((6, 6, 6)).unwrap();
/// let before = g.clone();
/// assert_eq!(perturb_interior(&mut g, 0.2, 7).unwrap(), 4 * 4 * 4);
/// assert_eq!(g.node(0, 2, 3), before.node(0, 2, 3)); // boundary nodes stay
/// ```
pub fn perturb_interior<M: HasHexCells + FreeNodes + ?Sized>(
    mesh: &mut M,
    amplitude: f64,
    seed: u64,
) -> Result<usize, HexGenError> {
    if !(amplitude.is_finite() && amplitude >= 0.0) {
        return Err(HexGenError::InvalidParameter {
            name: "perturbation amplitude",
            value: amplitude,
            reason: "must be finite and ≥ 0 (a multiple of the shortest edge at each node)",
        });
    }
    let h = shortest_edges(mesh);
    let mut rng = SplitMix64::new(seed);
    let free = mesh.free_nodes();
    let nodes = mesh.nodes_mut();
    let mut moved = 0;
    for v in free {
        let u = rng.in_unit_ball();
        if h[v].is_finite() {
            nodes[v] += amplitude * h[v] * u;
            moved += 1;
        }
    }
    Ok(moved)
}

/// The smallest amplitude of the sequence `s₀, 1.1·s₀, 1.1²·s₀, …` (at most `max_steps`
/// tries) whose [`perturb_interior`] (same `seed`) leaves at least `min_nonconvex` cells
/// failing the plain 10-tetrahedra test. The mesh is left perturbed with that amplitude;
/// returns `(amplitude, non-convex cells)`. If no amplitude of the sequence reaches the
/// target, the last one is kept.
pub fn perturb_until_nonconvex<M: HasHexCells + FreeNodes + Clone>(
    mesh: &mut M,
    min_nonconvex: usize,
    start_amplitude: f64,
    seed: u64,
    max_steps: usize,
) -> Result<(f64, usize), HexGenError> {
    if !(start_amplitude.is_finite() && start_amplitude > 0.0) {
        return Err(HexGenError::InvalidParameter {
            name: "start amplitude",
            value: start_amplitude,
            reason: "must be finite and > 0",
        });
    }
    let orig = mesh.clone();
    let mut amp = start_amplitude;
    let mut last = (amp, 0);
    for _ in 0..max_steps.max(1) {
        *mesh = orig.clone();
        perturb_interior(mesh, amp, seed)?;
        let nc = hex_non_convex_count(mesh, 0.0);
        last = (amp, nc);
        if nc >= min_nonconvex {
            break;
        }
        amp *= 1.1;
    }
    Ok(last)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::StructuredGrid3;
    use crate::traits::HasNodes;

    fn unit_grid(n: usize) -> StructuredGrid3 {
        let h = 1.0 / (n - 1) as f64;
        StructuredGrid3::from_fn(n, n, n, |i, j, k| {
            DVec3::new(i as f64, j as f64, k as f64) * h
        })
        .unwrap()
    }

    #[test]
    fn splitmix_matches_the_reference_sequence() {
        // first outputs of SplitMix64 with seed 1234567 (the reference C implementation by
        // Vigna, splitmix64.c, as listed in many test suites)
        let mut r = SplitMix64::new(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
        assert_eq!(r.next_u64(), 9817491932198370423);
    }

    #[test]
    fn displacements_are_bounded_by_amplitude_times_shortest_edge() {
        let g0 = unit_grid(6);
        let mut g = g0.clone();
        perturb_interior(&mut g, 0.3, 42).unwrap();
        let h = 1.0 / 5.0;
        let mut max_d: f64 = 0.0;
        for (a, b) in g0.nodes().iter().zip(g.nodes()) {
            let d = a.distance(*b);
            assert!(d <= 0.3 * h + 1e-15);
            max_d = max_d.max(d);
        }
        // 64 uniform points in a ball: the largest is well beyond half the radius
        assert!(max_d > 0.15 * h);
        // same seed, same mesh; different seed, different mesh
        let mut g2 = g0.clone();
        perturb_interior(&mut g2, 0.3, 42).unwrap();
        assert_eq!(g, g2);
        let mut g3 = g0.clone();
        perturb_interior(&mut g3, 0.3, 43).unwrap();
        assert_ne!(g, g3);
    }

    #[test]
    fn small_perturbations_keep_a_cube_grid_convex_and_the_search_reaches_its_target() {
        let mut g = unit_grid(8);
        perturb_interior(&mut g, 0.05, 1).unwrap();
        assert_eq!(hex_non_convex_count(&g, 0.0), 0);
        let mut g = unit_grid(8);
        let (amp, nc) = perturb_until_nonconvex(&mut g, 10, 0.05, 3, 40).unwrap();
        assert!(nc >= 10 && amp > 0.05, "{amp} {nc}");
        assert_eq!(hex_non_convex_count(&g, 0.0), nc);
        assert!(perturb_interior(&mut g, f64::NAN, 1).is_err());
    }
}
