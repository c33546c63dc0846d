//! Measuring the speed–accuracy trade: references, metrics, convergence, stability, advice.

pub mod advise;
pub mod case;
pub mod command;
pub mod compare;
pub mod contacts;
pub mod dop853;
pub mod fit;
pub mod grid;
pub mod metrics;
pub mod modes;
pub mod progress;
pub mod reference;
pub mod stability;
pub mod sweep;
pub mod trace;
