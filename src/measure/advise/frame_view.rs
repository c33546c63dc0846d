//! The game view of advice: `springlab framerate` over the verified candidates at the
//! common frame rates (and the game's own), with each rate's cheapest answer by the one rule
//! every reader of the frame-rate table uses ([`crate::measure::framerate::best_at`]). Advice
//! measures no frame-rate fact of its own: the substeps per frame are the table's search.

use super::config::AdviseConfig;
use super::cost::PickedBy;
use crate::error::Result;
use crate::measure::framerate::{best_at, framerate, Framerate, FramerateConfig, DEFAULT_RATES};
use crate::scenario::Scenario;
use serde::Serialize;

/// The rates of the frame view: the frame-rate table's default rates when `view` is asked,
/// with `game_hz` added where it is not among them; `game_hz` alone without the view.
pub fn rates_of(view: bool, game_hz: Option<f64>) -> Vec<f64> {
    let mut rates: Vec<f64> = if view { DEFAULT_RATES.to_vec() } else { vec![] };
    if let Some(hz) = game_hz.filter(|h| !rates.contains(h)) {
        rates.push(hz);
    }
    rates
}

/// The cheapest answer at one rate of the view.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RateBest {
    /// Frame rate (Hz).
    pub hz: f64,
    /// The cheapest method whose fewest substeps meet the bound (null when none does).
    pub method: Option<String>,
    /// Its substeps per frame.
    pub substeps: Option<u64>,
    /// Which rule of the ranking put it first.
    pub picked_by: Option<PickedBy>,
}

/// The frame view: the frame-rate table of `names` (the verified candidates, cheapest first)
/// over `horizon` s, judged as the advice was asked to judge, with each rate's cheapest
/// answer. `ensemble` is the one the advice judged by, handed on so that the table does not
/// solve it again (the tolerance's decision sets it aside where its grid is not the scene's).
/// The modelled cost ranks, so the table's wall times are each run's own
/// ([`MEASURED_RUN`](crate::measure::case::MEASURED_RUN)): repeating runs to time them
/// would decide nothing and nearly double the advice's time on the shipped cloth. `None`
/// when no rate is asked or no candidate was verified.
pub(super) fn frame_view(
    scene: &Scenario,
    cfg: &AdviseConfig,
    (horizon, ensemble): (f64, Option<crate::measure::statistics::Ensemble>),
    names: Vec<String>,
) -> Result<(Option<Framerate>, Vec<RateBest>)> {
    let rates = rates_of(cfg.frame_rates, cfg.game_hz);
    if rates.is_empty() || names.is_empty() {
        return Ok((None, Vec::new()));
    }
    let fc = FramerateConfig {
        rates: rates.clone(),
        tolerance: cfg.tolerance,
        metric: cfg.metric,
        ensemble,
        duration: Some(horizon),
        timing: crate::measure::case::MEASURED_RUN,
        common: crate::measure::Common {
            methods: names,
            ..cfg.common.clone()
        },
        ..Default::default()
    };
    let table = framerate(scene, &fc)?;
    let best = rates
        .iter()
        .map(|&hz| {
            let b = best_at(&table, hz, &scene.name)?;
            Ok(RateBest {
                hz,
                method: b.map(|(e, _, _)| e.method.clone()),
                substeps: b.map(|(_, f, _)| f.substeps),
                picked_by: b.and_then(|(_, _, p)| p),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((Some(table), best))
}
