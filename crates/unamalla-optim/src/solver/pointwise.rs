//! Pointwise (Gauss–Seidel) Newton: the node colouring, the local Newton step of one node, the
//! sweeps, and the [`QuadLocalGuard`] that checks convexity around a node.

use std::sync::Arc;

use rayon::prelude::*;
use unamalla_functionals::{
    Csr, ElementMeasures, Gradient, Hessian, PointwiseModel, QuadTopology, Variables,
};

use super::newton::ensure_hessian;
use super::{PointwiseMode, SolverOptions, State};
use crate::linalg::{inv3_spd, norm};
use crate::monitor::Session;
use crate::status::{LineSearchFailure, StopReason};

/// Local convexity check for pointwise Newton on quad meshes: the corner triangles of the
/// cells around a node, evaluated directly (no global pass).
#[derive(Debug, Clone)]
pub struct QuadLocalGuard {
    topo: Arc<QuadTopology>,
    offsets: Vec<usize>,
    cells: Vec<u32>,
}

impl QuadLocalGuard {
    /// Builds the node → cells incidence of a topology.
    pub fn new(topo: Arc<QuadTopology>) -> Self {
        let n = topo.num_nodes();
        let mut cnt = vec![0usize; n + 1];
        for c in 0..topo.num_cells() {
            for v in topo.cell(c) {
                cnt[v + 1] += 1;
            }
        }
        for i in 0..n {
            cnt[i + 1] += cnt[i];
        }
        let mut fill = cnt.clone();
        let mut cells = vec![0u32; cnt[n]];
        for c in 0..topo.num_cells() {
            for v in topo.cell(c) {
                cells[fill[v]] = c as u32;
                fill[v] += 1;
            }
        }
        Self {
            topo,
            offsets: cnt,
            cells,
        }
    }

    /// Minimum α over the corner triangles that contain `node`, at `x`.
    pub fn node_min_alpha(&self, x: &[f64], node: usize) -> f64 {
        let pt = |v: usize| match self.topo.var_of(v) {
            Some(j) => glam::DVec2::new(x[2 * j], x[2 * j + 1]),
            None => self.topo.coords()[v],
        };
        let mut m = f64::INFINITY;
        for &c in &self.cells[self.offsets[node]..self.offsets[node + 1]] {
            let cell = self.topo.cell(c as usize);
            let Some(i) = cell.iter().position(|&v| v == node) else {
                continue;
            };
            let p = cell.map(pt);
            for k in 0..4 {
                if k == (i + 2) & 3 {
                    continue;
                }
                let a = (p[(k + 1) & 3] - p[k]).perp_dot(p[(k + 3) & 3] - p[k]);
                m = m.min(if a.is_nan() { f64::NEG_INFINITY } else { a });
            }
        }
        m
    }
}

/// Greedy node colouring of the free-node adjacency (nodes sharing a cell get different
/// colours), from the Hessian pattern.
fn node_colors(h: &Csr, dim: usize) -> Vec<Vec<usize>> {
    let nb = h.nrows / dim;
    let mut color = vec![usize::MAX; nb];
    let mut classes: Vec<Vec<usize>> = Vec::new();
    let mut used: Vec<bool> = Vec::new();
    for v in 0..nb {
        used.iter_mut().for_each(|u| *u = false);
        let r = v * dim;
        for k in h.row_offsets[r]..h.row_offsets[r + 1] {
            let u = h.col_indices[k] as usize / dim;
            if color[u] != usize::MAX {
                used[color[u]] = true;
            }
        }
        let c = used.iter().position(|u| !u).unwrap_or(used.len());
        if c == classes.len() {
            classes.push(Vec::new());
            used.push(false);
        }
        color[v] = c;
        classes[c].push(v);
    }
    classes
}

/// Local Newton step of one node (`comp = None`: simultaneous; `Some(c)`: coordinate `c`).
fn local_step(m: &unamalla_functionals::LocalModel, comp: Option<usize>) -> [f64; 3] {
    let dim = m.dim;
    let mut d = [0.0; 3];
    if let Some(c) = comp {
        let hcc = m.hess[c][c];
        d[c] = if hcc > 0.0 {
            -m.grad[c] / hcc
        } else {
            let s = (0..dim)
                .map(|i| m.hess[i][i].abs())
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE);
            -m.grad[c] / s
        };
        return d;
    }
    let ok = if dim == 2 {
        let (p, q, r) = (
            m.hess[0][0],
            0.5 * (m.hess[0][1] + m.hess[1][0]),
            m.hess[1][1],
        );
        let det = p * r - q * q;
        if p > 0.0 && det > 1e-14 * p * r {
            d[0] = -(r * m.grad[0] - q * m.grad[1]) / det;
            d[1] = -(-q * m.grad[0] + p * m.grad[1]) / det;
            true
        } else {
            false
        }
    } else if let Some(inv) = inv3_spd(&m.hess) {
        for a in 0..3 {
            d[a] = -(0..3).map(|b| inv[a][b] * m.grad[b]).sum::<f64>();
        }
        true
    } else {
        false
    };
    if !ok {
        // indefinite local Hessian: gradient step scaled by the largest diagonal entry
        let s = (0..dim)
            .map(|i| m.hess[i][i].abs())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        for (da, ga) in d.iter_mut().zip(&m.grad).take(dim) {
            *da = -ga / s;
        }
    }
    d
}

pub(super) fn pointwise<P>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
    local_guard: Option<&QuadLocalGuard>,
) -> StopReason
where
    P: Variables + Gradient + Hessian + PointwiseModel + ElementMeasures + ?Sized,
{
    let dim = problem.dim();
    let ok = matches!(&session.colors, Some(c) if c.iter().map(Vec::len).sum::<usize>() * dim == problem.num_vars());
    if !ok {
        ensure_hessian(problem, session);
        let classes = match session.hess.as_ref() {
            Some(h) => node_colors(h, dim),
            None => node_colors(&problem.hessian_pattern(), dim),
        };
        session.colors = Some(classes);
    }
    let colors = session.colors.take().unwrap_or_default();
    let free = problem.free_nodes().to_vec();
    let mut x0 = vec![0.0; x.len()];
    let comps: Vec<Option<usize>> = match opts.pointwise_mode {
        PointwiseMode::Simultaneous => vec![None],
        PointwiseMode::Components => (0..dim).map(Some).collect(),
    };
    struct Prop {
        v: usize,
        d: [f64; 3],
        old: [f64; 3],
        val: f64,
        gd: f64,
        t: f64,
        done: bool,
    }
    let reason = loop {
        let guard = session.guard_active(st.cur_min);
        let thr = session.threshold();
        x0.copy_from_slice(x);
        for class in &colors {
            for &comp in &comps {
                let xr: &[f64] = x;
                let mut props: Vec<Prop> = class
                    .par_iter()
                    .with_min_len(256)
                    .filter_map(|&v| {
                        let m = problem.local(xr, free[v])?;
                        let d = local_step(&m, comp);
                        let gd: f64 = (0..dim).map(|a| m.grad[a] * d[a]).sum();
                        if gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) || !gd.is_finite()
                        {
                            return None;
                        }
                        let mut old = [0.0; 3];
                        old[..dim].copy_from_slice(&xr[dim * v..dim * v + dim]);
                        // the same value-only evaluation as the trials below
                        let val = problem.local_value(xr, free[v]).unwrap_or(m.value);
                        Some(Prop {
                            v,
                            d,
                            old,
                            val,
                            gd,
                            t: 1.0,
                            done: false,
                        })
                    })
                    .collect();
                for _ in 0..8 {
                    for p in props.iter().filter(|p| !p.done) {
                        for a in 0..dim {
                            x[dim * p.v + a] = p.old[a] + p.t * p.d[a];
                        }
                    }
                    let xr: &[f64] = x;
                    props
                        .par_iter_mut()
                        .with_min_len(256)
                        .filter(|p| !p.done)
                        .for_each(|p| {
                            let node = free[p.v];
                            let acc = problem
                                .local_value(xr, node)
                                .is_some_and(|v| v.is_finite() && v <= p.val + 1e-4 * p.t * p.gd)
                                && (!guard
                                    || local_guard
                                        .is_none_or(|lg| lg.node_min_alpha(xr, node) > thr));
                            if acc {
                                p.done = true;
                            } else {
                                p.t *= 0.5;
                            }
                        });
                    if props.iter().all(|p| p.done) {
                        break;
                    }
                }
                for p in props.iter().filter(|p| !p.done) {
                    x[dim * p.v..dim * p.v + dim].copy_from_slice(&p.old[..dim]);
                }
            }
        }
        if guard && local_guard.is_none() && !session.admissible(problem, x) {
            // sweep-level safeguard: backtrack along the sweep displacement
            let xs = x.to_vec();
            let mut t = 0.5;
            let mut found = false;
            for _ in 0..40 {
                for i in 0..x.len() {
                    x[i] = x0[i] + t * (xs[i] - x0[i]);
                }
                if session.admissible(problem, x) {
                    found = true;
                    break;
                }
                t *= 0.5;
            }
            if !found {
                x.copy_from_slice(&x0);
                break StopReason::LineSearch(LineSearchFailure::Rounding);
            }
        }
        let f_new = problem.value_grad(x, g);
        st.fevals += 1;
        let gn = norm(g);
        if let Some(r) = st.accept(problem, x, f_new, gn, opts, session, false) {
            break r;
        }
    };
    session.colors = Some(colors);
    reason
}
