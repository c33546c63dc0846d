//! The game question: at each frame rate, how does each method fare with one step per frame,
//! and how many substeps per frame does it need to stay stable and within a position
//! tolerance — at what cost per frame?
//!
//! Method: one reference (exact impulses, [`super::reference`]) sampled on every rate's frame
//! grid; per method and rate, the run at 1 substep, then the fewest substeps that is stable
//! and meets the tolerance ([`search::fewest_substeps_from`]: from the fewest substeps the
//! linear stability theory says are stable, where the method's registry entry says it applies,
//! else from one; doubling, then bisection, up to `max_substeps`, and in a budgeted study up
//! to a cost cap in particle-steps). A substep
//! means the same for every method ([`crate::run::RunPlan`]): native methods take n equal
//! steps per frame, Rapier methods n solver substeps. Position error and energy drift are
//! compare's metrics (`measure::metrics`); the runs of the table are then timed like advice's
//! candidates ([`super::case::time_interleaved`], on one thread after every accuracy run).
//!
//! Every number in [`Framerate`] is reproducible bit for bit, regardless of thread count,
//! except `wall_seconds_per_frame` and `timing`; which methods a budget admits is decided on
//! modelled seconds ([`crate::run::cost`]), so it is reproducible too.

mod best;
mod rate;
mod rows;
pub mod search;
mod timing;
mod write;

pub use best::best_at;
use rate::RateSearch;
pub use rows::{FrameRun, RateEntry, RowKind};
pub use timing::FRAMERATE_TIMING;

pub use write::{write_framerate, FRAMERATE_HEADER};

use super::advise::cost::force_evals_per_second;
use super::case::{CaseResult, CaseSettings, TimingRule, WallTimes};
use super::command::CommandLine;
use super::grid::{max_samples_for, TimeGrid, DEFAULT_BUDGET_BYTES};
use super::reference::{Reference, ReferenceInfo};
use crate::error::{Error, Result};
use crate::measure::command::DocumentHead;
use crate::measure::statistics::Ensemble;
use crate::measure::tolerance::{Judge, JudgedBy, Metric};
use crate::method::Order;
use crate::model::Events;
use crate::scenario::Scenario;
use rayon::prelude::*;
use serde::Serialize;

/// Frame rates asked by default (Hz): the common game and display rates.
pub const DEFAULT_RATES: [f64; 5] = [30.0, 60.0, 120.0, 144.0, 240.0];

/// Default largest substep count searched per frame.
pub const DEFAULT_MAX_SUBSTEPS: u64 = 64;

/// Options of [`framerate`].
#[derive(Debug, Clone)]
pub struct FramerateConfig {
    /// Frame rates (Hz).
    pub rates: Vec<f64>,
    /// The rates engines (Rapier) are searched at, each one of `rates`: an engine's frame
    /// costs far more than a native step, so a study searches it at the game rate only;
    /// `None`: every rate.
    pub engine_rates: Option<Vec<f64>>,
    /// Position tolerance (m); None: the scene's `[run] tolerance`, else 1 % of its motion
    /// scale ([`crate::measure::tolerance`]).
    pub tolerance: Option<f64>,
    /// Which error decides; None: statistics past a predictability horizon, else position.
    pub metric: Option<Metric>,
    /// An ensemble already made for this scene over the same run (the study passes
    /// compare's); None: made here when the statistics metric needs it.
    pub ensemble: Option<Ensemble>,
    /// Methods, registry, options, blow-up factor, progress and budget: what every
    /// measuring command shares.
    pub common: crate::measure::Common,
    /// Simulated time (s; default the scene's duration).
    pub duration: Option<f64>,
    /// Largest substep count tried.
    pub max_substeps: u64,
    /// Largest run tried, in particle-steps (particles × frames × substeps); `None`: no cap.
    pub cost_cap: Option<f64>,
    /// How the table's runs are timed.
    pub timing: TimingRule,
    /// Start each method's search from the fewest substeps its linear stability theory says
    /// are stable, where its registry entry says the theory applies
    /// ([`search::fewest_substeps_from`]); false: double from one substep. The fewest found is
    /// the same either way for a test monotone in the substeps; the start saves the runs below.
    pub theory_start: bool,
}

impl Default for FramerateConfig {
    fn default() -> Self {
        FramerateConfig {
            rates: DEFAULT_RATES.to_vec(),
            engine_rates: None,
            tolerance: None,
            metric: None,
            ensemble: None,
            duration: None,
            max_substeps: DEFAULT_MAX_SUBSTEPS,
            cost_cap: None,
            timing: FRAMERATE_TIMING,
            theory_start: true,
            common: crate::measure::Common::default(),
        }
    }
}

/// The frame-event floor of [`RateEntry::frame_event_floor`] on grid `g` of `reference`:
/// `scene` with its kicks moved to the frame boundaries of `g` and applied exactly, solved by
/// the reference's own solver, against `reference`, over the frames before the reference's
/// predictability horizon. None when events are exact or the scene has no kicks.
pub fn frame_event_floor(scene: &Scenario, reference: &Reference, g: usize) -> Result<Option<f64>> {
    if scene.run.events == Events::Exact || scene.impulses.is_empty() {
        return Ok(None);
    }
    let grid = reference.grids[g];
    let mut lagged = scene.clone();
    for im in &mut lagged.impulses {
        im.time = scene.run.events.applied_at(im.time, grid.dt);
    }
    lagged.run.events = Events::Exact;
    let end = grid.time(grid.steps);
    let lagged = Reference::compute(&lagged.build(), &scene.initial_state(), &[grid], end)?;
    let horizon = reference
        .info
        .predictability_horizon
        .unwrap_or(f64::INFINITY);
    let floor = (1..=grid.steps)
        .take_while(|&k| grid.time(k) < horizon)
        .filter_map(|k| Some((reference.positions(g, k)?, lagged.positions(0, k)?)))
        .map(|(a, b)| super::metrics::position_error(a, b))
        .fold(0.0, f64::max);
    Ok(Some(floor))
}

/// `framerate.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Framerate {
    /// The command, the scene and the reference (impulses at their exact times).
    #[serde(flatten)]
    pub head: DocumentHead,
    /// When impulses took effect in the runs (`exact` or `frame`).
    pub events: &'static str,
    /// What every run was judged by.
    #[serde(flatten)]
    pub judged: JudgedBy,
    /// Simulated time asked (s); each rate runs the nearest whole number of frames.
    pub duration: f64,
    /// Frame rates (Hz).
    pub rates: Vec<f64>,
    /// Largest substep count tried.
    pub max_substeps: u64,
    /// Largest run tried in particle-steps, if capped.
    pub cost_cap: Option<f64>,
    /// How the runs were timed.
    pub timing: TimingRule,
    /// Per method, per rate (methods in the order asked, rates as given).
    pub entries: Vec<RateEntry>,
    /// Methods that cannot run the scene, with the reason.
    pub skipped: Vec<(String, String)>,
    /// Set when the reference's own uncertainty before its predictability horizon exceeds
    /// the position tolerance: then no run can be verified to it, and "none" means that.
    pub reference_note: Option<String>,
}

/// Whole frames at `hz` covering `duration` s (the nearest count, at least 1): how every
/// frame-rate view (this one and advice's) turns a duration into frames.
pub fn frames_at(duration: f64, hz: f64) -> u64 {
    crate::model::whole_steps(duration * hz, 1.0)
}

fn check(cfg: &FramerateConfig) -> Result<()> {
    if cfg.rates.is_empty() {
        return Err(Error::option("--hz", "give at least one frame rate"));
    }
    if let Some(f) = cfg.rates.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        return Err(Error::option(
            "--hz",
            format!(
                "every frame rate must be a finite number > 0 Hz, got {}",
                crate::error::num(*f)
            ),
        ));
    }
    if let Some(f) = cfg
        .engine_rates
        .iter()
        .flatten()
        .find(|f| !cfg.rates.contains(f))
    {
        return Err(Error::option(
            "--engine-hz",
            format!(
                "{} Hz is not one of the rates asked with --hz",
                crate::error::num(*f)
            ),
        ));
    }
    crate::measure::tolerance::check(cfg.tolerance)?;
    if cfg.max_substeps == 0 {
        return Err(Error::option("--max-substeps", "must be at least 1"));
    }
    if let Some(c) = cfg.cost_cap.filter(|c| !(c.is_finite() && *c > 0.0)) {
        return Err(Error::option(
            "--cost-cap",
            format!("must be a finite number > 0, got {}", crate::error::num(c)),
        ));
    }
    Ok(())
}

/// The measured part of a run; its wall time too under [`MEASURED_RUN`] timing (a stable run
/// that covered every frame), else filled in by the timing after every accuracy run.
fn frame_run(
    cfg: &FramerateConfig,
    c: &CaseResult,
    substeps: u64,
    judge: &Judge,
) -> Result<FrameRun> {
    let (evals, why) = force_evals_per_second(
        &cfg.common.registry,
        &c.method,
        c.force_evals,
        c.steps as f64,
    )?;
    let measured = (cfg.timing.reuses_measured_run() && c.ok() && c.steps_done == c.steps)
        .then(|| WallTimes::of(&[c.wall_seconds]));
    Ok(FrameRun {
        substeps,
        status: c.status,
        meets_tolerance: judge.meets(c),
        error: judge.error(c),
        max_position_error: c.metric(|m| m.error_max),
        energy_drift: c.metric(|m| m.energy_drift),
        modelled_seconds_per_frame: c
            .ok()
            .then(|| c.modelled_seconds / c.steps_done.max(1) as f64),
        wall_seconds_per_frame: measured
            .as_ref()
            .map(|t| t.median_seconds / c.steps.max(1) as f64),
        timing: measured,
        force_evals_per_frame: evals,
        force_evals_reason: why,
        unstable_time: c.unstable_time,
        unstable_reason: c.unstable_reason.clone(),
        strain_max: c.metric(|m| m.strain_max),
        energy_drift_rate: c.metric(|m| m.energy_drift_rate),
    })
}

/// Whether method `name` is searched at `hz` ([`FramerateConfig::engine_rates`]).
fn searched_at(cfg: &FramerateConfig, name: &str, hz: f64) -> bool {
    match &cfg.engine_rates {
        Some(r) if cfg.common.registry.info(name).is_ok_and(|m| m.engine) => r.contains(&hz),
        _ => true,
    }
}

/// Frames a method's search runs over, summed over the rates it is searched at.
fn frames_searched(cfg: &FramerateConfig, name: &str, frames: &[u64]) -> f64 {
    cfg.rates
        .iter()
        .zip(frames)
        .filter(|(&hz, _)| searched_at(cfg, name, hz))
        .map(|(_, &n)| n as f64)
        .sum()
}

/// Substeps a worst-case search runs over `frames` frames (summed over the rates): doubling to
/// `max_substeps` (2·max − 1 substeps per frame in all) and bisecting below it (fewer than max
/// more). Budgets project a search's cost from it.
pub fn worst_case_substeps(frames: f64, max_substeps: u64) -> f64 {
    frames * (3 * max_substeps) as f64
}

/// The methods whose worst-case searches fit `budget` (s, summed), cheapest first; each
/// projected from its time per substep (an engine's probe at the fastest rate divided by its
/// solver substeps). The rest go to `skipped` with the figures.
fn within_budget(
    sys: &crate::model::System,
    s0: &crate::model::State,
    cfg: &FramerateConfig,
    names: Vec<String>,
    frames: &[u64],
    budget: f64,
    skipped: &mut Vec<(String, String)>,
) -> Result<Vec<String>> {
    use crate::measure::probe::{
        check_budget, seconds_per_step, split_by_budget, Cost, PROBE_STEPS,
    };
    // Engines are priced per solver substep from their modelled frame.
    check_budget(budget)?;
    let hz = cfg.rates.iter().cloned().fold(0.0, f64::max);
    let costs: Vec<Cost> = names
        .iter()
        .map(|n| {
            let per = seconds_per_step(
                sys,
                s0,
                &cfg.common.registry,
                &cfg.common.options,
                n,
                1.0 / hz,
                PROBE_STEPS,
            )
            .unwrap_or(0.0);
            let engine = cfg.common.registry.info(n).is_ok_and(|m| m.engine);
            let per_unit = if engine {
                per / cfg.common.options.substeps.max(1) as f64
            } else {
                per
            };
            let worst = worst_case_substeps(frames_searched(cfg, n, frames), cfg.max_substeps);
            Cost {
                per_unit,
                projected: per_unit * worst,
            }
        })
        .collect();
    let what = format!(
        "its search (up to {} substeps at {} rates)",
        cfg.max_substeps,
        cfg.rates.len()
    );
    let (kept, left) = split_by_budget(names, &costs, budget, &what, "substep");
    skipped.extend(left);
    Ok(kept)
}

/// Whole frames at each asked rate over `duration`, refused where a run would pass the step
/// limit (the length's fault at one substep, `--max-substeps`' with them) or an impulse would
/// never act.
fn frames_per_rate(scene: &Scenario, cfg: &FramerateConfig, duration: f64) -> Result<Vec<u64>> {
    // Too many frames at one substep is the length's fault (the rate's when the length is the
    // scene's); too many only with the substeps, --max-substeps'.
    let length_flag = if cfg.duration.is_some() {
        "--duration"
    } else {
        "--hz"
    };
    for &hz in &cfg.rates {
        // A frame longer than the run is refused as `run` refuses it (the run would end one
        // frame after its duration), before any reference is solved over that frame.
        crate::scenario::Timing::step_fits(scene, 1.0 / hz, Some(length_flag), duration)?;
        crate::scenario::Timing::steps_within(length_flag, 1.0 / hz, duration)?;
    }
    let frames: Vec<u64> = cfg
        .rates
        .iter()
        .map(|&hz| frames_at(duration, hz))
        .collect();
    for (&hz, &n) in cfg.rates.iter().zip(&frames) {
        let end = n as f64 / hz;
        if n.saturating_mul(cfg.max_substeps) > crate::scenario::MAX_STEPS {
            return Err(Error::option(
                "--max-substeps",
                format!(
                    "{n} frames at {} Hz × {} substeps exceeds the limit of {} steps",
                    crate::error::num(hz),
                    cfg.max_substeps,
                    crate::scenario::MAX_STEPS
                ),
            ));
        }
        crate::scenario::Timing::check_impulses(scene, end)?;
        crate::scenario::Timing::check_frame_impulses(scene, 1.0 / hz, end)?;
    }
    Ok(frames)
}

/// Why no substep count met the bound: the search's end (the cap on substeps or on cost),
/// and, with frame events, the floor the kicks' move to frame boundaries puts under any run.
fn no_fewest_note(
    cfg: &FramerateConfig,
    largest: u64,
    floor: Option<f64>,
    tolerance: f64,
) -> String {
    let capped = largest < cfg.max_substeps;
    let base = if capped {
        format!(
            "none up to {largest} substeps; {} would pass the cost cap of {} particle-steps",
            2 * largest,
            crate::error::num(cfg.cost_cap.unwrap_or(f64::INFINITY))
        )
    } else {
        format!("none up to --max-substeps {}", cfg.max_substeps)
    };
    match floor {
        Some(f) if f > tolerance => format!(
            "{base}: with events = \"frame\" the kicks move to frame boundaries, which alone puts the exact solution {} m from the reference, above the tolerance; no substep count removes that floor",
            crate::error::significant(f, 4)
        ),
        Some(f) => format!(
            "{base} (the frame-event floor, the exact solution with its kicks at frame boundaries, is {} m)",
            crate::error::significant(f, 4)
        ),
        None => base,
    }
}

/// Each method's largest stable step by the linear stability theory, where its registry entry
/// says the theory applies and the theory gives one (None elsewhere, or with
/// [`FramerateConfig::theory_start`] off): the frame-rate search starts from the substeps it
/// implies instead of doubling from one.
fn search_starts(
    cfg: &FramerateConfig,
    sys: &crate::model::System,
    s0: &crate::model::State,
    names: &[String],
) -> Result<Vec<Option<f64>>> {
    if !cfg.theory_start {
        return Ok(vec![None; names.len()]);
    }
    crate::measure::stability::theory_limits(
        &cfg.common.registry,
        &cfg.common.options,
        sys,
        s0,
        names,
    )
}

/// The command that re-creates a table of `names` (and the `skipped` methods) on `scene` over
/// `duration` s.
fn command_line(
    scene: &Scenario,
    cfg: &FramerateConfig,
    names: &[String],
    skipped: &[(String, String)],
    duration: f64,
) -> String {
    let listed: Vec<String> = names
        .iter()
        .chain(skipped.iter().map(|s| &s.0))
        .cloned()
        .collect();
    CommandLine::new("framerate", &scene.source)
        .list("hz", &cfg.rates)
        .list("engine-hz", cfg.engine_rates.as_deref().unwrap_or(&[]))
        .flag_opt("tolerance", cfg.tolerance)
        .flag_opt("metric", cfg.metric.map(Metric::name))
        .flag("duration", duration)
        .flag("max-substeps", cfg.max_substeps)
        .flag_opt("cost-cap", cfg.cost_cap)
        .common(&cfg.common, &listed)
        .render()
}

/// Why no run can be verified, when the reference `info`'s own uncertainty over a run with no
/// predictability horizon exceeds the position `tolerance` (m).
fn reference_note(info: &ReferenceInfo, tolerance: f64) -> Option<String> {
    let u = info.uncertainty;
    (info.predictability_horizon.is_none() && u > tolerance).then(|| {
        format!(
            "the reference's own uncertainty over the run is {} m, above the tolerance {} m: no run can be verified to it",
            crate::error::significant(u, 3),
            crate::error::significant(tolerance, 4)
        )
    })
}

/// A method left out of the table, with why.
type Skipped = (String, String);

/// The methods the table searches (every applicable one but closed forms unless asked for,
/// within the budget) and those left out, with why.
fn methods_of(
    sys: &crate::model::System,
    s0: &crate::model::State,
    cfg: &FramerateConfig,
    frames: &[u64],
) -> Result<(Vec<String>, Vec<Skipped>)> {
    let (mut names, mut skipped) = cfg.common.applicable(sys)?;
    if cfg.common.methods.is_empty() {
        // Closed forms solve special scenes exactly; they are not a frame-rate choice.
        names.retain(|n| {
            cfg.common
                .registry
                .info(n)
                .is_ok_and(|m| m.order != Order::Exact)
        });
    }
    if let Some(b) = cfg.common.budget_seconds {
        names = within_budget(sys, s0, cfg, names, frames, b, &mut skipped)?;
    }
    Ok((names, skipped))
}

/// Each rate's frame grid (`frames` frames of 1/hz), its samples held to the memory budget
/// of a reference of `particles` particles.
fn frame_grids(cfg: &FramerateConfig, frames: &[u64], particles: usize) -> Vec<TimeGrid> {
    let max_samples = max_samples_for(DEFAULT_BUDGET_BYTES, cfg.rates.len(), particles);
    cfg.rates
        .iter()
        .zip(frames)
        .map(|(hz, &n)| TimeGrid::new(1.0 / hz, n, max_samples))
        .collect()
}

/// The settings of the table's runs: no series, no repeats (the timing comes after), the
/// substeps set per run.
fn case_settings(cfg: &FramerateConfig) -> CaseSettings {
    CaseSettings::measuring(
        cfg.common.registry.clone(),
        cfg.common.options.clone(),
        cfg.common.blowup_factor,
    )
}

/// Measures every method at every frame rate: per method and rate, the fewest substeps that
/// meet the tolerance.
pub fn framerate(scene: &Scenario, cfg: &FramerateConfig) -> Result<Framerate> {
    check(cfg)?;
    let sys = scene.build();
    let s0 = scene.initial_state();
    let duration = crate::scenario::Timing::duration(scene, cfg.duration)?;
    let frames = frames_per_rate(scene, cfg, duration)?;
    let (names, skipped) = methods_of(&sys, &s0, cfg, &frames)?;
    let grids = frame_grids(cfg, &frames, sys.len());
    let horizon = grids.iter().map(|g| g.time(g.steps)).fold(0.0, f64::max);
    let stage = crate::run::progress_stage(
        format!("framerate {}: reference and judge", scene.name),
        cfg.common.progress,
    );
    let mut reference = Reference::compute(&sys, &s0, &grids, horizon)?;
    let (judge, metric_note) = crate::measure::tolerance::decide(
        cfg.metric,
        cfg.tolerance,
        scene,
        &mut reference,
        &sys,
        &s0,
        cfg.ensemble.as_ref(),
    )?;
    let set = case_settings(cfg);
    let floors: Vec<Option<f64>> = (0..cfg.rates.len())
        .map(|r| frame_event_floor(scene, &reference, r))
        .collect::<Result<_>>()?;
    drop(stage);
    let jobs: Vec<(usize, usize)> = (0..names.len())
        .flat_map(|b| (0..cfg.rates.len()).map(move |r| (b, r)))
        .filter(|&(b, r)| searched_at(cfg, &names[b], cfg.rates[r]))
        .collect();
    let pb = crate::run::progress_bar(
        jobs.len() as u64,
        &format!("framerate {}", scene.name),
        cfg.common.progress,
    );
    let particles = sys.len().max(1) as f64;
    let starts = search_starts(cfg, &sys, &s0, &names)?;
    let search = RateSearch {
        cfg,
        sys: &sys,
        s0: &s0,
        reference: &reference,
        judge: &judge,
        set: &set,
        names: &names,
        frames: &frames,
        floors: &floors,
        starts: &starts,
        particles,
        guided: scene.collision.is_none() && scene.impulses.is_empty(),
    };
    let searched: Vec<Result<RateEntry>> = jobs
        .par_iter()
        .map(|&(b, r)| {
            let entry = search.entry(b, r)?;
            pb.inc(1);
            Ok(entry)
        })
        .collect();
    pb.finish_and_clear();
    let mut entries = searched.into_iter().collect::<Result<Vec<_>>>()?;
    {
        let _stage = crate::run::progress_stage(
            format!("framerate {}: timing", scene.name),
            cfg.common.progress,
        );
        if !cfg.timing.reuses_measured_run() {
            timing::time_entries(&sys, &s0, &mut entries, &set, &cfg.timing)?;
        }
    }
    let command = command_line(scene, cfg, &names, &skipped, duration);
    let reference_note = reference_note(&reference.info, judge.tolerance.value);
    Ok(Framerate {
        reference_note,
        head: DocumentHead {
            command,
            scenario: scene.name.clone(),
            reference: reference.info,
        },
        events: sys.events.label(),
        judged: JudgedBy::of(&judge, metric_note),
        duration,
        rates: cfg.rates.clone(),
        max_substeps: cfg.max_substeps,
        cost_cap: cfg.cost_cap,
        timing: cfg.timing,
        entries,
        skipped,
    })
}
