//! Writing results: atomic files, transactions that replace several outputs together, the
//! per-run CSV writers and the run summary, and the lock that keeps one writer per folder.

mod atomic;
pub mod digest;
pub mod interrupt;
mod lock;
mod run_files;
mod run_size;
pub mod timing;
mod transaction;

pub use atomic::{write_atomic, AtomicFile};
pub use lock::{lock_dir, lock_dir_shared, DirLock};
pub use run_files::{
    every_within, human_bytes, projected_run_bytes, write_run, written_frames, RunFiles,
    RunSummary, SIZE_WARNING_BYTES,
};
pub use run_size::{size_guard, SizeAsk};
pub use timing::{read_document, write_document, TIMING_FILE};
pub use transaction::{published_path, recover, Recovery, Transaction};
