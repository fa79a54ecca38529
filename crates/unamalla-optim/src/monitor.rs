//! The monitor ([González Flores, §A.4.3, Table A.1]), the observers and the quality probe of the
//! plateau test. The per-run bookkeeping that measures convexity and enforces the domain
//! safeguard ([`Session`], [`Convexity`]) is in [`crate::safeguard`] and re-exported here.

use std::io::Write;
use std::time::{Duration, Instant};

pub use crate::safeguard::{Convexity, Session, GUARD_MARGIN};

/// The phase a driver is in (the three iteration counters of Table A.1, plus the continuation
/// phases of [Cortés Aguirre 2012, Algorithm A, Algorithm B]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum Phase {
    /// Pre-smoothing with Length ("IterSmooth").
    Smooth,
    /// Homotopy / continuation phase ("IterHomotopic"): adaptive k, ω-halving, μ-continuation.
    Homotopic,
    /// Classic / refinement phase ("IterClassic").
    #[default]
    Classic,
}

/// What an observer sees every iteration (Table A.1 fields).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Monitor {
    /// "Alfamin": `α₋`, the minimum measure over the elements with at least one free vertex
    /// (corner-triangle α in 2D, tetrahedron Jacobian in 3D).
    pub alfamin: f64,
    /// `ᾱ`, the mean measure over all elements.
    pub alpha_bar: f64,
    /// "Kcurrent": `k/ᾱ` of the adaptive driver (`None` outside it).
    pub k_current: Option<f64>,
    /// "Kold": the previous `k/ᾱ`.
    pub k_old: Option<f64>,
    /// Current `ω` (Algorithm A, (6.8)); `None` if not applicable.
    pub omega: Option<f64>,
    /// Current `μ` of the coplanarity continuation (Algorithm B).
    pub mu: Option<f64>,
    /// "Inocon": cells with an element (with a free vertex) of measure `≤ 0`.
    pub inocon: usize,
    /// Elements whose vertices are all fixed and whose measure is `≤ 0` (boundary data,
    /// reported separately).
    pub fixed_nonpositive: usize,
    /// "Fvalue".
    pub f: f64,
    /// "Gnorm": Euclidean norm of the gradient.
    pub gnorm: f64,
    /// "IterSmooth".
    pub iter_smooth: usize,
    /// "IterHomotopic".
    pub iter_homotopic: usize,
    /// "IterClassic".
    pub iter_classic: usize,
    /// The current phase.
    pub phase: Phase,
    /// "Process Time".
    pub elapsed: Duration,
}

impl Monitor {
    /// `α₋/ᾱ`.
    pub fn alfamin_rel(&self) -> f64 {
        self.alfamin / self.alpha_bar
    }
    /// Total iterations over the phases.
    pub fn total_iterations(&self) -> usize {
        self.iter_smooth + self.iter_homotopic + self.iter_classic
    }
}

/// What an observer wants after an iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop the run (reported as "STOP by user").
    Stop,
}

/// Called after every iteration of every solver with the current [`Monitor`]; can stop the run.
pub trait Observer {
    /// Inspect the monitor; return [`Control::Stop`] to stop.
    fn observe(&mut self, monitor: &Monitor) -> Control;
}

impl<F: FnMut(&Monitor) -> Control> Observer for F {
    fn observe(&mut self, monitor: &Monitor) -> Control {
        self(monitor)
    }
}

/// An observer that does nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NullObserver;

impl Observer for NullObserver {
    fn observe(&mut self, _: &Monitor) -> Control {
        Control::Continue
    }
}

/// Prints one updating progress line to stderr (`\r`-rewritten, at most every `interval`):
/// phase, iteration, Alfamin (as `α₋/ᾱ`), Inocon, F, ‖g‖, k/ᾱ or ω, elapsed time. Call
/// [`finish`](Self::finish) to end the line.
#[derive(Debug)]
pub struct ProgressObserver {
    interval: Duration,
    last: Option<Instant>,
    printed: bool,
}

impl Default for ProgressObserver {
    fn default() -> Self {
        Self::new(Duration::from_millis(100))
    }
}

impl ProgressObserver {
    /// Refreshes at most once per `interval`.
    pub fn new(interval: Duration) -> Self {
        Self {
            interval,
            last: None,
            printed: false,
        }
    }
    /// The progress line for a monitor.
    pub fn line(m: &Monitor) -> String {
        let phase = match m.phase {
            Phase::Smooth => "smooth",
            Phase::Homotopic => "homot.",
            Phase::Classic => "classic",
        };
        let extra = if let Some(k) = m.k_current {
            format!(" k/ᾱ {k:+.4}")
        } else if let Some(mu) = m.mu {
            format!(" μ {mu:.1e}")
        } else if let Some(w) = m.omega {
            format!(" ω {w:.2e}")
        } else {
            String::new()
        };
        format!(
            "{phase} it {:>5} | Alfamin/ᾱ {:+.4e} | Inocon {:>6} | F {:.6e} | ‖g‖ {:.3e}{extra} | {:.2}s",
            m.total_iterations(),
            m.alfamin_rel(),
            m.inocon,
            m.f,
            m.gnorm,
            m.elapsed.as_secs_f64()
        )
    }
    /// Ends the progress line with a newline (if anything was printed).
    pub fn finish(&mut self) {
        if self.printed {
            eprintln!();
            self.printed = false;
        }
    }
}

impl Observer for ProgressObserver {
    fn observe(&mut self, m: &Monitor) -> Control {
        let now = Instant::now();
        if self
            .last
            .is_none_or(|t| now.duration_since(t) >= self.interval)
        {
            self.last = Some(now);
            let mut e = std::io::stderr().lock();
            let _ = write!(e, "\r{}\x1b[K", Self::line(m));
            let _ = e.flush();
            self.printed = true;
        }
        Control::Continue
    }
}

/// A record of every monitor seen (for tests and tables).
#[derive(Debug, Clone, Default)]
pub struct HistoryObserver {
    /// The monitors, in order.
    pub history: Vec<Monitor>,
}

impl Observer for HistoryObserver {
    fn observe(&mut self, m: &Monitor) -> Control {
        self.history.push(m.clone());
        Control::Continue
    }
}

/// A quality measure of the variables for the plateau test: the share (percent) of cells
/// with μ ≥ 0.8 ([`quad_mu_share`] for quad meshes).
pub type QualityProbe = std::sync::Arc<dyn Fn(&[f64]) -> f64 + Send + Sync>;

/// The quality probe of a quad topology: the percentage of cells with μ ≥ 0.8
/// ([`unamalla_mesh::quality::quad::mu`], the same measure and threshold as the quality
/// report's good band). Cells are counted, so the value does not depend on the thread count.
pub fn quad_mu_share(topo: std::sync::Arc<unamalla_functionals::QuadTopology>) -> QualityProbe {
    std::sync::Arc::new(move |x: &[f64]| {
        use rayon::prelude::*;
        let p = topo.node_coords(x);
        let n = topo.num_cells();
        let good = (0..n)
            .into_par_iter()
            .with_min_len(1024)
            .filter(|&c| {
                let q = topo.cell(c).map(|v| p[v]);
                unamalla_mesh::quality::quad::mu(&q) >= unamalla_mesh::quality::MU_GOOD
            })
            .count();
        100.0 * good as f64 / n.max(1) as f64
    })
}
