//! Internal reduced form of problem (5.10) over a subset of constraint groups, the exact network-flow
//! solver used when the matrix is a (row-signed) network matrix, and a MILP on the reduced form.
//!
//! Reduction (the substitution of (5.11)): copies of a cut are merged into one class variable, pinned
//! classes are substituted, and `x_c = m_c − L_c ≥ 0` for the free classes. Every class column then has at
//! most two non-zeros, both ±1 in the common case. When the rows can be re-signed so that each two-entry
//! column has one +1 and one −1 (a 2-colouring, the condition of Prop. 5.2), the system is the node–arc
//! incidence matrix of a directed graph plus a ground node, and (5.11) is an uncapacitated min-cost
//! transshipment problem with positive arc costs. It is solved exactly, in integers, by successive shortest
//! paths with Dijkstra and node potentials; the final potentials are an integral dual certificate.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use crate::lp::{LinearProgram, LpOutcome, MilpBackend, Sense, VarDef};
use crate::system::CompatSystem;

/// Which constraint groups take part (all of them for the real problem; subsets in the deletion filter).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Active {
    /// One flag per side row (rows `0..2n` of the system).
    pub side_rows: Vec<bool>,
    /// One flag per cut.
    pub cuts: Vec<bool>,
    /// One flag per curve: whether its pin (if any) is enforced.
    pub pins: Vec<bool>,
}

impl Active {
    pub fn all(num_side_rows: usize, num_cuts: usize, num_curves: usize) -> Self {
        Active {
            side_rows: vec![true; num_side_rows],
            cuts: vec![true; num_cuts],
            pins: vec![true; num_curves],
        }
    }
}

/// The data of problem (5.10) that does not depend on the active groups.
#[derive(Debug, Clone)]
pub(crate) struct Instance<'a> {
    pub system: &'a CompatSystem,
    /// Number of side rows (`2n`).
    pub num_side_rows: usize,
    /// Cut pairs (curve indices).
    pub cuts: Vec<(usize, usize)>,
    /// Lower bounds `L_j`.
    pub lower: Vec<i64>,
    /// Pins.
    pub pins: Vec<Option<i64>>,
    /// Time limit (seconds) for each MILP call.
    pub time_limit: Option<f64>,
}

/// A class of curves forced equal by active cut equations.
#[derive(Debug, Clone)]
pub(crate) struct Class {
    pub members: Vec<usize>,
    /// Value forced by an active pin.
    pub fixed: Option<i64>,
    /// Lower bound (max of the members' non-pinned bounds).
    pub lb: i64,
    /// `(reduced row, coefficient)`, coefficients combined per row, zeros dropped.
    pub entries: Vec<(usize, i64)>,
}

/// Reduced problem: `min Σ_c |c|·x_c`, `Σ_c a_{rc} x_c = rhs_r` (free classes only), `x ≥ 0`.
#[derive(Debug, Clone)]
pub(crate) struct Reduced {
    pub classes: Vec<Class>,
    /// System row index of each reduced row.
    pub row_of: Vec<usize>,
    pub rhs: Vec<i64>,
}

/// Why the reduction itself shows infeasibility.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct TrivialConflict;

impl Instance<'_> {
    /// Build the reduced problem for the active groups.
    pub fn reduce(&self, active: &Active) -> Result<Reduced, TrivialConflict> {
        let p = self.lower.len();
        // union-find over active cuts (each curve is in at most one cut, so classes have size ≤ 2)
        let mut class_of: Vec<usize> = vec![usize::MAX; p];
        let mut classes: Vec<Class> = Vec::with_capacity(p);
        for (i, &(a, b)) in self.cuts.iter().enumerate() {
            if active.cuts[i] {
                class_of[a] = classes.len();
                class_of[b] = classes.len();
                classes.push(Class {
                    members: vec![a, b],
                    fixed: None,
                    lb: 0,
                    entries: Vec::new(),
                });
            }
        }
        for (j, c) in class_of.iter_mut().enumerate() {
            if *c == usize::MAX {
                *c = classes.len();
                classes.push(Class {
                    members: vec![j],
                    fixed: None,
                    lb: 0,
                    entries: Vec::new(),
                });
            }
        }
        for class in &mut classes {
            let mut lb = 0i64;
            let mut fixed: Option<i64> = None;
            for &j in &class.members {
                match (self.pins[j], active.pins[j]) {
                    (Some(pin), true) => {
                        if fixed.is_some_and(|f| f != pin) {
                            return Err(TrivialConflict);
                        }
                        fixed = Some(pin);
                    }
                    _ => lb = lb.max(self.lower[j]),
                }
            }
            if let Some(f) = fixed {
                if f < lb {
                    return Err(TrivialConflict);
                }
            }
            class.lb = lb;
            class.fixed = fixed;
        }
        let mut row_of = Vec::new();
        let mut rhs = Vec::new();
        for r in 0..self.num_side_rows {
            if !active.side_rows[r] {
                continue;
            }
            let rr = row_of.len();
            row_of.push(r);
            let eq = &self.system.equations[r];
            let mut b = eq.rhs;
            for &(j, a) in &eq.terms {
                let c = &mut classes[class_of[j]];
                b -= a * c.fixed.unwrap_or(c.lb);
                if c.fixed.is_none() {
                    if let Some(e) = c.entries.iter_mut().find(|e| e.0 == rr) {
                        e.1 += a;
                    } else {
                        c.entries.push((rr, a));
                    }
                }
            }
            rhs.push(b);
        }
        for c in &mut classes {
            c.entries.retain(|e| e.1 != 0);
        }
        Ok(Reduced {
            classes,
            row_of,
            rhs,
        })
    }
}

/// Result of an exact network solve.
#[derive(Debug, Clone)]
pub(crate) enum FlowOutcome {
    /// Optimal counts per curve and row duals `y` for every system row (side rows then cut rows), integral.
    Optimal {
        counts: Vec<i64>,
        duals: Vec<i64>,
    },
    Infeasible,
}

impl Reduced {
    /// Row signs `σ_r ∈ {±1}` making every free two-entry column a +1/−1 column, if they exist.
    pub fn orientation(&self) -> Option<Vec<i64>> {
        let nr = self.rhs.len();
        let mut adj: Vec<Vec<(usize, i64)>> = vec![Vec::new(); nr];
        for c in &self.classes {
            if c.fixed.is_some() {
                continue;
            }
            match c.entries.as_slice() {
                [] => {}
                [(_, a)] => {
                    if a.abs() != 1 {
                        return None;
                    }
                }
                [(u, a), (v, b)] => {
                    if a.abs() != 1 || b.abs() != 1 {
                        return None;
                    }
                    // need σ_u a = −σ_v b  ⇔  σ_u σ_v = −a b
                    let rel = -a * b;
                    adj[*u].push((*v, rel));
                    adj[*v].push((*u, rel));
                }
                _ => return None,
            }
        }
        let mut sigma = vec![0i64; nr];
        let mut queue = VecDeque::new();
        for s in 0..nr {
            if sigma[s] != 0 {
                continue;
            }
            sigma[s] = 1;
            queue.push_back(s);
            while let Some(u) = queue.pop_front() {
                for &(v, rel) in &adj[u] {
                    let want = sigma[u] * rel;
                    if sigma[v] == 0 {
                        sigma[v] = want;
                        queue.push_back(v);
                    } else if sigma[v] != want {
                        return None;
                    }
                }
            }
        }
        Some(sigma)
    }

    /// Solve exactly as a min-cost transshipment with row signs `sigma` (from [`Reduced::orientation`]).
    /// Returns counts for all curves and integral duals for the **active** system rows, expanded to the
    /// whole system (inactive rows get 0) using `inst` to place cut-row duals.
    pub fn solve_flow(&self, sigma: &[i64], inst: &Instance<'_>, active: &Active) -> FlowOutcome {
        let nr = self.rhs.len();
        let g = nr;
        let src = nr + 1;
        let snk = nr + 2;
        let mut net = Network::new(nr + 3);
        let mut class_arc: Vec<Option<usize>> = vec![None; self.classes.len()];
        for (ci, c) in self.classes.iter().enumerate() {
            if c.fixed.is_some() || c.entries.is_empty() {
                continue;
            }
            let cost = c.members.len() as i64;
            let (tail, head) = match c.entries.as_slice() {
                [(u, a)] => {
                    if sigma[*u] * a > 0 {
                        (*u, g)
                    } else {
                        (g, *u)
                    }
                }
                [(u, a), (v, _)] => {
                    if sigma[*u] * a > 0 {
                        (*u, *v)
                    } else {
                        (*v, *u)
                    }
                }
                _ => return FlowOutcome::Infeasible,
            };
            class_arc[ci] = Some(net.add_edge(tail, head, INF_CAP, cost));
        }
        let mut bal: Vec<i64> = (0..nr).map(|r| sigma[r] * self.rhs[r]).collect();
        bal.push(-bal.iter().sum::<i64>());
        let mut need = 0i64;
        for (u, &b) in bal.iter().enumerate() {
            if b > 0 {
                net.add_edge(src, u, b, 0);
                need += b;
            } else if b < 0 {
                net.add_edge(u, snk, -b, 0);
            }
        }
        let (flow, pot) = net.min_cost_flow(src, snk, need);
        if flow < need {
            return FlowOutcome::Infeasible;
        }
        // counts
        let mut counts = vec![0i64; inst.lower.len()];
        for (ci, c) in self.classes.iter().enumerate() {
            let x = class_arc[ci].map(|e| net.flow(e)).unwrap_or(0);
            for &j in &c.members {
                counts[j] = c.fixed.unwrap_or(c.lb + x);
            }
        }
        // duals: π_u = h_g − h_u on the signed rows; y_r = σ_r π_r on the original rows
        let mut duals = vec![0i64; inst.system.equations.len()];
        for rr in 0..nr {
            duals[self.row_of[rr]] = sigma[rr] * (pot[g] - pot[rr]);
        }
        // cut rows: split the class' reduced cost between the two copies
        let place_row = side_row_of_curves(inst);
        let col_fast = |j: usize, duals: &[i64]| -> i64 {
            match place_row[j] {
                Some((r, a)) => a * duals[r],
                None => 0,
            }
        };
        for (i, &(a, b)) in inst.cuts.iter().enumerate() {
            if !active.cuts[i] {
                continue;
            }
            let row = inst.num_side_rows + i;
            let sa = col_fast(a, &duals);
            let sb = col_fast(b, &duals);
            let pinned_a = inst.pins[a].is_some() && active.pins[a];
            let pinned_b = inst.pins[b].is_some() && active.pins[b];
            // copy a: column entry +1 in the cut row; copy b: −1
            let y = if !pinned_a && counts[a] > inst.lower[a] {
                1 - sa
            } else if !pinned_b && counts[b] > inst.lower[b] {
                sb - 1
            } else if !pinned_a {
                1 - sa
            } else if !pinned_b {
                sb - 1
            } else {
                0
            };
            duals[row] = y;
        }
        FlowOutcome::Optimal { counts, duals }
    }

    /// Solve the reduced problem as a MILP with `backend` (a second formulation of (5.10)).
    /// Returns counts per curve, unverified except for integrality of the raw values.
    pub fn solve_milp(
        &self,
        inst: &Instance<'_>,
        backend: MilpBackend,
        relax: bool,
    ) -> Result<Option<Vec<f64>>, String> {
        let lp = self.linear_program();
        match lp.solve(backend, relax, inst.time_limit) {
            LpOutcome::Solved(x) => Ok(Some(self.expand(inst, &x))),
            LpOutcome::Infeasible => Ok(None),
            LpOutcome::Failed(e) => Err(e),
        }
    }

    /// The reduced problem as a [`LinearProgram`] over the free classes.
    pub fn linear_program(&self) -> LinearProgram {
        let mut lp = LinearProgram::default();
        let mut var_of = vec![usize::MAX; self.classes.len()];
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.rhs.len()];
        for (ci, c) in self.classes.iter().enumerate() {
            if c.fixed.is_some() || c.entries.is_empty() {
                continue;
            }
            var_of[ci] = lp.vars.len();
            lp.vars.push(VarDef {
                lower: 0.0,
                upper: f64::INFINITY,
                integer: true,
                cost: c.members.len() as f64,
            });
            for &(r, a) in &c.entries {
                rows[r].push((var_of[ci], a as f64));
            }
        }
        for (r, terms) in rows.into_iter().enumerate() {
            lp.rows.push((terms, Sense::Eq, self.rhs[r] as f64));
        }
        lp
    }

    /// Map raw reduced values back to per-curve values.
    pub fn expand(&self, inst: &Instance<'_>, x: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; inst.lower.len()];
        let mut k = 0;
        for c in &self.classes {
            let v = if let Some(f) = c.fixed {
                f as f64
            } else if c.entries.is_empty() {
                c.lb as f64
            } else {
                let v = c.lb as f64 + x[k];
                k += 1;
                v
            };
            for &j in &c.members {
                out[j] = v;
            }
        }
        out
    }

    /// Whether the reduced problem is feasible: exact for network systems; MILP otherwise.
    pub fn is_feasible(&self, inst: &Instance<'_>, active: &Active) -> Option<bool> {
        if self.rhs.is_empty() {
            return Some(true);
        }
        match self.orientation() {
            Some(sigma) => Some(matches!(
                self.solve_flow(&sigma, inst, active),
                FlowOutcome::Optimal { .. }
            )),
            None => match self.solve_milp(inst, MilpBackend::Microlp, false) {
                Ok(Some(_)) => Some(true),
                Ok(None) => Some(false),
                Err(_) => None,
            },
        }
    }
}

/// For each curve, the side row holding it and its coefficient.
fn side_row_of_curves(inst: &Instance<'_>) -> Vec<Option<(usize, i64)>> {
    let mut out = vec![None; inst.lower.len()];
    for (r, eq) in inst.system.equations[..inst.num_side_rows]
        .iter()
        .enumerate()
    {
        for &(j, a) in &eq.terms {
            out[j] = Some((r, a));
        }
    }
    out
}

pub(crate) const INF_CAP: i64 = i64::MAX / 4;

#[derive(Debug, Clone, Copy)]
struct Edge {
    to: usize,
    cap: i64,
    cost: i64,
}

/// Residual network for successive shortest paths.
pub(crate) struct Network {
    edges: Vec<Edge>,
    adj: Vec<Vec<usize>>,
}

impl Network {
    pub(crate) fn new(n: usize) -> Self {
        Network {
            edges: Vec::new(),
            adj: vec![Vec::new(); n],
        }
    }

    /// Add `u→v` and its reverse; returns the forward edge index (reverse = index ^ 1).
    pub(crate) fn add_edge(&mut self, u: usize, v: usize, cap: i64, cost: i64) -> usize {
        let e = self.edges.len();
        self.edges.push(Edge { to: v, cap, cost });
        self.edges.push(Edge {
            to: u,
            cap: 0,
            cost: -cost,
        });
        self.adj[u].push(e);
        self.adj[v].push(e + 1);
        e
    }

    pub(crate) fn flow(&self, e: usize) -> i64 {
        self.edges[e ^ 1].cap
    }

    /// One augmenting path in the level graph of admissible arcs (depth-first, current-arc pointers).
    /// Iterative, so deep level graphs cannot overflow the stack.
    fn augment(
        &mut self,
        s: usize,
        t: usize,
        limit: i64,
        level: &[usize],
        iter: &mut [usize],
        pot: &[i64],
    ) -> i64 {
        let mut path: Vec<usize> = Vec::new(); // edge indices from s
        let mut u = s;
        loop {
            if u == t {
                let f = path
                    .iter()
                    .map(|&e| self.edges[e].cap)
                    .fold(limit, i64::min);
                for &e in &path {
                    self.edges[e].cap -= f;
                    self.edges[e ^ 1].cap += f;
                }
                return f;
            }
            let mut advanced = false;
            while iter[u] < self.adj[u].len() {
                let e = self.adj[u][iter[u]];
                let ed = self.edges[e];
                if ed.cap > 0
                    && level[ed.to] == level[u].wrapping_add(1)
                    && ed.cost + pot[u] - pot[ed.to] == 0
                {
                    path.push(e);
                    u = ed.to;
                    advanced = true;
                    break;
                }
                iter[u] += 1;
            }
            if !advanced {
                // dead end: retreat and skip the arc that led here
                match path.pop() {
                    None => return 0,
                    Some(e) => {
                        u = self.edges[e ^ 1].to;
                        iter[u] += 1;
                    }
                }
            }
        }
    }

    /// Primal–dual min-cost flow: Dijkstra with potentials (all initial costs ≥ 0) to find the shortest
    /// distances, then blocking flows on the zero-reduced-cost arcs, repeated until `limit` is sent or the
    /// sink is unreachable. Returns the flow sent and the final potentials.
    pub(crate) fn min_cost_flow(&mut self, s: usize, t: usize, limit: i64) -> (i64, Vec<i64>) {
        let n = self.adj.len();
        let mut pot = vec![0i64; n];
        let mut dist = vec![i64::MAX; n];
        let mut level = vec![usize::MAX; n];
        let mut iter = vec![0usize; n];
        let mut queue = VecDeque::new();
        let mut flow = 0i64;
        let mut heap = BinaryHeap::new();
        while flow < limit {
            dist.iter_mut().for_each(|d| *d = i64::MAX);
            dist[s] = 0;
            heap.clear();
            heap.push(Reverse((0i64, s)));
            while let Some(Reverse((d, u))) = heap.pop() {
                if d > dist[u] {
                    continue;
                }
                for &e in &self.adj[u] {
                    let ed = self.edges[e];
                    if ed.cap <= 0 {
                        continue;
                    }
                    let nd = d + ed.cost + pot[u] - pot[ed.to];
                    if nd < dist[ed.to] {
                        dist[ed.to] = nd;
                        heap.push(Reverse((nd, ed.to)));
                    }
                }
            }
            if dist[t] == i64::MAX {
                break;
            }
            let dmax = dist
                .iter()
                .filter(|&&d| d != i64::MAX)
                .copied()
                .max()
                .unwrap_or(0);
            for v in 0..n {
                pot[v] += if dist[v] == i64::MAX { dmax } else { dist[v] };
            }
            // blocking flows (Dinic) on the admissible arcs: residual capacity and zero reduced cost
            loop {
                level.iter_mut().for_each(|l| *l = usize::MAX);
                level[s] = 0;
                queue.clear();
                queue.push_back(s);
                while let Some(u) = queue.pop_front() {
                    for &e in &self.adj[u] {
                        let ed = self.edges[e];
                        if ed.cap > 0
                            && level[ed.to] == usize::MAX
                            && ed.cost + pot[u] - pot[ed.to] == 0
                        {
                            level[ed.to] = level[u] + 1;
                            queue.push_back(ed.to);
                        }
                    }
                }
                if level[t] == usize::MAX {
                    break;
                }
                iter.iter_mut().for_each(|i| *i = 0);
                loop {
                    let f = self.augment(s, t, limit - flow, &level, &mut iter, &pot);
                    if f == 0 {
                        break;
                    }
                    flow += f;
                    if flow >= limit {
                        break;
                    }
                }
                if flow >= limit {
                    break;
                }
            }
        }
        (flow, pot)
    }
}
