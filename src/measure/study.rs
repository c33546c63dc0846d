//! One study per scene: compare, sweep, stability and advice (and, through compare, the
//! contact metrics) run with one set of methods and options, returning the very documents the
//! commands write. The report renders a [`SceneStudy`] and measures nothing itself.
//!
//! Which methods take part where (stated in [`SceneStudy::notes`]):
//! - compare: the scene's `[run].integrators` (else every registered method) next to every
//!   engine, as `springlab compare` does by default; engines only on scenes of at most
//!   [`ENGINE_MAX_PARTICLES`] particles (a Rapier run of the 32×32 cloth takes minutes);
//! - sweep: the non-engine, finite-order methods of that list (an engine's cost per run is far
//!   higher, and its order is not ours to fit);
//! - stability and advice: the compared methods that ran, engines included when their compare
//!   run took at most [`ENGINE_BUDGET_SECONDS`] of wall time (an engine's empirical bisection
//!   and advice grid cost hundreds of such runs; `springlab stability` and `advise` run any
//!   engine on request). The documents' commands name exactly the methods that took part.
//!   Stability runs the empirical bisection only where linear theory does not apply (the
//!   spectral radius decides where it does); a quick study runs theory only.

use super::advise::{advise, Advice, AdviseConfig};
use super::compare::{compare, CompareConfig, CompareResult};
use super::stability::{analyse, StabilityConfig, StabilityReport};
use super::sweep::{run_sweep, SweepConfig, SweepResult};
use crate::error::Result;
use crate::integrate::IntegratorOptions;
use crate::method::Registry;
use crate::scenario::Scenario;
use serde::Serialize;

/// Largest scene (particles) whose comparison includes the engines.
pub const ENGINE_MAX_PARTICLES: usize = 64;

/// Largest wall time (s) of an engine's compare run for it to join stability and advice.
pub const ENGINE_BUDGET_SECONDS: f64 = 1.0;

/// Default advice tolerance of a study: 1 mm of position error over the scene's duration.
pub const DEFAULT_TOLERANCE: f64 = 1e-3;

/// The sweep's cost cap per method (particle-steps) in a full study: a tenth of a default
/// `springlab sweep`'s, so the 32×32 cloth's sweep stays within seconds.
pub const STUDY_COST_CAP: f64 = 4e5;

/// The sweep's cost cap per method (particle-steps) in a quick study.
pub const QUICK_COST_CAP: f64 = 5e4;

/// How thorough a study is and with which methods.
#[derive(Debug, Clone)]
pub struct StudyConfig {
    /// The methods (built-ins unless a library user added theirs).
    pub methods: Registry,
    /// Integrator options.
    pub options: IntegratorOptions,
    /// Position tolerance of the advice (m).
    pub tolerance: f64,
    /// A coarse pass (for tests and previews): fewer sweep points, no empirical stability
    /// search, a short advice grid.
    pub quick: bool,
    /// Progress bars on a terminal.
    pub progress: bool,
    /// Blow-up factor of every run (see [`crate::run::verdict`]).
    pub blowup_factor: f64,
}

impl Default for StudyConfig {
    fn default() -> Self {
        StudyConfig {
            methods: Registry::builtin(),
            options: IntegratorOptions::default(),
            tolerance: DEFAULT_TOLERANCE,
            quick: false,
            progress: false,
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
        }
    }
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
    /// What took part where, and what was left out and why.
    pub notes: Vec<String>,
}

/// Runs the study of `scene`.
pub fn study(scene: &Scenario, cfg: &StudyConfig) -> Result<SceneStudy> {
    let mut notes = Vec::new();
    let small = scene.particles.len() <= ENGINE_MAX_PARTICLES;
    let is_engine = |n: &str| cfg.methods.info(n).is_ok_and(|m| m.engine);
    let asked: Vec<String> = if scene.run.integrators.is_empty() {
        cfg.methods.names().into_iter().map(String::from).collect()
    } else {
        let mut v = scene.run.integrators.clone();
        v.extend(cfg.methods.engine_names().into_iter().map(String::from));
        v
    };
    let (asked, left): (Vec<String>, Vec<String>) =
        asked.into_iter().partition(|n| small || !is_engine(n));
    if !left.is_empty() {
        notes.push(format!(
            "Left out on {} particles (> {ENGINE_MAX_PARTICLES}): {}; `springlab compare` runs them on request.",
            scene.particles.len(),
            left.join(", ")
        ));
    }
    let compared = compare(
        scene,
        &CompareConfig {
            methods: cfg.methods.clone(),
            integrators: asked,
            options: cfg.options,
            series_points: if cfg.quick { 120 } else { 250 },
            progress: cfg.progress,
            blowup_factor: cfg.blowup_factor,
            trace: true,
            ..Default::default()
        },
    )?;
    let ran: Vec<(String, f64)> = compared
        .entries
        .iter()
        .filter_map(|e| {
            e.result
                .as_ref()
                .map(|r| (r.integrator.clone(), r.wall_seconds))
        })
        .collect();
    let sweepable: Vec<String> = ran
        .iter()
        .map(|(n, _)| n)
        .filter(|n| {
            cfg.methods
                .info(n)
                .is_ok_and(|m| !m.engine && m.order.finite().is_some())
        })
        .cloned()
        .collect();
    let mut measured = Vec::new();
    for (n, wall) in &ran {
        if is_engine(n) && *wall > ENGINE_BUDGET_SECONDS {
            notes.push(format!(
                "Stability and advice leave out {n}: its compare run took {wall:.2} s (> {ENGINE_BUDGET_SECONDS} s), and they cost hundreds of such runs."
            ));
        } else {
            measured.push(n.clone());
        }
    }
    let sweep = if sweepable.is_empty() {
        notes.push("No sweep: no non-engine method of finite order applies to this scene.".into());
        None
    } else {
        Some(run_sweep(
            scene,
            &SweepConfig {
                methods: cfg.methods.clone(),
                integrators: sweepable,
                cost_cap: Some(if cfg.quick {
                    QUICK_COST_CAP
                } else {
                    STUDY_COST_CAP
                }),
                options: cfg.options,
                progress: cfg.progress,
                blowup_factor: cfg.blowup_factor,
                ..Default::default()
            },
        )?)
    };
    let stability = analyse(
        scene,
        &StabilityConfig {
            methods: cfg.methods.clone(),
            integrators: measured.clone(),
            options: cfg.options,
            theory_only: cfg.quick,
            progress: cfg.progress,
            blowup_factor: cfg.blowup_factor,
            // Where the spectral radius applies it decides; the bisection would only
            // cross-check it at the price of dozens of runs per method.
            empirical_where_no_theory: !cfg.quick,
            ..Default::default()
        },
    )?;
    let exact: Vec<String> = measured
        .iter()
        .filter(|n| {
            cfg.methods
                .info(n)
                .is_ok_and(|m| m.order == crate::method::Order::Exact)
        })
        .cloned()
        .collect();
    let candidates: Vec<String> = measured
        .iter()
        .filter(|n| !exact.contains(n))
        .cloned()
        .collect();
    if !exact.is_empty() {
        notes.push(format!(
            "Advice leaves out {}: a closed form for this scene only, not a general integrator.",
            exact.join(", ")
        ));
    }
    let uncertainty = compared.reference.uncertainty;
    let mut advice_note = None;
    let advice = if candidates.is_empty() {
        advice_note = Some("no candidate applies".to_string());
        None
    } else if uncertainty > cfg.tolerance {
        // The reference cannot tell errors below its own uncertainty from zero, so no step
        // can be verified to the tolerance (a chaotic scene past its predictable range).
        advice_note = Some(format!(
            "the reference cannot verify {} m: its own uncertainty over the scene's duration is {:.2e} m{}",
            cfg.tolerance,
            uncertainty,
            compared
                .reference
                .predictability_horizon
                .map_or(String::new(), |h| format!(" (predictable for {h} s)"))
        ));
        None
    } else {
        Some(advise(
            scene,
            &AdviseConfig {
                methods: cfg.methods.clone(),
                integrators: candidates,
                options: cfg.options,
                tolerance: cfg.tolerance,
                points: if cfg.quick { 4 } else { 8 },
                progress: cfg.progress,
                blowup_factor: cfg.blowup_factor,
                ..Default::default()
            },
        )?)
    };
    Ok(SceneStudy {
        scenario: scene.name.clone(),
        description: scene.description.clone(),
        compare: compared,
        sweep,
        stability,
        advice,
        advice_note,
        notes,
    })
}
