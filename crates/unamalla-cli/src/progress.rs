//! Progress of `unamalla mesh` on stderr: a real progress bar (`indicatif`) over the pipeline's
//! seven stages, with the elapsed time, an ETA and the smoother's current line as its message,
//! when stderr is a terminal; plain lines otherwise (one per stage, and the smoother's line at
//! most every 2 s), so a redirected log holds no carriage returns or escape codes.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use unamalla_core::optim::{Control, Monitor, Observer, ProgressObserver};
use unamalla_core::pipeline::Stage;

/// The number of pipeline stages ([`Stage`]).
const STAGES: u64 = 8;

fn stage_index(s: Stage) -> u64 {
    match s {
        Stage::Simplify => 0,
        Stage::Decompose => 1,
        Stage::Counts => 2,
        Stage::Tfi => 3,
        Stage::Merge => 4,
        Stage::Smooth => 5,
        Stage::Shape => 6,
        Stage::Report => 7,
    }
}

/// Progress display for one run.
#[derive(Clone)]
pub enum Progress {
    /// A terminal: the bar.
    Bar(ProgressBar),
    /// Not a terminal: plain lines.
    Plain,
}

impl Progress {
    /// The bar when stderr is a terminal, else plain lines.
    pub fn for_stderr() -> Self {
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(Some(STAGES), ProgressDrawTarget::stderr());
            let style = ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:28} stage {pos}/{len} (ETA {eta}) {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            bar.enable_steady_tick(Duration::from_millis(200));
            Self::Bar(bar)
        } else {
            Self::Plain
        }
    }

    /// A stage starts.
    pub fn stage(&self, s: Stage, msg: &str) {
        match self {
            Self::Bar(b) => {
                b.set_position(stage_index(s));
                b.set_message(msg.to_string());
            }
            Self::Plain => eprintln!("· {msg}"),
        }
    }

    /// The smoother's observer.
    pub fn observer(&self) -> SmoothProgress {
        SmoothProgress {
            progress: self.clone(),
            last: None,
        }
    }

    /// Ends the display (clears the bar).
    pub fn finish(&self) {
        if let Self::Bar(b) = self {
            b.finish_and_clear();
        }
    }
}

/// Shows the smoother's state: in the bar's message, or as a plain line every 2 s.
pub struct SmoothProgress {
    progress: Progress,
    last: Option<Instant>,
}

impl Observer for SmoothProgress {
    fn observe(&mut self, m: &Monitor) -> Control {
        let now = Instant::now();
        let every = match self.progress {
            Progress::Bar(_) => Duration::from_millis(200),
            Progress::Plain => Duration::from_secs(2),
        };
        if self.last.is_none_or(|t| now.duration_since(t) >= every) {
            self.last = Some(now);
            match &self.progress {
                Progress::Bar(b) => b.set_message(ProgressObserver::line(m)),
                Progress::Plain => eprintln!("  {}", ProgressObserver::line(m)),
            }
        }
        Control::Continue
    }
}
