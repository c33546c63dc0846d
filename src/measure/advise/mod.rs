//! Timestep advice: the cheapest method and step whose error over a horizon stays within
//! a tolerance, verified by running it, with alternatives and, for games, the frame-rate table
//! of the verified candidates ([`frame_view`]).
//!
//! Method: every candidate runs on a log grid of steps against one reference; for each, the
//! largest grid step below which every step met tolerance / safety is found, refined by
//! log-log interpolation towards the next (failing) step; that step is then run again
//! (against a reference sampled on its own grid) and accepted only when the verified error is
//! within the tolerance, else the last passing grid step is used. Candidates are ranked by
//! modelled seconds per simulated second (the run's counted work, priced: [`crate::run::cost`]),
//! with force evaluations per simulated second beside it and breaking ties ([`cost`]): a Rapier
//! method has no force-evaluation count, and counting them would make it look free. The
//! median wall time of repeated interleaved runs is shown beside it.
//!
//! The work is ordered so the cheap candidates are verified first (`waves`), and a candidate
//! (or a grid step of one) modelled far above the cheapest verified answer is not run
//! ([`screen`]: more than [`SCREEN_FACTOR`] times its cost), named with the figures.
//!
//! Every number in [`Advice`] is reproducible bit for bit, the ranking and the pick included,
//! except the wall times (`wall_per_second`, `timing`).

mod config;
pub mod cost;
pub mod frame_view;
pub mod screen;
mod search;
mod timing;
mod verify;
mod waves;

pub use config::AdviseConfig;
pub use cost::{CostMeasure, PickedBy, ADVICE_TIMING, TIE_BAND};
pub use frame_view::{rates_of, RateBest};
pub use screen::{Basis, Screened, SCREEN_FACTOR, STABILITY_SLACK};
pub use search::unable_reason;
use search::{candidates, Decided};
pub use search::{EXTENSION_FACTOR, EXTENSION_PARTICLE_STEPS, GRID_EXTENSIONS};
use verify::{Answer, Ctx};
pub use waves::FIRST_WAVE;
use waves::{run_waves, settle};

use super::case::{CaseResult, CaseSettings, TimingRule, WallTimes};
use super::sweep::step_grid;
use crate::error::{Error, Result};
use crate::measure::command::DocumentHead;
use crate::measure::tolerance::{Judge, JudgedBy, Metric};
use crate::method::Registry;
use crate::scenario::Scenario;
use cost::{force_evals_per_second, rank, CostKey};
use serde::Serialize;

/// One candidate's recommendation.
#[derive(Debug, Clone, Serialize)]
pub struct Choice {
    /// Method name.
    pub method: String,
    /// Recommended step (s).
    pub dt: f64,
    /// Error predicted for that step from the grid.
    pub predicted_error: f64,
    /// Error measured by running it.
    pub verified_error: f64,
    /// Modelled seconds per simulated second (s/s): what candidates are ranked by.
    pub modelled_per_second: f64,
    /// Median stepping wall time per simulated second (s/s), shown beside it.
    pub wall_per_second: f64,
    /// Force evaluations per simulated second; null for a method without such a count.
    pub cost_per_second: Option<f64>,
    /// Why `cost_per_second` is null.
    pub cost_per_second_reason: Option<String>,
    /// The repeated timing behind `wall_per_second` (wall seconds of the whole run).
    pub timing: WallTimes,
    /// Largest strain of the chosen run ([`crate::measure::Metrics::strain_max`]).
    pub strain_max: Option<f64>,
    /// Slope of the chosen run's energy balance (J/s).
    pub energy_drift_rate: Option<f64>,
}

/// `advice.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Advice {
    /// The command, the scene and the reference.
    #[serde(flatten)]
    pub head: DocumentHead,
    /// What every candidate was judged by.
    #[serde(flatten)]
    pub judged: JudgedBy,
    /// Horizon (s).
    pub horizon: f64,
    /// Safety factor.
    pub safety: f64,
    /// How candidates are costed and ranked.
    pub cost: CostMeasure,
    /// Which rule of the ranking made the pick (None when there is no pick).
    pub picked_by: Option<PickedBy>,
    /// The pick (None when nothing meets the tolerance on the grid).
    pub method: Option<String>,
    /// Its step (s).
    pub dt: Option<f64>,
    /// Its predicted error.
    pub predicted_error: Option<f64>,
    /// Its verified error.
    pub verified_error: Option<f64>,
    /// Its modelled seconds per simulated second (s/s).
    pub modelled_per_second: Option<f64>,
    /// Its median wall time per simulated second (s/s).
    pub wall_per_second: Option<f64>,
    /// Its force evaluations per simulated second (null without a pick or without a count).
    pub cost_per_second: Option<f64>,
    /// Why `cost_per_second` is null for a pick.
    pub cost_per_second_reason: Option<String>,
    /// Every candidate meeting the tolerance, cheapest first by [`cost::rank`] (the pick
    /// included).
    pub alternatives: Vec<Choice>,
    /// Candidates that cannot meet the tolerance on the grid, with the reason.
    pub unable: Vec<(String, String)>,
    /// The screen: a candidate, or a grid step of one, modelled above this many times the
    /// cheapest verified answer's cost is not run ([`screen`]).
    pub screen_factor: f64,
    /// Candidates not run, or not run below a step, for the screen, with the figures.
    pub screened: Vec<Screened>,
    /// The step grid tried (s).
    pub grid: Vec<f64>,
    /// The frame view: `springlab framerate`'s table of the verified candidates at the view's
    /// rates (null when no rate is asked or nothing was verified).
    pub frame_rates: Option<crate::measure::framerate::Framerate>,
    /// Per rate of the view, the cheapest method meeting the bound there and its substeps.
    pub best_at_rates: Vec<RateBest>,
}

impl Choice {
    /// The choice of run `c` with its prediction `pred` and its repeated `timing`.
    fn new(
        registry: &Registry,
        c: &CaseResult,
        pred: f64,
        judge: &Judge,
        timing: WallTimes,
    ) -> Result<Self> {
        let simulated = c.dt * c.steps as f64;
        let (cost, why) = force_evals_per_second(registry, &c.method, c.force_evals, simulated)?;
        Ok(Choice {
            method: c.method.clone(),
            dt: c.dt,
            predicted_error: pred,
            verified_error: judge.error(c).unwrap_or(f64::INFINITY),
            modelled_per_second: c.modelled_seconds / simulated,
            wall_per_second: timing.median_seconds / simulated,
            cost_per_second: cost,
            cost_per_second_reason: why,
            timing,
            strain_max: c.metric(|m| m.strain_max),
            energy_drift_rate: c.metric(|m| m.energy_drift_rate),
        })
    }
}

/// `choices` cheapest first by [`cost::rank`], with the rule that decided the first place.
fn rank_choices(choices: Vec<Choice>, scenario: &str) -> Result<(Vec<Choice>, Option<PickedBy>)> {
    let keys: Vec<CostKey> = choices
        .iter()
        .map(|c| CostKey {
            method: c.method.clone(),
            modelled_per_second: c.modelled_per_second,
            force_evals_per_second: c.cost_per_second,
        })
        .collect();
    let (order, picked_by) = rank(&keys, scenario)?;
    let mut slots: Vec<Option<Choice>> = choices.into_iter().map(Some).collect();
    let ranked = order
        .iter()
        .map(|&i| slots[i].take().expect("rank returns a permutation"))
        .collect();
    Ok((ranked, picked_by))
}

fn check_timing(r: &TimingRule) -> Result<()> {
    let ok = r.reuses_measured_run() && *r == crate::measure::case::MEASURED_RUN
        || r.min_repetitions >= 1
            && r.max_repetitions >= r.min_repetitions
            && r.cap_repetitions >= 1
            && r.min_total_seconds.is_finite()
            && r.min_total_seconds >= 0.0
            && r.cap_seconds > 0.0;
    if ok {
        Ok(())
    } else {
        Err(Error::option(
            "timing",
            format!("need MEASURED_RUN, or 1 ≤ min_repetitions ≤ max_repetitions, cap_repetitions ≥ 1, a finite min_total_seconds ≥ 0 and cap_seconds > 0; got {r:?}"),
        ))
    }
}

/// The horizon and the candidate steps (step, whole steps over the horizon) `advise` tries on
/// `scene` with `cfg`: from `--dt-min` (default the scene's step / 30) to `--dt-max` (default
/// min(10 × the scene's step, horizon / 4)), `--points` of them, log-spaced.
pub fn step_grid_of(scene: &Scenario, cfg: &AdviseConfig) -> Result<(f64, Vec<(f64, u64)>)> {
    let horizon = crate::scenario::Timing::horizon(scene, cfg.horizon)?;
    let base = scene.run.dt.unwrap_or(horizon / 1000.0);
    let dt_max = cfg.dt_max.unwrap_or((10.0 * base).min(horizon / 4.0));
    let dt_min = cfg.dt_min.unwrap_or(base / 30.0);
    if cfg.points < 2 {
        return Err(Error::option(
            "--points",
            format!(
                "must be at least 2 (a grid needs two ends), got {}",
                cfg.points
            ),
        ));
    }
    if cfg.dt_max.is_some() && !(dt_max.is_finite() && dt_max > 0.0) {
        return Err(Error::option(
            "--dt-max",
            format!(
                "must be a positive finite step (s), got {}",
                crate::error::num(dt_max)
            ),
        ));
    }
    if !(dt_min > 0.0 && dt_min <= dt_max) {
        // A default small end above a user's --dt-max is that flag's doing.
        let blamed = if cfg.dt_min.is_none() && cfg.dt_max.is_some() {
            "--dt-max"
        } else {
            "--dt-min"
        };
        return Err(Error::option(
            blamed,
            format!(
                "need 0 < dt-min ≤ dt-max, got {} and {}",
                crate::error::num(dt_min),
                crate::error::num(dt_max)
            ),
        ));
    }
    // The finest step over the horizon: the longest run of the grid, held to the step limit.
    let flag = if cfg.dt_min.is_some() && cfg.horizon.is_none() {
        "--dt-min"
    } else {
        "--horizon"
    };
    crate::scenario::Timing::steps_within(flag, dt_min, horizon)?;
    Ok((
        horizon,
        step_grid(dt_min, dt_max, cfg.points.max(2), horizon),
    ))
}

/// Refuses a config `advise` cannot run, naming the flag (tolerance, safety, screen factor,
/// timing rule, the step grid), before any work: a command checks it before it takes its
/// output folder. Returns the horizon and the step grid.
pub fn check_config(scene: &Scenario, cfg: &AdviseConfig) -> Result<(f64, Vec<(f64, u64)>)> {
    crate::measure::tolerance::check(cfg.tolerance)?;
    if cfg.safety.is_nan() || cfg.safety < 1.0 {
        return Err(Error::option(
            "--safety",
            format!("must be ≥ 1, got {}", crate::error::num(cfg.safety)),
        ));
    }
    screen::check_factor(cfg.screen_factor)?;
    check_timing(&cfg.timing)?;
    step_grid_of(scene, cfg)
}

/// The settings of advice's runs: no series, no repeats, the step varied, not the substeps.
fn case_settings(cfg: &AdviseConfig) -> CaseSettings {
    // Advice times its candidates' runs itself, after the accuracy runs.
    CaseSettings::measuring(
        cfg.common.registry.clone(),
        cfg.common.options.clone(),
        cfg.common.blowup_factor,
    )
}

/// The command that re-creates the advice on `scene` over `horizon` s.
fn command_line(scene: &Scenario, cfg: &AdviseConfig, horizon: f64) -> String {
    // The methods as asked: none asked means advice's default set (closed forms left out with
    // a reason), which listing every name would change.
    let asked = &cfg.common.methods;
    super::command::CommandLine::new("advise", &scene.source)
        .flag_opt("tolerance", cfg.tolerance)
        .flag_opt("metric", cfg.metric.map(Metric::name))
        .flag("horizon", horizon)
        .flag("safety", cfg.safety)
        .flag("points", cfg.points)
        .flag_opt("dt-min", cfg.dt_min)
        .flag_opt("dt-max", cfg.dt_max)
        .flag("substeps", cfg.common.options.substeps)
        .switch("no-frame-rates", !cfg.frame_rates)
        .flag_opt("hz", cfg.game_hz)
        .flag_opt(
            "screen",
            (cfg.screen_factor != SCREEN_FACTOR).then_some(cfg.screen_factor),
        )
        .common(&cfg.common, asked)
        .render()
}

/// Runs the advice: the candidates priced, then run in waves (the cheapest verified first,
/// the dear ones screened against them: `waves`), the grid extended downwards while nothing
/// meets the bound and the runs stay affordable, the frame-rate view, the timing and the pick.
pub fn advise(scene: &Scenario, cfg: &AdviseConfig) -> Result<Advice> {
    let (horizon, grid) = check_config(scene, cfg)?;
    let sys = scene.build();
    let (names, mut unable) = candidates((scene, &sys), cfg, &grid)?;
    let set = case_settings(cfg);
    let priced = {
        let _stage = crate::run::progress_stage(
            format!("advise {}: modelled costs", scene.name),
            cfg.common.progress,
        );
        screen::price((scene, &sys), cfg, &names, &grid)?
    };
    let ctx = Ctx {
        scene,
        sys: &sys,
        cfg,
        set: &set,
        horizon,
    };
    let mut decided = Decided::default();
    let waves = run_waves(&ctx, &priced, &grid, &mut decided)?;
    let settled = settle(&ctx, &names, (waves, &grid), &mut decided)?;
    unable.extend(settled.unable);
    let (reference, tried, screened) = (settled.reference, settled.tried, settled.screened);
    let answers: Vec<&Answer> = settled.answers.iter().collect();
    let judge = decided
        .judge
        .clone()
        .expect("decided by the first reference");
    let choices = timing::timed_choices(&ctx, &answers, &judge)?;
    let (alternatives, picked_by) = rank_choices(choices, &scene.name)?;
    let verified = alternatives.iter().map(|c| c.method.clone()).collect();
    let ensemble = decided.ensemble.clone().or_else(|| cfg.ensemble.clone());
    let (frame_rates, best_at_rates) =
        frame_view::frame_view(scene, cfg, (horizon, ensemble), verified)?;
    let pick = alternatives.first().cloned();
    let command = command_line(scene, cfg, horizon);
    Ok(Advice {
        head: DocumentHead {
            command,
            scenario: scene.name.clone(),
            reference,
        },
        judged: JudgedBy::of(&judge, decided.metric_note.clone()),
        horizon,
        safety: cfg.safety,
        cost: CostMeasure::new(&cfg.timing),
        picked_by,
        method: pick.as_ref().map(|p| p.method.clone()),
        dt: pick.as_ref().map(|p| p.dt),
        predicted_error: pick.as_ref().map(|p| p.predicted_error),
        verified_error: pick.as_ref().map(|p| p.verified_error),
        modelled_per_second: pick.as_ref().map(|p| p.modelled_per_second),
        wall_per_second: pick.as_ref().map(|p| p.wall_per_second),
        cost_per_second: pick.as_ref().and_then(|p| p.cost_per_second),
        cost_per_second_reason: pick.as_ref().and_then(|p| p.cost_per_second_reason.clone()),
        alternatives,
        unable,
        screen_factor: cfg.screen_factor,
        screened,
        grid: tried,
        frame_rates,
        best_at_rates,
    })
}

/// Writes `advice.json` into `dir` (with `--out dir` in its command), its wall times in
/// `timing.json` ([`crate::output::timing`]); returns the files written.
pub fn write_advice(dir: &std::path::Path, adv: &Advice) -> Result<Vec<std::path::PathBuf>> {
    let doc = Advice {
        head: adv.head.written_to(dir),
        ..adv.clone()
    };
    let mut json = serde_json::to_vec_pretty(&doc).expect("serialisable");
    json.push(b'\n');
    crate::output::write_document(dir.join("advice.json"), &json)
}

/// The `[expect]` table that holds a scene to the advice's pick, or None without a pick: the
/// pick's method and step (one substep), held as [`held_to`] says.
pub fn expect_table(adv: &Advice) -> Option<crate::scenario::file::ExpectSpec> {
    let pick = adv.alternatives.first()?;
    let mut spec = held_to(adv, &pick.method, pick.strain_max, pick.energy_drift_rate);
    spec.dt = Some(pick.dt);
    spec.substeps = Some(1);
    Some(spec)
}

/// The limits an `[expect]` table holds a verified run of `method` to (the caller sets its
/// step or frame rate): stable, its position error within the position tolerance, its strain
/// within the verified run's `strain` plus the relative tolerance (the tolerance over the motion
/// scale), and its energy drift rate within twice the verified run's `drift`.
pub fn held_to(
    adv: &Advice,
    method: &str,
    strain: Option<f64>,
    drift: Option<f64>,
) -> crate::scenario::file::ExpectSpec {
    let relative = adv.judged.position_tolerance.value / adv.head.reference.motion_scale;
    crate::scenario::file::ExpectSpec {
        method: method.to_string(),
        hz: None,
        dt: None,
        substeps: None,
        stable: Some(true),
        max_position_error: Some(adv.judged.position_tolerance.value),
        max_strain: strain.map(|s| s + relative),
        max_energy_drift_rate: drift.map(|r| 2.0 * r.abs()),
    }
}

#[cfg(test)]
mod tests {
    use super::unable_reason;

    // Oracle: each reason must agree with the errors it is given (the statement it makes is
    // checked against the numbers, not against the code's wording).
    #[test]
    fn the_reason_agrees_with_the_grid_errors() {
        let (tol, safety) = (1e-3, 2.0);
        // Met the tolerance but not the margin: says so, and never "exceeds".
        let r = unable_reason(&[(1e-3, Some(7e-4)), (2e-3, Some(9e-4))], tol, safety);
        assert!(
            r.contains("meets the tolerance") && !r.contains("exceeds"),
            "{r}"
        );
        // Its numbers as a person writes them (`error::significant`): plain between 1e-3 and
        // 1e5, scientific below.
        assert!(
            r.contains("tolerance 0.001000 on the grid (smallest error 7.000e-4 at 0.0010000 s)"),
            "{r}"
        );
        // An aliased sample below the target at a coarse step while the smallest misses it:
        // the reason names the failing smallest step, never "smallest error … exceeds".
        let r = unable_reason(&[(1e-3, Some(8e-4)), (5e-2, Some(1.6e-5))], tol, safety);
        assert!(
            r.contains("does not fall with the step") && !r.contains("exceeds"),
            "{r}"
        );
        // Twin: above the tolerance everywhere reads as exceeding it.
        let r = unable_reason(&[(1e-3, Some(2e-3)), (2e-3, Some(8e-3))], tol, safety);
        assert!(r.contains("exceeds the tolerance"), "{r}");
        let r = unable_reason(&[(1e-3, None), (2e-3, None)], tol, safety);
        assert_eq!(r, "unstable at every step of the grid");
    }
}
