//! The runner: owns the loop, the impulses, the energy accounts, blow-up detection and timing.

pub mod cost;
mod energy;
mod frame_loop;
mod observer;
pub mod progress;
pub mod runaway;
mod runner;
mod scale;
pub mod verdict;

pub use cost::{CostModel, Work};
pub use energy::EnergyRecord;
pub use observer::{NoObserver, Observer};
pub use progress::{bar as progress_bar, stage as progress_stage, ProgressObserver, Stage};
pub use runner::{run, run_with, RunOutcome, RunPlan, RunStatus, Status};
pub use scale::{characteristic_length, energy_scale};
pub use verdict::DEFAULT_BLOWUP_FACTOR;
