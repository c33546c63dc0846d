//! One study per scene: compare, sweep, stability and advice (and, through compare, the
//! contact metrics) run with one set of methods and options, returning the very documents the
//! commands write. The report renders a [`SceneStudy`] and measures nothing itself.
//!
//! Which methods take part where (stated in [`SceneStudy::notes`]):
//! - compare: the scene's `[run].methods` (else every registered method) next to every
//!   engine, as `springlab compare` does by default; an engine unless its cost model
//!   ([`crate::rapier::cost`]) projects its run above [`engine_compare_limit`]:
//!   [`ENGINE_NATIVE_FACTOR`] times the native methods' modelled total, at least
//!   [`ENGINE_COMPARE_SECONDS`] (the note gives its modelled time per step otherwise);
//! - sweep: the non-engine, finite-order methods of that list (an engine's cost per run is far
//!   higher, and its order is not ours to fit);
//! - stability and advice: the compared methods that ran; an engine joins stability when its
//!   empirical search (about `SEARCH_TRIALS` trials of at least `MIN_TRIAL_STEPS` steps, priced
//!   per step from its compare run) projects at most [`ENGINE_BUDGET_SECONDS`] and advice when its runs over the advice grid project at most
//!   [`ENGINE_ADVICE_SECONDS`] (`springlab stability` and `advise` run any engine on request). The documents' commands name exactly the methods that took part.
//!   Stability runs the empirical bisection only where linear theory does not apply (the
//!   spectral radius decides where it does); a quick study runs theory only.
//! - framerate: the compared methods that ran (closed forms aside) at
//!   [`crate::measure::framerate::DEFAULT_RATES`] with a 1 cm tolerance, up to
//!   [`FRAMERATE_MAX_SUBSTEPS`] substeps per frame; a method (engine or not) takes part when
//!   its compare run's modelled seconds per (sub)step project the worst-case search at
//!   [`FRAMERATE_METHOD_SECONDS`] or less. Engines (Rapier) are the comparison a game
//!   programmer makes at these rates, so they take part even when compare left them out (their
//!   modelled frame then prices it), and every engine gets [`FRAMERATE_ENGINE_SECONDS`]; the section lists the modelled time of any method left out
//!   (`springlab framerate` runs it). Each table run's and each advice candidate's wall time is its accuracy run's own
//!   ([`super::case::MEASURED_RUN`]): the wall times decide nothing, so the study runs nothing again to time it.
//!
//! Every such choice is made on modelled seconds ([`crate::run::cost`]: counted work, priced),
//! never on a clock, so a re-run of the study takes the same methods everywhere.

use super::advise::{advise, Advice, AdviseConfig};
use super::compare::{compare, CompareConfig, CompareResult};
use super::framerate::{framerate, Framerate, FramerateConfig};
use super::stability::{analyse, StabilityConfig, StabilityReport};
use super::sweep::{plan_sweep, run_sweep, SweepConfig, SweepResult};
use crate::error::Result;
use crate::scenario::Scenario;
use serde::Serialize;

/// Steps of a probe run that counts a method's work per step (an engine is priced from the
/// scene without one).
pub const ENGINE_PROBE_STEPS: u64 = super::probe::PROBE_STEPS;

/// Modelled seconds of an engine's compare run below which it always takes part.
pub const ENGINE_COMPARE_SECONDS: f64 = 5.0;

/// How many times the native methods' modelled compare total an engine's compare run may cost
/// and still take part ([`engine_compare_limit`]).
pub const ENGINE_NATIVE_FACTOR: f64 = 20.0;

/// Largest projected modelled seconds of an engine's empirical stability search (its
/// compare run's cost per step over the search's trials) for it to join stability.
pub const ENGINE_BUDGET_SECONDS: f64 = 2.0;

/// Largest projected modelled seconds of an engine's runs over the advice grid for it to join
/// the advice.
pub const ENGINE_ADVICE_SECONDS: f64 = 0.25;

/// Largest substep count per frame the study's frame-rate search tries (a quick study: 4).
pub const FRAMERATE_MAX_SUBSTEPS: u64 = 32;

/// Largest projected modelled seconds of one method's worst-case frame-rate search (every rate,
/// doubling to [`FRAMERATE_MAX_SUBSTEPS`] and bisecting) for it to take part.
pub const FRAMERATE_METHOD_SECONDS: f64 = 4.0;

/// Largest projected modelled seconds of the worst-case frame-rate search of an engine (a
/// Rapier row): Rapier at game rates is what the frame-rate section exists to compare against,
/// so an engine gets far more than a native method (the 32×32 cloth's rapier_impulse projects
/// about 12 s; rapier_multibody there about 350 s, and is left out with its time per frame).
pub const FRAMERATE_ENGINE_SECONDS: f64 = 60.0;

/// Time budget of a study's advice (s of runs, summed over its candidates): the costliest
/// candidates whose grid runs would not fit are left out with the figure (on the 32×32 cloth,
/// the implicit methods, whose finest grid runs take tens of seconds each).
pub const STUDY_ADVICE_SECONDS: f64 = 30.0;

/// The sweep's cost cap per method (particle-steps) in a full study: a tenth of a default
/// `springlab sweep`'s, so the 32×32 cloth's sweep stays within seconds.
pub const STUDY_COST_CAP: f64 = 4e5;

/// Fewest step sizes a study's sweep must afford to be run (an order fit needs three).
pub const MIN_SWEEP_STEPS: usize = 3;

/// The sweep's cost cap per method (particle-steps) in a quick study.
pub const QUICK_COST_CAP: f64 = 5e4;

/// How thorough a study is and with which methods.
#[derive(Debug, Clone, Default)]
pub struct StudyConfig {
    /// Methods, registry, options, blow-up factor, progress and budget: what every
    /// measuring command shares.
    pub common: crate::measure::Common,
    /// Position tolerance of every answer (m); None: each scene's `[run] tolerance`, else 1 %
    /// of its motion scale ([`crate::measure::tolerance`]).
    pub tolerance: Option<f64>,
    /// A coarse pass (for tests and previews): fewer sweep points, no empirical stability
    /// search, a short advice grid.
    pub quick: bool,
}

/// Everything measured about one scene: the commands' own documents.
#[derive(Debug, Clone, Serialize)]
pub struct SceneStudy {
    /// Scene name.
    pub scenario: String,
    /// Scene description.
    pub description: String,
    /// `compare`'s result at the scene's step (with series, traces and contact metrics).
    pub compare: CompareResult,
    /// `sweep`'s result, when a sweepable method applies.
    pub sweep: Option<SweepResult>,
    /// `stability`'s result.
    pub stability: StabilityReport,
    /// `advise`'s result, when a candidate applies and the reference can verify the tolerance.
    pub advice: Option<Advice>,
    /// Why there is no advice, when there is none.
    pub advice_note: Option<String>,
    /// `framerate`'s result (1 cm tolerance), when a method fits the budget.
    pub framerate: Option<Framerate>,
    /// Why there is no frame-rate table, when there is none.
    pub framerate_note: Option<String>,
    /// The scene's answer at a free step and at its game rate ([`super::answer`]).
    pub answer: super::answer::Answer,
    /// What took part where, and what was left out and why.
    pub notes: Vec<String>,
    /// What the frame-rate section left out and why (rates whose frame is longer than the
    /// run, methods beyond its budget): the report shows them in that section.
    pub framerate_notes: Vec<String>,
    /// Wall time of each part (s), for the report's budget.
    pub seconds: StudySeconds,
}

/// Wall time (s) each part of a study took: where a report's time goes.
#[derive(Debug, Clone, Copy, Default, Serialize, serde::Deserialize)]
pub struct StudySeconds {
    /// `compare` (reference, every method, contact metrics, traces).
    pub compare: f64,
    /// `sweep`.
    pub sweep: f64,
    /// `stability`.
    pub stability: f64,
    /// `advise`.
    pub advice: f64,
    /// `framerate`.
    #[serde(default)]
    pub framerate: f64,
}

/// Runs the study of `scene`: compare, sweep, stability, advice and frame rates in that order,
/// each on the methods the earlier parts leave in, then the two answers.
pub fn study(scene: &Scenario, cfg: &StudyConfig) -> Result<SceneStudy> {
    let mut notes = Vec::new();
    let mut seconds = StudySeconds::default();
    let timing = crate::scenario::Timing::resolve(scene, None, None)?;
    let mut clock = std::time::Instant::now();
    let mut lap = |slot: &mut f64| {
        *slot = clock.elapsed().as_secs_f64();
        clock = std::time::Instant::now();
    };
    let (asked, probed_out) = compared_methods(scene, cfg, timing, &mut notes)?;
    let compared = compare(
        scene,
        &CompareConfig {
            series_points: if cfg.quick { 120 } else { 250 },
            trace: true,
            tolerance: cfg.tolerance,
            common: crate::measure::Common {
                methods: asked,
                ..cfg.common.clone()
            },
            ..Default::default()
        },
    )?;
    lap(&mut seconds.compare);
    let advice_cfg = AdviseConfig {
        tolerance: cfg.tolerance,
        ensemble: compared.ensemble.clone(),
        points: if cfg.quick { 4 } else { 8 },
        // The frame-rate section (`framerate`) answers the game view: one computation.
        frame_rates: false,
        timing: super::case::MEASURED_RUN,
        common: crate::measure::Common {
            budget_seconds: Some(STUDY_ADVICE_SECONDS),
            ..cfg.common.clone()
        },
        ..Default::default()
    };
    let kept = kept_after_compare(scene, cfg, &compared, &advice_cfg, timing, &mut notes)?;
    let sweep = study_sweep(scene, cfg, kept.sweepable, &mut notes)?;
    lap(&mut seconds.sweep);
    let stability = analyse(
        scene,
        &StabilityConfig {
            theory_only: cfg.quick,
            // Where the spectral radius applies it decides; the bisection would only
            // cross-check it at the price of dozens of runs per method.
            empirical_where_no_theory: !cfg.quick,
            common: crate::measure::Common {
                methods: kept.measured.clone(),
                ..cfg.common.clone()
            },
            ..Default::default()
        },
    )?;
    lap(&mut seconds.stability);
    let (advice, advice_note) = study_advice(
        scene,
        cfg,
        &kept.measured,
        &kept.advisable,
        advice_cfg,
        &mut notes,
    )?;
    lap(&mut seconds.advice);
    let mut framerate_notes = Vec::new();
    let (framerate, framerate_note, framerate_left_out) =
        study_framerate(scene, cfg, &compared, &probed_out, &mut framerate_notes)?;
    lap(&mut seconds.framerate);
    let measured = super::answer::Measured {
        compared: &compared,
        advice: advice.as_ref(),
        advice_note: advice_note.as_deref(),
        framerate: framerate.as_ref(),
        framerate_note: framerate_note.as_deref(),
        framerate_left_out: &framerate_left_out,
    };
    let answer = super::answer::answer(
        &cfg.common.registry,
        &measured,
        scene.run.hz.unwrap_or(super::answer::GAME_HZ),
        &scene.name,
    )?;
    Ok(SceneStudy {
        answer,
        framerate,
        framerate_note,
        seconds,
        scenario: scene.name.clone(),
        description: scene.description.clone(),
        compare: compared,
        sweep,
        stability,
        advice,
        advice_note,
        notes,
        framerate_notes,
    })
}

/// The methods compare runs: the scene's `[run] methods` (else every method) plus the
/// engines, less each engine whose probe projects a compare run over its
/// [`engine_compare_limit`] (returned apart with its modelled seconds per step, and noted).
fn compared_methods(
    scene: &Scenario,
    cfg: &StudyConfig,
    timing: crate::scenario::Timing,
    notes: &mut Vec<String>,
) -> Result<(Vec<String>, Vec<ProbedOut>)> {
    let is_engine = |n: &str| cfg.common.registry.info(n).is_ok_and(|m| m.engine);
    let asked: Vec<String> = if scene.run.methods.is_empty() {
        cfg.common
            .registry
            .names()
            .into_iter()
            .map(String::from)
            .collect()
    } else {
        let mut v = scene.run.methods.clone();
        v.extend(
            cfg.common
                .registry
                .engine_names()
                .into_iter()
                .map(String::from),
        );
        v
    };
    // Engines are priced from the scene; the native methods' total (a short probe run each)
    // is counted only when some engine costs more than the floor it is judged against.
    let engine_cost: Vec<(String, Option<f64>)> = asked
        .iter()
        .filter(|n| is_engine(n))
        .map(|n| Ok((n.clone(), method_probe(scene, cfg, n, timing)?)))
        .collect::<Result<_>>()?;
    let steps = timing.steps as f64;
    let native_total = if engine_cost
        .iter()
        .any(|(_, c)| c.is_some_and(|c| c * steps > ENGINE_COMPARE_SECONDS))
    {
        asked
            .iter()
            .filter(|n| !is_engine(n))
            .filter_map(|n| method_probe(scene, cfg, n, timing).transpose())
            .sum::<Result<f64>>()?
            * steps
    } else {
        0.0
    };
    let limit = engine_compare_limit(native_total);
    let mut kept = Vec::new();
    let mut probed_out = Vec::new();
    for n in asked {
        let Some((_, cost)) = engine_cost.iter().find(|(e, _)| *e == n) else {
            kept.push(n);
            continue;
        };
        match *cost {
            Some(per_step) if per_step * steps > limit => {
                notes.push(format!(
                    "Left out {n}: {:.3} ms per step by the cost model, so {} steps would take about {:.1} s, over {ENGINE_NATIVE_FACTOR}× the native methods' {:.2} s (and over {ENGINE_COMPARE_SECONDS} s); `springlab compare --methods {n}` runs it.",
                    per_step * 1e3,
                    timing.steps,
                    per_step * steps,
                    native_total
                ));
                probed_out.push((n, per_step));
            }
            _ => kept.push(n),
        }
    }
    Ok((kept, probed_out))
}

/// Largest modelled seconds of an engine's compare run for it to take part, given the native
/// methods' modelled total on the scene: [`ENGINE_NATIVE_FACTOR`] times that total, and never
/// less than [`ENGINE_COMPARE_SECONDS`]. Rapier beside the native methods is the comparison the
/// study exists for, so an engine is left out only when it would cost far more than they do.
pub fn engine_compare_limit(native_total_seconds: f64) -> f64 {
    (ENGINE_NATIVE_FACTOR * native_total_seconds).max(ENGINE_COMPARE_SECONDS)
}

/// An engine compare leaves out, with its modelled seconds per step.
type ProbedOut = (String, f64);

/// Which of the methods compare ran go on to the sweep, the stability analysis and advice.
struct Kept {
    /// Native methods of finite order.
    sweepable: Vec<String>,
    /// All but engines whose empirical search projects over [`ENGINE_BUDGET_SECONDS`].
    measured: Vec<String>,
    /// All but engines whose runs over the advice grid would take over
    /// [`ENGINE_ADVICE_SECONDS`].
    advisable: Vec<String>,
}

/// The methods that go on after compare, engines judged by their compare run's modelled
/// seconds (each one left out noted with the figure).
fn kept_after_compare(
    scene: &Scenario,
    cfg: &StudyConfig,
    compared: &CompareResult,
    advice_cfg: &AdviseConfig,
    timing: crate::scenario::Timing,
    notes: &mut Vec<String>,
) -> Result<Kept> {
    let ran: Vec<(String, f64)> = compared
        .entries
        .iter()
        .filter_map(|e| {
            e.result
                .as_ref()
                .map(|r| (r.method.clone(), r.modelled_seconds))
        })
        .collect();
    let info = |n: &str| cfg.common.registry.info(n).ok();
    let sweepable = ran
        .iter()
        .map(|(n, _)| n)
        .filter(|n| info(n).is_some_and(|m| !m.engine && m.order.finite().is_some()))
        .cloned()
        .collect();
    let (_, advice_grid) = super::advise::step_grid_of(scene, advice_cfg)?;
    let grid_steps: u64 = advice_grid.iter().map(|&(_, s)| s).sum();
    let mut measured = Vec::new();
    let mut advisable = Vec::new();
    for (n, cost) in &ran {
        let engine = info(n).is_some_and(|m| m.engine);
        // The empirical search runs about SEARCH_TRIALS trials of at least MIN_TRIAL_STEPS
        // steps each (more where the horizon needs them), priced per step from compare.
        let search = cost / timing.steps.max(1) as f64
            * timing.steps.max(super::stability::MIN_TRIAL_STEPS) as f64
            * super::stability::SEARCH_TRIALS;
        if engine && search > ENGINE_BUDGET_SECONDS {
            notes.push(format!(
                "Stability leaves out {n}: its empirical search (about {} trials of at least {} steps) would cost about {search:.1} s by the cost model (> {ENGINE_BUDGET_SECONDS} s); `springlab stability --methods {n}` runs it.",
                super::stability::SEARCH_TRIALS,
                super::stability::MIN_TRIAL_STEPS
            ));
        } else {
            measured.push(n.clone());
        }
        let projected = cost / timing.steps as f64 * grid_steps as f64;
        if engine && projected > ENGINE_ADVICE_SECONDS {
            notes.push(format!(
                "Advice leaves out {n}: its runs over the advice grid ({} steps, down to {:.2e} s) would take about {projected:.1} s (> {ENGINE_ADVICE_SECONDS} s); `springlab advise --methods {n}` runs it.",
                grid_steps,
                advice_grid.first().map_or(0.0, |g| g.0)
            ));
        } else {
            advisable.push(n.clone());
        }
    }
    Ok(Kept {
        sweepable,
        measured,
        advisable,
    })
}

/// The study's sweep of `sweepable` at the study's cost cap, `None` (noted) when no method
/// applies or the cap affords too few steps to fit an order.
fn study_sweep(
    scene: &Scenario,
    cfg: &StudyConfig,
    sweepable: Vec<String>,
    notes: &mut Vec<String>,
) -> Result<Option<SweepResult>> {
    if sweepable.is_empty() {
        notes.push("No sweep: no non-engine method of finite order applies to this scene.".into());
        return Ok(None);
    }
    let sweep_cfg = SweepConfig {
        cost_cap: Some(if cfg.quick {
            QUICK_COST_CAP
        } else {
            STUDY_COST_CAP
        }),
        // Wall times decide nothing here: one run each, not five for a median.
        repeat_short: false,
        common: crate::measure::Common {
            methods: sweepable,
            ..cfg.common.clone()
        },
        ..Default::default()
    };
    let plan = plan_sweep(scene, &sweep_cfg)?;
    if plan.dts.len() < MIN_SWEEP_STEPS {
        // One or two steps fit no order: not worth a reference solve and every method.
        notes.push(format!(
            "No sweep: at the study's cost cap ({:.0e} particle-steps per method) this scene of {} particles affords {} step size(s), too few to fit an order; `springlab sweep {}` (cap {:.0e}) measures it.",
            sweep_cfg.cost_cap.unwrap_or_default(),
            plan.particles,
            plan.dts.len(),
            scene.source.display(),
            super::sweep::DEFAULT_COST_CAP
        ));
        return Ok(None);
    }
    Ok(Some(run_sweep(scene, &sweep_cfg)?))
}

/// Advice over the advisable methods but closed forms (a closed form is for this scene only,
/// not a general method; noted), with why there is none.
fn study_advice(
    scene: &Scenario,
    cfg: &StudyConfig,
    measured: &[String],
    advisable: &[String],
    advice_cfg: AdviseConfig,
    notes: &mut Vec<String>,
) -> Result<(Option<Advice>, Option<String>)> {
    let exact: Vec<String> = measured
        .iter()
        .filter(|n| {
            cfg.common
                .registry
                .info(n)
                .is_ok_and(|m| m.order == crate::method::Order::Exact)
        })
        .cloned()
        .collect();
    let candidates: Vec<String> = advisable
        .iter()
        .filter(|n| !exact.contains(n))
        .cloned()
        .collect();
    if !exact.is_empty() {
        notes.push(format!(
            "Advice leaves out {}: a closed form for this scene only, not a general method.",
            exact.join(", ")
        ));
    }
    if candidates.is_empty() {
        return Ok((None, Some("no candidate applies".to_string())));
    }
    let advice = advise(
        scene,
        &AdviseConfig {
            common: crate::measure::Common {
                methods: candidates,
                ..advice_cfg.common.clone()
            },
            ..advice_cfg
        },
    )?;
    Ok((Some(advice), None))
}

/// Modelled seconds per step of method `name` on `scene` at the scene's step
/// ([`super::probe::seconds_per_step`]: an engine priced from the scene, a native method
/// counted over a short run); `None` when it does not apply (the comparison then reports it
/// as it does every method).
fn method_probe(
    scene: &Scenario,
    cfg: &StudyConfig,
    name: &str,
    timing: crate::scenario::Timing,
) -> Result<Option<f64>> {
    Ok(super::probe::seconds_per_step(
        &scene.build(),
        &scene.initial_state(),
        &cfg.common.registry,
        &cfg.common.options,
        name,
        timing.dt,
        timing.steps,
    ))
}

/// The study's frame-rate table: every compared method that ran (closed forms aside) whose
/// worst-case search projects within [`FRAMERATE_METHOD_SECONDS`] (an engine:
/// [`FRAMERATE_ENGINE_SECONDS`]), from its compare run's modelled seconds per step (an engine's per
/// solver substep: its compare run used `options.substeps`), and every engine compare left
/// out (`probed_out`: its probe's time per step) under the same rule. Returns the table, why
/// there is none, and the methods left out for time.
fn study_framerate(
    scene: &Scenario,
    cfg: &StudyConfig,
    compared: &CompareResult,
    probed_out: &[(String, f64)],
    notes: &mut Vec<String>,
) -> Result<(Option<Framerate>, Option<String>, Vec<String>)> {
    let game = scene.run.hz.unwrap_or(super::answer::GAME_HZ);
    let max_substeps = if cfg.quick { 4 } else { FRAMERATE_MAX_SUBSTEPS };
    let duration = crate::scenario::Timing::duration(scene, None)?;
    let rates = framerate_rates(cfg, game, duration, notes);
    if !rates.contains(&game) {
        return Ok((
            None,
            Some(format!(
                "the game rate's frame is longer than the run's {duration} s"
            )),
            Vec::new(),
        ));
    }
    let frames: f64 = rates
        .iter()
        .map(|&hz| super::framerate::frames_at(duration, hz) as f64)
        .sum();
    let budget = FrameBudget {
        game,
        rate_count: rates.len(),
        max_substeps,
        worst: super::framerate::worst_case_substeps(frames, max_substeps),
        // Engines are searched at the game rate only: the row a game programmer compares.
        worst_engine: super::framerate::worst_case_substeps(
            super::framerate::frames_at(duration, game) as f64,
            max_substeps,
        ),
    };
    let ran = compared
        .entries
        .iter()
        .filter_map(|e| e.result.as_ref())
        .map(|r| (&r.method, r.modelled_seconds / r.steps_done.max(1) as f64));
    let probed = probed_out.iter().map(|(n, s)| (n, *s));
    let measured: Vec<(&String, f64)> = ran.chain(probed).collect();
    let (mut chosen, left_out) = within_frame_budget(cfg, &measured, probed_out, &budget, notes);
    // An engine that cannot run the scene is listed in the section with compare's reason.
    chosen.extend(
        compared
            .entries
            .iter()
            .filter(|e| {
                e.result.is_none() && cfg.common.registry.info(&e.method).is_ok_and(|m| m.engine)
            })
            .map(|e| e.method.clone()),
    );
    if chosen.is_empty() {
        return Ok((
            None,
            Some("no method fits the frame-rate budget".into()),
            left_out,
        ));
    }
    let fr = framerate(
        scene,
        &FramerateConfig {
            rates,
            engine_rates: Some(vec![game]),
            max_substeps,
            tolerance: cfg.tolerance,
            ensemble: compared.ensemble.clone(),
            timing: super::case::MEASURED_RUN,
            common: crate::measure::Common {
                methods: chosen,
                ..cfg.common.clone()
            },
            ..Default::default()
        },
    )?;
    Ok((Some(fr), None, left_out))
}

/// The study's frame rates over a run of `duration` s: the default ones (none when quick) and
/// the `game` rate, less those whose frame is longer than the run (said in `notes`).
fn framerate_rates(
    cfg: &StudyConfig,
    game: f64,
    duration: f64,
    notes: &mut Vec<String>,
) -> Vec<f64> {
    let mut rates: Vec<f64> = if cfg.quick {
        vec![]
    } else {
        super::framerate::DEFAULT_RATES.to_vec()
    };
    if !rates.contains(&game) {
        rates.push(game);
        rates.sort_by(f64::total_cmp);
    }
    // A frame longer than the run cannot be a frame of it.
    let too_long: Vec<f64> = rates
        .iter()
        .copied()
        .filter(|&hz| 1.0 / hz > duration)
        .collect();
    if !too_long.is_empty() {
        rates.retain(|hz| !too_long.contains(hz));
        notes.push(format!(
            "Frame rates leave out {} Hz: a frame is longer than the run's {} s.",
            too_long
                .iter()
                .map(|hz| crate::error::significant(*hz, 3))
                .collect::<Vec<_>>()
                .join(", "),
            crate::error::significant(duration, 3)
        ));
    }
    rates
}

/// What the study's frame-rate search of one method is projected to take.
struct FrameBudget {
    /// The game's frame rate (Hz), the one engines are searched at.
    game: f64,
    /// How many rates a native method is searched at.
    rate_count: usize,
    /// Largest substep count searched.
    max_substeps: u64,
    /// Substeps of a worst-case search over every rate.
    worst: f64,
    /// Substeps of a worst-case search at the game rate alone (an engine's).
    worst_engine: f64,
}

/// Of the `measured` methods (name, modelled seconds per step; `probed_out` those priced from
/// the scene), those whose worst-case search fits its budget and those left out, each of these
/// with a note in `notes`. Closed forms and unknown methods are in neither.
fn within_frame_budget(
    cfg: &StudyConfig,
    measured: &[(&String, f64)],
    probed_out: &[(String, f64)],
    fb: &FrameBudget,
    notes: &mut Vec<String>,
) -> (Vec<String>, Vec<String>) {
    let (game, max_substeps) = (fb.game, fb.max_substeps);
    let (mut chosen, mut left_out) = (Vec::new(), Vec::new());
    for &(name, per_step) in measured {
        let Ok(info) = cfg.common.registry.info(name) else {
            continue;
        };
        if info.order == crate::method::Order::Exact {
            continue;
        }
        let per_substep = if info.engine {
            per_step / cfg.common.options.substeps.max(1) as f64
        } else {
            per_step
        };
        let projected = per_substep
            * if info.engine {
                fb.worst_engine
            } else {
                fb.worst
            };
        // Every engine is a Rapier row: each gets the engine budget.
        let budget = if info.engine {
            FRAMERATE_ENGINE_SECONDS
        } else {
            FRAMERATE_METHOD_SECONDS
        };
        if projected > budget {
            left_out.push(name.clone());
            notes.push(format!(
                "Frame rates leave out {name}: {:.3} ms per {}, modelled {}, so its search (up to {max_substeps} substeps at {}) could take about {projected:.0} s (> {budget} s); `springlab framerate --methods {name}` runs it.",
                per_substep * 1e3,
                if info.engine {
                    format!("solver substep ({:.3} ms per frame at {} substeps)", per_step * 1e3, cfg.common.options.substeps.max(1))
                } else {
                    "step".into()
                },
                if probed_out.iter().any(|(n, _)| n == name) { "from the scene" } else { "from its compare run" },
                if info.engine { format!("{} Hz", crate::error::significant(game, 3)) } else { format!("{} rates", fb.rate_count) },
            ));
        } else {
            chosen.push(name.clone());
        }
    }
    (chosen, left_out)
}
