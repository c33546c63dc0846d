//! Progress: a bar with an ETA on a terminal; without one (pipes, CI logs, batch jobs) plain
//! lines. Either way a long command is never silent: while any stage or bar of it is active, a
//! line comes at least every [`line_interval`] (`lines`), naming the stage it is in, even
//! while one long case runs. [`bar`] counts a stage's cases; [`stage`] names a stretch of work
//! without a count (a reference solve, the timing runs, a whole command); [`ProgressObserver`]
//! shows a run's steps.

mod lines;

pub use lines::{line_interval, stage, Stage};

use super::energy::EnergyRecord;
use super::observer::Observer;
use crate::error::Result;
use crate::model::State;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Most steps between updates of the bar (updates are cheap, but not free on million-step
/// runs).
const STRIDE: u64 = 256;

/// Least time between updates below which the stride between them doubles: a run of slow
/// steps updates at every step, a run of fast ones every [`STRIDE`] steps.
const SETTLE: Duration = Duration::from_millis(20);

/// How often a bar drawn on a terminal redraws itself when nothing moves (its elapsed time
/// and ETA keep counting while one long case runs).
const DRAWN_TICK: Duration = Duration::from_millis(500);

/// Shows how many of a run's steps are done.
#[derive(Debug)]
pub struct ProgressObserver {
    bar: ProgressBar,
    /// Steps between updates, 1 to [`STRIDE`]: doubled while updates come faster than
    /// [`SETTLE`], halved while they come slower.
    stride: u64,
    /// The step of the next update.
    next: u64,
    /// When the bar was last updated.
    last: Instant,
}

impl ProgressObserver {
    /// A bar over `steps` steps labelled `msg`, shown only if `enabled` and stderr is a terminal.
    pub fn new(steps: u64, msg: &str, enabled: bool) -> Self {
        ProgressObserver {
            bar: bar(steps, msg, enabled),
            stride: 1,
            next: 1,
            last: Instant::now(),
        }
    }
}

impl Observer for ProgressObserver {
    fn observe(&mut self, step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        if step >= self.next {
            self.bar.set_position(step);
            let now = Instant::now();
            if now.duration_since(self.last) < SETTLE {
                self.stride = (self.stride * 2).min(STRIDE);
            } else {
                self.stride = (self.stride / 2).max(1);
            }
            self.last = now;
            self.next = step + self.stride;
        }
        Ok(())
    }
    fn finish(&mut self, _last_step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        self.bar.finish_and_clear();
        Ok(())
    }
}

/// A bar of `len` steps labelled `msg`: drawn when `enabled` and stderr is a terminal, reported
/// as plain lines (`lines`) when `enabled` and it is not, silent when not `enabled` (a
/// command's inner loops, whose command shows its own progress).
pub fn bar(len: u64, msg: &str, enabled: bool) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
    if !enabled {
        return pb;
    }
    let drawn = std::io::stderr().is_terminal();
    if drawn {
        pb.set_draw_target(ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template(
            "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})",
        ) {
            pb.set_style(style);
        }
        pb.set_message(msg.to_string());
        pb.enable_steady_tick(DRAWN_TICK);
    }
    lines::watch(&pb, msg, drawn);
    pb
}
