//! One adaptive solve per scene and horizon, shared by every grid that asks for it.
//!
//! The main DOP853 solve and its two companions ([`super::uncertainty`]) take the same steps
//! whatever times they are sampled at, so each is solved once with its dense output kept
//! ([`super::dense`]) and every later request for the same system, initial state, horizon and
//! tolerance samples the kept solves: a study's compare, sweep, advice and frame-rate grids,
//! and the scene grid its ensemble is made on, pay for one solve. The kept solve is the same
//! bits whichever request (or thread) made it, because nothing in it depends on the request.
//!
//! The cache lives in memory for the process, keyed by the system's and initial state's full
//! description, the horizon and the tolerance. It holds at most [`CACHE_BYTES`], dropping the
//! oldest solves first (a dropped solve is solved again, to the same bits). A solve whose
//! dense output would pass [`TRACK_BYTES`] is not kept; the cache remembers that, and such a
//! scene's references solve on their grids as before.

use super::adaptive::{solve, SolveOut, SolveSpec};
use super::dense::DenseTrack;
use super::tracked::Tracked;
use super::uncertainty::{perturbed, COMPANION_WORK_FACTOR, LOOSE_FACTOR};
use crate::error::Result;
use crate::model::{State, System};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// Most bytes of dense output one kept solve may hold: enough for the shipped 32×32 cloth
/// (about 400 MB over its 1843 steps), whose every grid would otherwise solve again.
pub const TRACK_BYTES: usize = 1 << 30;

/// Most bytes the cache holds over all kept solves.
pub const CACHE_BYTES: usize = 3 << 30;

/// A kept solve: the main solve and its companions, each sampleable anywhere.
#[derive(Debug)]
pub(super) struct Solution {
    /// Which solve this is (distinct per solve in a process; for tests of the sharing).
    pub id: u64,
    /// The main solve's dense output.
    pub main: DenseTrack,
    /// The looser companion's, or None when it was abandoned over its work budget.
    pub loose: Option<DenseTrack>,
    /// The perturbed companion's, or None when it was abandoned over its work budget.
    pub perturbed: Option<DenseTrack>,
    /// What the main solve did besides sampling.
    pub out: SolveOut,
}

impl Solution {
    fn bytes(&self) -> usize {
        self.main.bytes()
            + self.loose.as_ref().map_or(0, DenseTrack::bytes)
            + self.perturbed.as_ref().map_or(0, DenseTrack::bytes)
    }
}

/// A cache entry: the kept solve, or None when it was too big to keep.
type Entry = (String, Option<Arc<Solution>>);

static CACHE: Mutex<Vec<Entry>> = Mutex::new(Vec::new());
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// A fresh solve id, distinct from every other kept solve's (adaptive or fine-step) in the
/// process.
pub(super) fn new_id() -> u64 {
    NEXT_ID.fetch_add(1, Ordering::Relaxed)
}

/// The kept solve of `sys` from `s0` to `horizon` at tolerance `rtol` (tracking `tracked`),
/// solving it when no request has yet; None when its dense output does not fit
/// [`TRACK_BYTES`] (the caller solves on its grids instead).
pub(super) fn shared(
    sys: &System,
    s0: &State,
    horizon: f64,
    rtol: f64,
    tracked: Option<Tracked>,
    limit: Option<super::cost::StepLimit>,
) -> Result<Option<Arc<Solution>>> {
    let key = format!("{sys:?}|{s0:?}|{horizon:?}|{rtol:?}|{tracked:?}");
    if let Some((_, kept)) = lock().iter().find(|(k, _)| *k == key) {
        return Ok(kept.clone());
    }
    // Solved outside the lock: two threads asking at once both solve, to the same bits, and
    // the first to finish is kept.
    let made = solve_kept(sys, s0, horizon, rtol, tracked, limit)?.map(Arc::new);
    let mut cache = lock();
    if let Some((_, kept)) = cache.iter().find(|(k, _)| *k == key) {
        return Ok(kept.clone());
    }
    let size = made.as_ref().map_or(0, |s| s.bytes());
    let mut held: usize = cache
        .iter()
        .filter_map(|(_, s)| s.as_ref().map(|s| s.bytes()))
        .sum();
    while held + size > CACHE_BYTES && !cache.is_empty() {
        let (_, old) = cache.remove(0);
        held -= old.map_or(0, |s| s.bytes());
    }
    cache.push((key, made.clone()));
    Ok(made)
}

fn lock() -> std::sync::MutexGuard<'static, Vec<Entry>> {
    CACHE.lock().unwrap_or_else(|e| e.into_inner())
}

fn solve_kept(
    sys: &System,
    s0: &State,
    horizon: f64,
    rtol: f64,
    tracked: Option<Tracked>,
    limit: Option<super::cost::StepLimit>,
) -> Result<Option<Solution>> {
    let n = sys.len();
    // One solve from `start` recording its dense output: the main solve and each companion.
    let tracked_solve = |start: &State, tol: f64, track_v: Option<Tracked>, steps: Option<u64>| {
        let y = super::rhs::pack(&start.x, &start.v);
        let mut track = DenseTrack::new(n, &y, TRACK_BYTES);
        let spec = SolveSpec {
            sys,
            s0: start,
            times: &[],
            horizon,
            rtol: tol,
            tracked: track_v,
            max_steps: steps,
        };
        let done = solve(&spec, &mut |_, _| {}, Some(&mut track))?;
        Ok::<_, crate::error::Error>((done, track))
    };
    let (out, main) = tracked_solve(s0, rtol, tracked, limit.map(|l| l.steps))?;
    if let (None, true, Some(l)) = (&out, main.complete(), limit) {
        return Err(l.error(horizon));
    }
    let Some(out) = out.filter(|_| main.complete()) else {
        return Ok(None);
    };
    let max_steps = COMPANION_WORK_FACTOR * (out.stats.steps + out.stats.rejected).max(100);
    let sp = perturbed(sys, s0);
    let companion = |start: &State, tol: f64| -> Result<Option<Option<DenseTrack>>> {
        let (done, track) = tracked_solve(start, tol, None, Some(max_steps))?;
        if !track.complete() {
            return Ok(None);
        }
        Ok(Some(done.map(|_| track)))
    };
    let (loose, pert) = rayon::join(
        || companion(s0, rtol * LOOSE_FACTOR),
        || companion(&sp, rtol),
    );
    let (Some(loose), Some(perturbed)) = (loose?, pert?) else {
        return Ok(None);
    };
    Ok(Some(Solution {
        id: new_id(),
        main,
        loose,
        perturbed,
        out,
    }))
}
