//! What is measured of a run: the metrics and their table, contact metrics, decimated series,
//! traces and the convergence fit. They import `base` and `truth`.

pub mod contacts;
pub mod decimated;
pub(crate) mod fit;
pub mod metric_table;
pub(crate) mod metrics;
pub(crate) mod trace;
