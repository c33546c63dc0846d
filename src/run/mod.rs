//! The runner: owns the loop, the impulses, the energy accounts, blow-up detection and timing.

mod energy;
mod observer;
mod runner;

pub use energy::{energy_scale, EnergyRecord};
pub use observer::{NoObserver, Observer};
pub use runner::{run, RunOutcome, RunPlan, Status, DEFAULT_BLOWUP_FACTOR};
