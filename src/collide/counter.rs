//! Counts of parry work done on the current thread: a test can show that a scene without
//! obstacles builds nothing and queries nothing. Thread-local, so parallel runs do not mix.

use std::cell::Cell;

thread_local! {
    static QUERIES: Cell<u64> = const { Cell::new(0) };
    static BUILDS: Cell<u64> = const { Cell::new(0) };
}

/// Narrow-phase parry queries (point projections, ray casts) made on this thread so far.
pub fn query_count() -> u64 {
    QUERIES.with(|q| q.get())
}

/// Obstacle sets (parry shapes + broad phase) built on this thread so far.
pub fn build_count() -> u64 {
    BUILDS.with(|b| b.get())
}

pub(crate) fn count_query() {
    QUERIES.with(|q| q.set(q.get() + 1));
}

pub(crate) fn count_build() {
    BUILDS.with(|b| b.set(b.get() + 1));
}
