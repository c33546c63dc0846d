//! Progress bars: drawn with an ETA on a terminal only, silent otherwise (pipes, CI, batch
//! jobs). [`bar`] serves every command; [`ProgressObserver`] shows a run's steps.

use super::energy::EnergyRecord;
use super::observer::Observer;
use crate::error::Result;
use crate::model::State;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// Steps between updates of the bar (updates are cheap, but not free on million-step runs).
const STRIDE: u64 = 256;

/// Shows how many of a run's steps are done.
#[derive(Debug)]
pub struct ProgressObserver {
    bar: ProgressBar,
}

impl ProgressObserver {
    /// A bar over `steps` steps labelled `msg`, shown only if `enabled` and stderr is a terminal.
    pub fn new(steps: u64, msg: &str, enabled: bool) -> Self {
        ProgressObserver {
            bar: bar(steps, msg, enabled),
        }
    }
}

impl Observer for ProgressObserver {
    fn observe(&mut self, step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        if step % STRIDE == 0 {
            self.bar.set_position(step);
        }
        Ok(())
    }
    fn finish(&mut self, _last_step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        self.bar.finish_and_clear();
        Ok(())
    }
}

/// A bar of `len` steps labelled `msg`, hidden unless `enabled` and stderr is a terminal.
pub fn bar(len: u64, msg: &str, enabled: bool) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
    if enabled && std::io::stderr().is_terminal() {
        pb.set_draw_target(ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template(
            "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})",
        ) {
            pb.set_style(style);
        }
        pb.set_message(msg.to_string());
    }
    pb
}
