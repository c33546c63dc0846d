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
    let rate = adv.frame_rates.iter().find(|r| r.fps == hz)?;
    let best = rate.best.as_ref()?;
    let entry = rate.entries.iter().find(|e| &e.method == best)?;
    let mut spec = super::advise::held_to(
        adv,
        &entry.method,
        entry.strain_max,
        entry.energy_drift_rate,
    );
    spec.hz = Some(hz);
    spec.substeps = Some(entry.substeps as i64);
    Some(spec)
}
