//! Measuring the speed–accuracy trade: references, metrics, convergence, stability, advice.

pub mod advise;
pub mod answer;
pub mod apexes;
pub mod case;
pub mod command;
pub mod common;
pub mod compare;
pub mod contacts;
pub mod decimated;
mod dop853;
pub mod engine_fare;
pub mod expect;
pub mod expect_answer;
mod fit;
pub mod framerate;
pub mod grid;
mod kept;
pub mod metric_table;
pub(crate) mod metrics;
mod modes;
pub mod observables;
pub mod probe;
pub mod reference;
pub mod small_steps;
pub mod small_steps_budget;
pub mod stability;
pub mod statistics;
pub mod study;
pub mod sweep;
pub mod tolerance;
mod trace;

pub use common::Common;
pub use metrics::{strain_max, Metrics, Quality, QualityObserver};
