//! Termination reasons and the UNAMALLA status messages ([González Flores, Table A.2]).

use std::fmt;

/// Why a line search (Moré–Thuente, MINPACK-2 `dcsrch` info codes) ended without satisfying
/// the strong Wolfe conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum LineSearchFailure {
    /// The interval of uncertainty is below `xtol`.
    Xtol,
    /// Rounding errors prevent further progress (also: no admissible decrease found).
    Rounding,
    /// The step is at the lower bound `stpmin`.
    StpMin,
    /// The step is at the upper bound `stpmax`.
    StpMax,
    /// The maximum number of function evaluations was reached.
    MaxFev,
}

/// Why a solver run stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum StopReason {
    /// Relative change of `F` below FTOL.
    Ftol,
    /// Gradient norm below GTOL (relative to the first gradient of the run, or absolute).
    Gtol,
    /// Iteration limit reached.
    MaxIter,
    /// The observer asked to stop.
    User,
    /// The explicit time limit of the run ([`Session::set_time_limit`](crate::monitor::Session::set_time_limit),
    /// `Mesher::time_limit`, `--time-limit`) was reached ("STOP by TIME LIMIT"; never reported
    /// as "by user").
    TimeLimit,
    /// The window test of [`StopRules`](crate::solver::StopRules): `F` decreased by at most
    /// `window_ftol·|F|` over the last `window` iterations ("STOP by WINDOW FTOL condition").
    WindowFtol,
    /// The quality plateau of [`StopRules`](crate::solver::StopRules): α₋/ᾱ and the share of
    /// cells with μ ≥ 0.8 did not change over the last `window` iterations ("STOP by QUALITY
    /// PLATEAU").
    Plateau,
    /// The line search failed.
    LineSearch(LineSearchFailure),
    /// The trust radius collapsed (reported with the "rounding errors" message of Table A.2).
    TrustRadius,
    /// Algorithm B's planarity stop: every penalized face is planar to the requested
    /// tolerance, so the continuation ended early (not in Table A.2; spelled like its
    /// messages, "Convex grid, STOP by PLANARITY condition").
    Planar,
}

impl StopReason {
    /// `true` for the ideal endings (FTOL, GTOL, the window and plateau tests of
    /// [`StopRules`](crate::solver::StopRules), and the planarity stop of Algorithm B).
    pub fn converged(self) -> bool {
        matches!(
            self,
            StopReason::Ftol
                | StopReason::Gtol
                | StopReason::Planar
                | StopReason::WindowFtol
                | StopReason::Plateau
        )
    }

    /// `true` when the run was interrupted from outside: by the observer or by the time
    /// limit. Drivers stop their continuation on it.
    pub fn interrupted(self) -> bool {
        matches!(self, StopReason::User | StopReason::TimeLimit)
    }
}

/// A status of an optimization run in the words of UNAMALLA 2.0 (Table A.2, typos kept).
/// Non-convex FTOL/GTOL endings, which the table does not list, are spelled like the listed
/// ones ("Non convex grid, STOP by FTOL condition").
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Status {
    /// "The initial grid is convex, optimizing".
    InitialConvex,
    /// "The initial grid is non convex, optimizing".
    InitialNonConvex,
    /// "Convex grid, the initial grid is good" (the homotopy phase had nothing to do).
    InitialGood,
    /// "Convex grid, the homotopic step is ok" (the adaptive phase reached its target).
    HomotopicOk,
    /// A solver run ended; `convex` is the verdict on the final mesh.
    Stopped {
        /// Why the run ended.
        reason: StopReason,
        /// Whether the final mesh is convex (every element with a free vertex positive).
        convex: bool,
    },
}

impl Status {
    /// The final verdict on convexity, if the status carries one.
    pub fn convex(&self) -> Option<bool> {
        match self {
            Status::Stopped { convex, .. } => Some(*convex),
            Status::InitialGood | Status::HomotopicOk | Status::InitialConvex => Some(true),
            Status::InitialNonConvex => Some(false),
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match *self {
            Status::InitialConvex => "The initial grid is convex, optimizing",
            Status::InitialNonConvex => "The initial grid is non convex, optimizing",
            Status::InitialGood => "Convex grid, the initial grid is good",
            Status::HomotopicOk => "Convex grid, the homotopic step is ok",
            Status::Stopped { reason, convex } => {
                use LineSearchFailure as L;
                match (reason, convex) {
                    (StopReason::Ftol, true) => "Convex grid, STOP by FTOL condition",
                    (StopReason::Ftol, false) => "Non convex grid, STOP by FTOL condition",
                    (StopReason::Gtol, true) => "Convex grid, STOP by GTOL condition",
                    (StopReason::Gtol, false) => "Non convex grid, STOP by GTOL condition",
                    (StopReason::MaxIter, true) => "Convex grid, STOP by MAXITER condition",
                    (StopReason::MaxIter, false) => "Non convex grid, STOP by MAXITER condition",
                    (StopReason::Planar, true) => "Convex grid, STOP by PLANARITY condition",
                    (StopReason::Planar, false) => "Non convex grid, STOP by PLANARITY condition",
                    (StopReason::User, true) => "Convex grid, STOP by user",
                    (StopReason::User, false) => "Non convex grid, STOP by user",
                    (StopReason::TimeLimit, true) => "Convex grid, STOP by TIME LIMIT",
                    (StopReason::TimeLimit, false) => "Non convex grid, STOP by TIME LIMIT",
                    (StopReason::WindowFtol, true) => "Convex grid, STOP by WINDOW FTOL condition",
                    (StopReason::WindowFtol, false) => {
                        "Non convex grid, STOP by WINDOW FTOL condition"
                    }
                    (StopReason::Plateau, true) => "Convex grid, STOP by QUALITY PLATEAU",
                    (StopReason::Plateau, false) => "Non convex grid, STOP by QUALITY PLATEAU",
                    (StopReason::LineSearch(L::Xtol), _) => {
                        "The interval of uncertainty is at mos xtol"
                    }
                    (StopReason::LineSearch(L::Rounding) | StopReason::TrustRadius, true) => {
                        "Convex grid, Rounding errors prevent furthet progress"
                    }
                    (StopReason::LineSearch(L::Rounding) | StopReason::TrustRadius, false) => {
                        "Non convex grid, Rounding errors prevent further progress"
                    }
                    (StopReason::LineSearch(L::StpMin), true) => {
                        "Convex grid, the step is at the lower bound STPMIN"
                    }
                    (StopReason::LineSearch(L::StpMin), false) => {
                        "Non convex grid, the step is at the lower bound STPMIN"
                    }
                    (StopReason::LineSearch(L::StpMax), true) => {
                        "Convex grid, the step is at the upper bound STPMAX"
                    }
                    (StopReason::LineSearch(L::StpMax), false) => {
                        "Non convex grid, the step is at the upper bound STPMAX"
                    }
                    (StopReason::LineSearch(L::MaxFev), true) => {
                        "Convex grid, the number calls of FCN has reached"
                    }
                    (StopReason::LineSearch(L::MaxFev), false) => {
                        "Non convex grid, the number calls of FCN has reached"
                    }
                }
            }
        };
        f.write_str(s)
    }
}
