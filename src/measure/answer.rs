//! A scene's answer, in two forms a programmer asks for: the method and step to use when the
//! step is free, and the method and substeps per frame at a game's frame rate.
//!
//! Both come from the study's own documents (one computation per fact): the free step is the
//! advice's pick ([`super::advise`]); the game rate is the cheapest row of the frame-rate
//! table ([`super::framerate`]) at the scene's rate ([`GAME_HZ`] unless `[run] hz` says
//! otherwise) that meets the bound, ranked by the advice's cost rule
//! ([`super::advise::cost::rank`]). Each says by which metric and tolerance it was judged.
//!
//! Where no method meets the bound, the answer says what *was* verified and answers on that,
//! labelled `meets: false`: the most accurate run that stayed stable (the compared step for
//! the free step, one substep per frame for the game rate), with its error by the same metric.

use super::advise::Advice;
use super::compare::CompareResult;
use super::framerate::Framerate;
use super::tolerance::Metric;
use crate::error::Result;
use crate::method::{Order, Registry};
use serde::{Deserialize, Serialize};

/// The game frame rate an answer is given at unless the scene names one (Hz).
pub const GAME_HZ: f64 = 60.0;

/// The answer when the step is free.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FreeStep {
    /// Method (null when nothing ran stably).
    #[serde(alias = "integrator")]
    pub method: Option<String>,
    /// Step (s).
    pub dt: Option<f64>,
    /// The metric that judged it.
    pub metric: Metric,
    /// The bound its error is held to, in the metric's unit.
    pub tolerance: f64,
    /// The position tolerance (m) behind the bound.
    pub position_tolerance: f64,
    /// Its error by the metric (verified by running it).
    pub error: Option<f64>,
    /// Modelled seconds per simulated second ([`crate::run::cost`]).
    pub modelled_seconds_per_simulated_second: Option<f64>,
    /// Median wall time per simulated second (s/s), where measured.
    pub wall_seconds_per_simulated_second: Option<f64>,
    /// True when the error is within the bound; false for a labelled fallback.
    pub meets: bool,
    /// What was verified, in words.
    pub verified: String,
}

/// The answer at a game's frame rate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GameRate {
    /// Frame rate (Hz).
    pub hz: f64,
    /// Method (null when none ran stably at this rate).
    #[serde(alias = "integrator")]
    pub method: Option<String>,
    /// Substeps per frame.
    pub substeps: Option<u64>,
    /// The metric that judged it.
    pub metric: Metric,
    /// The bound its error is held to, in the metric's unit.
    pub tolerance: f64,
    /// The position tolerance (m) behind the bound.
    pub position_tolerance: f64,
    /// Its error by the metric.
    pub error: Option<f64>,
    /// Modelled seconds per frame ([`crate::run::cost`]).
    pub modelled_seconds_per_frame: Option<f64>,
    /// Median wall time per frame (s), where measured.
    pub wall_seconds_per_frame: Option<f64>,
    /// True when the error is within the bound; false for a labelled fallback.
    pub meets: bool,
    /// What was verified, in words.
    pub verified: String,
}

/// Both answers of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Answer {
    /// When the step is free.
    pub free_step: FreeStep,
    /// At the game's frame rate.
    pub game_rate: GameRate,
    /// The best engine (Rapier) at the game's frame rate beside the answer; `None` where no
    /// engine ran at that rate.
    #[serde(default)]
    pub engine: Option<super::engine_fare::EngineFare>,
}

impl FreeStep {
    /// No method: judged by `metric` against `bound` (position tolerance `position` m), with
    /// `why` saying what was verified instead.
    fn none(metric: Metric, bound: f64, position: f64, why: String) -> Self {
        FreeStep {
            method: None,
            dt: None,
            metric,
            tolerance: bound,
            position_tolerance: position,
            error: None,
            modelled_seconds_per_simulated_second: None,
            wall_seconds_per_simulated_second: None,
            meets: false,
            verified: why,
        }
    }
}

impl GameRate {
    /// No method at `hz`: judged by `metric` against `bound` (position tolerance `position`
    /// m), with `why` saying what was verified instead.
    fn none(hz: f64, metric: Metric, bound: f64, position: f64, why: String) -> Self {
        GameRate {
            hz,
            method: None,
            substeps: None,
            metric,
            tolerance: bound,
            position_tolerance: position,
            error: None,
            modelled_seconds_per_frame: None,
            wall_seconds_per_frame: None,
            meets: false,
            verified: why,
        }
    }
}

fn sig(v: f64) -> String {
    crate::error::significant(v, 3)
}

/// The free-step answer from the advice, or the labelled fallback from the comparison.
pub fn free_step(registry: &Registry, advice: &Advice, compared: &CompareResult) -> FreeStep {
    let metric = advice.judged.metric;
    let base = FreeStep::none(
        metric,
        advice.judged.tolerance,
        advice.judged.position_tolerance.value,
        String::new(),
    );
    if let (Some(m), Some(dt)) = (&advice.method, advice.dt) {
        return FreeStep {
            method: Some(m.clone()),
            dt: Some(dt),
            error: advice.verified_error,
            modelled_seconds_per_simulated_second: advice.modelled_per_second,
            wall_seconds_per_simulated_second: advice.wall_per_second,
            meets: true,
            verified: format!(
                "{} ≤ {} {}, verified by running it",
                metric.name(),
                sig(advice.judged.tolerance),
                metric.unit()
            ),
            ..base
        };
    }
    let finest = advice.grid.first().copied().unwrap_or(f64::NAN);
    let best = compared
        .entries
        .iter()
        .filter_map(|e| e.result.as_ref())
        .filter(|r| {
            registry
                .info(&r.method)
                .is_ok_and(|i| i.order != Order::Exact)
        })
        .filter_map(|r| {
            let m = r.metrics.as_ref()?;
            Some((r, metric.error(m, advice.judged.position_tolerance.value)?))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.method.cmp(&b.0.method)));
    match best {
        Some((r, e)) => FreeStep {
            method: Some(r.method.clone()),
            dt: Some(r.dt),
            error: Some(e),
            modelled_seconds_per_simulated_second: Some(r.modelled_seconds / (r.dt * r.steps as f64)),
            wall_seconds_per_simulated_second: Some(r.wall_seconds / (r.dt * r.steps as f64)),
            verified: format!(
                "stable only: no method met {} ≤ {} {} on steps down to {} s; the most accurate stable run at the scene's step is shown",
                metric.name(),
                sig(advice.judged.tolerance),
                metric.unit(),
                sig(finest)
            ),
            ..base
        },
        None => FreeStep {
            verified: "no method ran stably at the scene's step; see the stability limits".into(),
            ..base
        },
    }
}

/// The game-rate answer at `hz` from the frame-rate table: the cheapest row meeting the bound
/// by the advice's cost rule, or the labelled fallback (the most accurate stable run at one
/// substep). `left_out` names the methods the table did not run (for time), which the
/// fallback's words must not count among those that failed.
pub fn game_rate(fr: &Framerate, hz: f64, scenario: &str, left_out: &[String]) -> Result<GameRate> {
    let metric = fr.judged.metric;
    let base = GameRate::none(
        hz,
        metric,
        fr.judged.tolerance,
        fr.judged.position_tolerance.value,
        String::new(),
    );
    if let Some((e, f, _)) = super::framerate::best_at(fr, hz, scenario)? {
        return Ok(GameRate {
            method: Some(e.method.clone()),
            substeps: Some(f.substeps),
            error: f.error,
            modelled_seconds_per_frame: f.modelled_seconds_per_frame,
            wall_seconds_per_frame: f.wall_seconds_per_frame,
            meets: true,
            verified: format!(
                "{} ≤ {} {} at {} substep(s) per frame, the cheapest that does",
                metric.name(),
                sig(fr.judged.tolerance),
                metric.unit(),
                f.substeps
            ),
            ..base
        });
    }
    let at: Vec<_> = fr.entries.iter().filter(|e| e.hz == hz).collect();
    let best = at
        .iter()
        .filter_map(|e| Some((e, e.one_substep.error?)))
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.method.cmp(&b.0.method)));
    let untried = if left_out.is_empty() {
        String::new()
    } else {
        format!(
            " (not run here, for time: {}; `springlab framerate` runs them)",
            left_out.join(", ")
        )
    };
    Ok(match best {
        Some((e, err)) => GameRate {
            method: Some(e.method.clone()),
            substeps: Some(1),
            error: Some(err),
            modelled_seconds_per_frame: e.one_substep.modelled_seconds_per_frame,
            wall_seconds_per_frame: e.one_substep.wall_seconds_per_frame,
            verified: format!(
                "stable only: no method tried met {} ≤ {} {} up to {} substeps per frame{untried}; the most accurate stable run at one substep is shown",
                metric.name(),
                sig(fr.judged.tolerance),
                metric.unit(),
                fr.max_substeps
            ),
            ..base
        },
        None => GameRate {
            verified: format!("no method ran stably at {} Hz", sig(hz)),
            ..base
        },
    })
}

/// The study's documents an answer reads: the comparison, the advice and the frame-rate
/// table, each missing one with why, and the methods the table left out for time. Bundled
/// because a study hands them over together.
#[derive(Debug, Clone, Copy)]
pub struct Measured<'a> {
    /// The comparison at the scene's step.
    pub compared: &'a CompareResult,
    /// The advice, when measured.
    pub advice: Option<&'a Advice>,
    /// Why there is no advice.
    pub advice_note: Option<&'a str>,
    /// The frame-rate table, when measured.
    pub framerate: Option<&'a Framerate>,
    /// Why there is no frame-rate table.
    pub framerate_note: Option<&'a str>,
    /// The methods the frame-rate table left out for time.
    pub framerate_left_out: &'a [String],
}

/// The answer of a study's documents `measured`; `hz` the scene's game rate. Without an
/// advice or a frame-rate table the missing half says why (`advice_note`, `framerate_note`).
pub fn answer(
    registry: &Registry,
    measured: &Measured<'_>,
    hz: f64,
    scenario: &str,
) -> Result<Answer> {
    let Measured {
        compared,
        advice,
        advice_note,
        framerate,
        framerate_note,
        framerate_left_out,
    } = *measured;
    let position = compared.position_tolerance.value;
    let free_step = match advice {
        Some(a) => free_step(registry, a, compared),
        None => FreeStep::none(
            Metric::Position,
            position,
            position,
            advice_note.unwrap_or("no advice was measured").into(),
        ),
    };
    let game_rate = match framerate {
        Some(f) => game_rate(f, hz, scenario, framerate_left_out)?,
        None => GameRate::none(
            hz,
            Metric::Position,
            position,
            position,
            framerate_note
                .unwrap_or("no frame-rate table was measured")
                .into(),
        ),
    };
    let engine = framerate.and_then(|f| {
        super::engine_fare::engine_fare(
            &super::engine_fare::game_points(f, hz, registry),
            &game_rate,
        )
    });
    Ok(Answer {
        free_step,
        game_rate,
        engine,
    })
}
