//! `stability.json`: theory and empirical search for every applicable method on one scene.

use super::empirical::{
    empirical_limit_within, search_costs, searches_over_budget, EmpiricalCriterion,
};
use super::theory::{theory_limit, Limit, RHO_TOL, SCAN_MAX, SCAN_MIN};
use super::work::{units, SearchWork};
use super::{MethodStability, StabilityConfig, StabilityReport, Verdict};
use crate::error::{Error, Result};
use crate::measure::modes::{modes, Modes};
use crate::method::StabilityTheory;
use crate::scenario::Scenario;
use rayon::prelude::*;

/// Analyses every applicable method on `scene`: the linear theory per method, then the
/// empirical searches the budget allows, in parallel, each method judged by `analyse_one`.
pub fn analyse(scene: &Scenario, cfg: &StabilityConfig) -> Result<StabilityReport> {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let ms = modes(&sys, &s0);
    let (names, skipped) = cfg.common.applicable(&sys)?;
    let horizon = horizon(scene, cfg, &ms)?;
    let crit = EmpiricalCriterion {
        horizon,
        blowup_factor: cfg.common.blowup_factor,
        dt_min: horizon / 1e6,
        dt_max: horizon / 2.0,
    };
    // The linear theory per method (cheap), then where each empirical search would start and
    // which searches the budget allows.
    let theories: Vec<Option<Limit>> = names
        .iter()
        .map(|name| {
            let method = cfg.common.registry.get(name)?;
            Ok((method.info.linear_theory() && !ms.modes.is_empty())
                .then(|| theory_limit(method, &cfg.common.options, &ms)))
        })
        .collect::<Result<_>>()?;
    let starts = search_starts(scene, cfg, &names, &theories, &crit);
    let costs = search_costs(&sys, &s0, cfg, &names, &starts, horizon);
    let left_out = match cfg.common.budget_seconds {
        Some(b) => searches_over_budget(&names, &costs, b)?,
        None => vec![None; names.len()],
    };
    // The searches that run, their projections, and what each may spend: the budget less the
    // others' projections (a fixed share, so the verdicts do not depend on thread timing).
    let projected: Vec<f64> = costs
        .iter()
        .zip(&left_out)
        .map(|(c, l)| if l.is_none() { c.projected } else { 0.0 })
        .collect();
    let planned: f64 = projected.iter().sum();
    let pb = crate::run::progress_bar(
        units(planned).max(1),
        &format!("stability {} (modelled ms of trials)", scene.name),
        cfg.common.progress,
    );
    let results: Vec<Result<MethodStability>> = names
        .par_iter()
        .enumerate()
        .map(|(k, name)| {
            let allowance = cfg
                .common
                .budget_seconds
                .map(|b| b - (planned - projected[k]));
            let mut work = SearchWork::new(&pb, projected[k], allowance);
            let search = Search {
                sys: &sys,
                s0: &s0,
                crit: &crit,
                start: starts[k],
                left_out: left_out[k].as_deref(),
            };
            let r = analyse_one(cfg, name, theories[k], &ms, &search, &mut work);
            work.finish();
            r
        })
        .collect();
    pb.finish_and_clear();
    let asked = crate::measure::case::asked_or_all(&cfg.common.registry, &cfg.common.methods);
    let command = crate::measure::command::CommandLine::new("stability", &scene.source)
        .flag("substeps", cfg.common.options.substeps)
        .flag("horizon", horizon)
        .switch("theory-only", cfg.theory_only)
        .switch("empirical-where-no-theory", cfg.empirical_where_no_theory)
        .common(&cfg.common, &asked)
        .render();
    Ok(StabilityReport {
        command,
        scenario: scene.name.clone(),
        omega_max: ms.omega_max,
        theory_criterion: format!("spectral radius of the one-step map on every linearised mode ≤ 1 + {RHO_TOL:e}, scanned over hω ∈ [{SCAN_MIN:e}, {SCAN_MAX:e}] (down to 1e-2 ζ on a damped mode of damping ratio ζ) and bisected"),
        empirical_criterion: crit,
        methods: results.into_iter().collect::<Result<_>>()?,
        skipped,
        modes: ms,
    })
}

/// The empirical horizon: the one asked (checked: finite, positive, and coverable at the step
/// that resolves the fastest mode, hω_max = 1, like any run past the step limit), else 100
/// periods of the fastest mode, else the scene's own duration when nothing oscillates.
fn horizon(scene: &Scenario, cfg: &StabilityConfig, ms: &Modes) -> Result<f64> {
    let Some(h) = cfg.horizon else {
        return if ms.omega_max > 0.0 {
            Ok(100.0 * std::f64::consts::TAU / ms.omega_max)
        } else {
            crate::scenario::Timing::duration(scene, None)
        };
    };
    let flag = "--horizon";
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::option(
            flag,
            format!("must be a finite number > 0, got {}", crate::error::num(h)),
        ));
    }
    if ms.omega_max > 0.0 {
        let step = 1.0 / ms.omega_max;
        crate::scenario::Timing::steps_within(flag, step, h).map_err(|e| {
            Error::option(
                flag,
                format!(
                    "at the step that resolves the fastest mode (hω_max = 1), {}",
                    e.to_string().trim_start_matches("--horizon: ")
                ),
            )
        })?;
    } else if let Some(dt) = scene.run.dt {
        crate::scenario::Timing::steps_within(flag, dt, h)?;
    }
    Ok(h)
}

/// Where each method's empirical search starts (its theory limit, else the scene's step, else
/// a hundredth of the horizon, within the search bounds), `None` where no search runs: a
/// closed form, `--theory-only`, or a theory verdict with `--empirical-where-no-theory`.
fn search_starts(
    scene: &Scenario,
    cfg: &StabilityConfig,
    names: &[String],
    theories: &[Option<Limit>],
    crit: &EmpiricalCriterion,
) -> Vec<Option<f64>> {
    names
        .iter()
        .zip(theories)
        .map(|(name, theory)| {
            let unconditional = cfg
                .common
                .registry
                .info(name)
                .is_ok_and(|m| m.stability == StabilityTheory::Unconditional);
            let skip = unconditional
                || cfg.theory_only
                || (cfg.empirical_where_no_theory && theory.is_some());
            (!skip).then(|| {
                theory
                    .and_then(|t| t.1)
                    .or(scene.run.dt)
                    .unwrap_or(crit.horizon / 100.0)
                    .clamp(crit.dt_min, crit.dt_max)
            })
        })
        .collect()
}

/// One method's empirical search, as planned: the scene, the criterion, where it starts
/// (`None`: no search) and why the budget left it out (`None`: it runs).
struct Search<'a> {
    sys: &'a crate::model::System,
    s0: &'a crate::model::State,
    crit: &'a EmpiricalCriterion,
    start: Option<f64>,
    left_out: Option<&'a str>,
}

/// One method's verdict: a closed form is stable at any step; otherwise the linear theory
/// decides where it applies, the empirical search where it does not, with a note saying which
/// approximation or omission applies.
fn analyse_one(
    cfg: &StabilityConfig,
    name: &str,
    theory: Option<Limit>,
    ms: &Modes,
    search: &Search,
    work: &mut SearchWork,
) -> Result<MethodStability> {
    let method = cfg.common.registry.get(name)?;
    let exact = method.info.stability == StabilityTheory::Unconditional;
    let mut note = None;
    if theory.is_none() {
        if ms.modes.is_empty() {
            note = Some("the linearised scene has no stiffness or damping (constraints are projected, not linearised): empirical only".to_string());
        } else if exact {
            note = Some("exact closed form: stable at any step".to_string());
        } else if !method.info.linear_theory() {
            note = Some(format!(
                "no linear one-step theory applies to {name} (registered stability: empirical; a constraint projection or an engine's solver, not a linear map of the ODE): empirical bisection on the scene only"
            ));
        }
    }
    if exact {
        return Ok(MethodStability {
            method: name.to_string(),
            verdict: Verdict::UnconditionallyStable,
            max_stable_dt: None,
            h_omega: None,
            decided_by: super::DecidedBy::ClosedForm,
            theory_verdict: Some(Verdict::UnconditionallyStable),
            theory_max_stable_dt: None,
            empirical: None,
            note,
            statement: "a closed form: stable at every step".into(),
        });
    }
    let empirical = match (search.start, search.left_out) {
        (Some(start), None) => Some(empirical_limit_within(
            search.sys,
            search.s0,
            method,
            &cfg.common.options,
            start,
            search.crit,
            Some(work),
        )?),
        (Some(_), Some(why)) => {
            note = Some(why.to_string());
            None
        }
        (None, _) => None,
    };
    if let Some(why) = empirical.as_ref().and_then(|e| e.stopped.clone()) {
        note = Some(why);
    }
    let (verdict, dt, decided_by) = match (&theory, &empirical) {
        (Some(t), _) => (t.0, t.1, super::DecidedBy::SpectralRadius),
        (None, Some(e)) => (
            e.verdict,
            e.max_stable_dt,
            super::DecidedBy::EmpiricalBisection,
        ),
        (None, None) => {
            if search.left_out.is_none() {
                note = Some(
                    "no linear theory applies and the empirical search was skipped (--theory-only)"
                        .into(),
                );
            }
            (Verdict::NotAnalysed, None, super::DecidedBy::Nothing)
        }
    };
    if ms.damping_coupling.is_some_and(|c| c > 1e-6) && theory.is_some() {
        note = Some(format!(
            "modal damping is coupled (off-diagonal {:.1e} of the diagonal); the theory limit uses the diagonal",
            ms.damping_coupling.unwrap_or(0.0)
        ));
    }
    let statement = super::statement(
        method,
        &cfg.common.options,
        ms,
        theory,
        empirical.as_ref(),
        |h| super::trial_steps(search.crit, h),
    );
    Ok(MethodStability {
        method: name.to_string(),
        statement,
        verdict,
        max_stable_dt: dt,
        h_omega: dt.map(|d| d * ms.omega_max),
        decided_by,
        theory_verdict: theory.map(|t| t.0),
        theory_max_stable_dt: theory.and_then(|t| t.1),
        empirical,
        note,
    })
}

/// Writes `stability.json` into `dir` (with `--out dir` in its command).
pub fn write_stability(dir: &std::path::Path, rep: &StabilityReport) -> Result<std::path::PathBuf> {
    let doc = StabilityReport {
        command: crate::measure::command::with_out(&rep.command, dir),
        ..rep.clone()
    };
    let mut json = serde_json::to_vec_pretty(&doc).expect("serialisable");
    json.push(b'\n');
    crate::output::write_atomic(dir.join("stability.json"), &json)
}
