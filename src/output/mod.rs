//! Writing results: atomic files, the per-run CSV writers and the run summary.

mod atomic;
mod run_files;

pub use atomic::{write_atomic, AtomicFile, FreshDir};
pub use run_files::{write_run, RunFiles, RunSummary};
