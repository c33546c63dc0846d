//! The cheapest answer at one frame rate: of the table's rows at that rate whose fewest
//! substeps meet the bound, the one the advice's cost rule ranks first. One rule for every
//! reader of the table (the game-rate answer, advice's frame view, `--write-expect`).

use super::{FrameRun, Framerate, RateEntry};
use crate::error::Result;
use crate::measure::advise::cost::{rank, CostKey, PickedBy};

/// The cheapest row at `hz` that meets the bound, its fewest-substeps run and the rule that
/// ranked it first; `None` when no row at `hz` meets it. `scenario` names the scene in the
/// error a failed cost count raises.
pub fn best_at<'a>(
    fr: &'a Framerate,
    hz: f64,
    scenario: &str,
) -> Result<Option<(&'a RateEntry, &'a FrameRun, Option<PickedBy>)>> {
    let meeting: Vec<(&RateEntry, &FrameRun)> = fr
        .entries
        .iter()
        .filter(|e| e.hz == hz)
        .filter_map(|e| Some((e, e.fewest.as_ref()?)))
        .filter(|(_, f)| f.meets_tolerance && f.modelled_seconds_per_frame.is_some())
        .collect();
    if meeting.is_empty() {
        return Ok(None);
    }
    let keys: Vec<CostKey> = meeting
        .iter()
        .map(|(e, f)| CostKey {
            method: e.method.clone(),
            modelled_per_second: f.modelled_seconds_per_frame.unwrap_or(f64::NAN) * hz,
            force_evals_per_second: f.force_evals_per_frame.map(|x| x * hz),
        })
        .collect();
    let (order, picked_by) = rank(&keys, scenario)?;
    let (e, f) = meeting[order[0]];
    Ok(Some((e, f, picked_by)))
}
