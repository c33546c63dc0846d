//! A progress bar over a run's steps, as an [`Observer`]: drawn with an ETA on a terminal,
//! silent otherwise (see [`crate::measure::progress::bar`]).

use super::energy::EnergyRecord;
use super::observer::Observer;
use crate::error::Result;
use crate::model::State;
use indicatif::ProgressBar;

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
            bar: crate::measure::progress::bar(steps, msg, enabled),
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
