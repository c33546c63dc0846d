//! The `[expect]` table of an advice at a game's frame rate: the cheapest method there and its
//! substeps per frame, held to what its verified run achieved, for `advise --write-expect` on a
//! scene that has a frame rate (its `[run] hz`, or `--hz`). Without one, the free step's table
//! ([`super::advise::expect_table`]) is written.

use super::advise::Advice;
use crate::scenario::file::ExpectSpec;

/// The table holding a scene to the advice's answer at `hz`: the best method of the frame view
/// at that rate and its substeps, stable, the position tolerance as `max_position_error`, its
/// substepped run's strain plus the relative tolerance as `max_strain` and twice its energy
/// drift rate as `max_energy_drift_rate` (as the free step's table). `None` when the view has no
/// such rate or no method meets the bound there.
pub fn game_rate_table(adv: &Advice, hz: f64) -> Option<ExpectSpec> {
    let rate = adv.frame_rates.iter().find(|r| r.fps == hz)?;
    let best = rate.best.as_ref()?;
    let entry = rate.entries.iter().find(|e| &e.method == best)?;
    let relative = adv.position_tolerance.value / adv.reference.motion_scale;
    Some(ExpectSpec {
        method: entry.method.clone(),
        hz: Some(hz),
        dt: None,
        substeps: Some(entry.substeps as i64),
        stable: Some(true),
        max_position_error: Some(adv.position_tolerance.value),
        max_strain: entry.strain_max.map(|s| s + relative),
        max_energy_drift_rate: entry.energy_drift_rate.map(|r| 2.0 * r.abs()),
    })
}
