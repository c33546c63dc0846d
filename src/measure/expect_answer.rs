//! The `[expect]` table of an advice at a game's frame rate: the cheapest method there and its
//! substeps per frame, held to what its verified run achieved, for `advise --write-expect` on a
//! scene that has a frame rate (its `[run] hz`, or `--hz`). Without one, the free step's table
//! ([`super::advise::expect_table`]) is written.

use super::advise::Advice;
use crate::scenario::file::ExpectSpec;

/// The table holding a scene to the advice's answer at `hz`: the best method of the frame view
/// at that rate and its substeps, held to its substepped run as the free step's table is
/// ([`super::advise::held_to`]). `None` when the view has no such rate or no method meets the
/// bound there.
pub fn game_rate_table(adv: &Advice, hz: f64) -> Option<ExpectSpec> {
    let best = adv.best_at_rates.iter().find(|r| r.hz == hz)?;
    let method = best.method.as_ref()?;
    let run = adv
        .frame_rates
        .as_ref()?
        .entries
        .iter()
        .find(|e| e.hz == hz && &e.method == method)?
        .fewest
        .as_ref()?;
    let mut spec = super::advise::held_to(adv, method, run.strain_max, run.energy_drift_rate);
    spec.hz = Some(hz);
    spec.substeps = Some(run.substeps as i64);
    Some(spec)
}
