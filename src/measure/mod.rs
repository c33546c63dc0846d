//! Measuring the speed–accuracy trade: references, metrics, convergence, stability, advice.

pub mod dop853;
