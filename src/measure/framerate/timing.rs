//! Timing the frame-rate table's runs, like advice's candidates: on one thread after every
//! accuracy run, interleaved round-robin, each repetition a fresh stepper.

use super::rows::{FrameRun, RateEntry};
use crate::error::Result;
use crate::measure::case::{time_interleaved, CaseSettings, TimedRun, TimingRule};
use crate::model::{State, System};

/// The timing rule of the table's runs: at least 3 runs and 0.02 s in total; a run whose
/// total passes 0.2 s stops after 1; never more than 1000 runs.
pub const FRAMERATE_TIMING: TimingRule = TimingRule {
    min_repetitions: 3,
    min_total_seconds: 0.02,
    cap_seconds: 0.2,
    cap_repetitions: 1,
    max_repetitions: 1000,
};

/// Times every stable run of the table once per repetition rule, interleaved on this thread
/// after all accuracy runs, and fills in its wall time per frame.
pub(super) fn time_entries(
    sys: &System,
    s0: &State,
    entries: &mut [RateEntry],
    set: &CaseSettings,
    rule: &TimingRule,
) -> Result<()> {
    let run_of = |e: &RateEntry, r: &FrameRun| TimedRun {
        method: e.method.clone(),
        dt: e.frame_dt,
        steps: e.frames,
        substeps: Some(r.substeps),
    };
    let mut runs: Vec<TimedRun> = Vec::new();
    for e in entries.iter() {
        for r in std::iter::once(&e.one_substep).chain(e.fewest.as_ref()) {
            let t = run_of(e, r);
            if r.status.is_ok() && !runs.contains(&t) {
                runs.push(t);
            }
        }
    }
    let timings = time_interleaved(sys, s0, &runs, set, rule)?;
    for e in entries.iter_mut() {
        let frames = e.frames as f64;
        let (one, fewest) = (&mut e.one_substep, &mut e.fewest);
        for r in std::iter::once(one).chain(fewest.as_mut()) {
            let t = TimedRun {
                method: e.method.clone(),
                dt: e.frame_dt,
                steps: e.frames,
                substeps: Some(r.substeps),
            };
            if let Some(k) = runs.iter().position(|x| *x == t) {
                r.wall_seconds_per_frame = Some(timings[k].median_seconds / frames);
                r.timing = Some(timings[k].clone());
            }
        }
    }
    Ok(())
}
