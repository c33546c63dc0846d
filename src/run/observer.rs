//! Observers watch a run without owning it (argmin's pattern): writers and metrics.

use super::energy::EnergyRecord;
use crate::error::Result;
use crate::model::State;

/// Called by the runner at step 0 and after every step (and once at the end).
pub trait Observer {
    /// A new state at `step` (0 = initial) with its energy account.
    fn observe(&mut self, _step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        Ok(())
    }
    /// The run ended (normally or unstable) after `last_step`.
    fn finish(&mut self, _last_step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        Ok(())
    }
    /// True once the observer has seen enough to decide what it was asked (a run that can no
    /// longer meet a tolerance): the runner ends the run after this step, its status unchanged.
    fn seen_enough(&self) -> bool {
        false
    }
}

/// An observer that ignores everything.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoObserver;
impl Observer for NoObserver {}

impl<A: Observer, B: Observer> Observer for (A, B) {
    fn observe(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        self.0.observe(step, s, e)?;
        self.1.observe(step, s, e)
    }
    fn finish(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        self.0.finish(step, s, e)?;
        self.1.finish(step, s, e)
    }
    fn seen_enough(&self) -> bool {
        self.0.seen_enough() || self.1.seen_enough()
    }
}

/// An observer that may be absent (a metric that does not apply to the scene).
impl<T: Observer> Observer for Option<T> {
    fn observe(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        self.as_mut().map_or(Ok(()), |o| o.observe(step, s, e))
    }
    fn finish(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        self.as_mut().map_or(Ok(()), |o| o.finish(step, s, e))
    }
    fn seen_enough(&self) -> bool {
        self.as_ref().is_some_and(|o| o.seen_enough())
    }
}

impl<T: Observer + ?Sized> Observer for &mut T {
    fn observe(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        (**self).observe(step, s, e)
    }
    fn finish(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        (**self).finish(step, s, e)
    }
    fn seen_enough(&self) -> bool {
        (**self).seen_enough()
    }
}
