//! Writing results: atomic files, the per-run CSV writers and the run summary, and the lock
//! that keeps one writer per output folder.

mod atomic;
mod lock;
mod run_files;

pub use atomic::{write_atomic, AtomicFile, FreshDir};
pub use lock::{lock_dir, lock_dir_shared, DirLock};
pub use run_files::{
    every_within, human_bytes, projected_run_bytes, size_notice, write_run, written_frames,
    RunFiles, RunSummary, SIZE_WARNING_BYTES,
};
