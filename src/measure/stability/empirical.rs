//! The empirical search: the largest step at which the runner's one verdict calls a run of the
//! real scene ok over the horizon, bracketed and bisected, and the budget that decides which
//! searches run.

use super::{StabilityConfig, Verdict};
use crate::error::Result;
use crate::method::Method;
use crate::method::MethodOptions;
use crate::model::{State, System};
use crate::run::{run, NoObserver, RunPlan};
use serde::Serialize;

/// The empirical criterion and search bounds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EmpiricalCriterion {
    /// Simulated time of each trial run (s); a trial runs at least [`MIN_TRIAL_STEPS`] steps.
    pub horizon: f64,
    /// A run is unstable once its energy balance rises by more than this multiple of the
    /// scene's energy scale, or a state is non-finite (the runner's verdict).
    pub blowup_factor: f64,
    /// Smallest step tried (s).
    pub dt_min: f64,
    /// Largest step tried (s).
    pub dt_max: f64,
}

/// Fewest steps of a trial run: as many as the map's cells ([`super::MAP_MIN_STEPS`]), so a
/// spectral radius of [`super::RHO_SHOWN`] multiplies a mode's energy by
/// [`super::GROWTH_SHOWN`] within any trial, however few steps of a large h the horizon holds.
pub const MIN_TRIAL_STEPS: u64 = super::MAP_MIN_STEPS;

/// Steps of a trial run at step `h`: the horizon's, at least [`MIN_TRIAL_STEPS`].
pub fn trial_steps(crit: &EmpiricalCriterion, h: f64) -> u64 {
    crate::model::covering_steps(crit.horizon, h).max(MIN_TRIAL_STEPS)
}

/// Result of the empirical search.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Empirical {
    /// Verdict within the search bounds.
    pub verdict: Verdict,
    /// Largest stable step found (s).
    pub max_stable_dt: Option<f64>,
    /// Trial runs made.
    pub runs: usize,
    /// Why the search ended before its bracket closed (the budget), when it did: the verdict
    /// is then what the trials so far showed (`stable_below` a step found stable, larger ones
    /// untried or unbracketed; `not_analysed` when no stable step was found).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
}

/// Empirical search for the largest stable step of `method` on the real scene.
pub fn empirical_limit(
    sys: &System,
    s0: &State,
    method: &Method,
    opts: &MethodOptions,
    start: f64,
    crit: &EmpiricalCriterion,
) -> Result<Empirical> {
    empirical_limit_within(sys, s0, method, opts, start, crit, None)
}

/// As [`empirical_limit`], each trial booked on `work` ([`super::work::SearchWork`]): a trial
/// that would take the search past its allowance is not run, and the search ends with what it
/// found, saying so in [`Empirical::stopped`].
pub fn empirical_limit_within(
    sys: &System,
    s0: &State,
    method: &Method,
    opts: &MethodOptions,
    start: f64,
    crit: &EmpiricalCriterion,
    mut work: Option<&mut super::work::SearchWork>,
) -> Result<Empirical> {
    let mut runs = 0;
    let mut stopped: Option<String> = None;
    // Some(verdict) per trial; None when the budget stopped the search before it.
    let mut stable = |h: f64| -> Result<Option<bool>> {
        let steps = trial_steps(crit, h);
        if let Some(why) = work.as_deref().and_then(|w| w.refuse(steps)) {
            stopped = Some(why);
            return Ok(None);
        }
        runs += 1;
        let mut stepper = method.create(opts);
        let plan = RunPlan {
            dt: h,
            steps,
            substeps: 1,
            blowup_factor: crit.blowup_factor,
            stop_at_verdict: true,
        };
        let out = run(sys, &mut stepper, s0.clone(), &plan, &mut NoObserver)?;
        if let Some(w) = work.as_deref_mut() {
            w.book(out.modelled_seconds, out.steps_done);
        }
        Ok(Some(out.status.is_ok()))
    };
    let done = |verdict, max_stable_dt, runs, stopped: &mut Option<String>| Empirical {
        verdict,
        max_stable_dt,
        runs,
        stopped: stopped.take(),
    };
    let mut h = start.clamp(crit.dt_min, crit.dt_max);
    let (mut lo, mut hi);
    match stable(h)? {
        None => return Ok(done(Verdict::NotAnalysed, None, runs, &mut stopped)),
        Some(true) => {
            lo = h;
            loop {
                h *= 2.0;
                if h > crit.dt_max {
                    return Ok(done(
                        Verdict::UnconditionallyStable,
                        None,
                        runs,
                        &mut stopped,
                    ));
                }
                match stable(h)? {
                    // Stable at `lo`, larger steps untried: a lower bound.
                    None => return Ok(done(Verdict::StableBelow, Some(lo), runs, &mut stopped)),
                    Some(false) => {
                        hi = h;
                        break;
                    }
                    Some(true) => lo = h,
                }
            }
        }
        Some(false) => {
            hi = h;
            loop {
                h *= 0.5;
                if h < crit.dt_min {
                    return Ok(done(Verdict::UnstableForAllDt, None, runs, &mut stopped));
                }
                match stable(h)? {
                    None => return Ok(done(Verdict::NotAnalysed, None, runs, &mut stopped)),
                    Some(true) => {
                        lo = h;
                        break;
                    }
                    Some(false) => hi = h,
                }
            }
        }
    }
    while hi / lo > 1.001 {
        let mid = (lo * hi).sqrt();
        match stable(mid)? {
            None => break,
            Some(true) => lo = mid,
            Some(false) => hi = mid,
        }
    }
    Ok(done(Verdict::StableBelow, Some(lo), runs, &mut stopped))
}

/// Per method, its empirical search's projected cost: [`SEARCH_TRIALS`] trials of
/// `horizon / start` steps at its probed time per step (nothing where no search runs).
pub(super) fn search_costs(
    sys: &System,
    s0: &State,
    cfg: &StabilityConfig,
    names: &[String],
    starts: &[Option<f64>],
    horizon: f64,
) -> Vec<crate::measure::probe::Cost> {
    use crate::measure::probe::{seconds_per_step, Cost};
    names
        .iter()
        .zip(starts)
        .map(|(name, start)| match start {
            Some(h) => {
                let steps = (horizon / h).ceil().max(MIN_TRIAL_STEPS as f64);
                let per = seconds_per_step(
                    sys,
                    s0,
                    &cfg.common.registry,
                    &cfg.common.options,
                    name,
                    *h,
                    steps as u64,
                )
                .unwrap_or(0.0);
                Cost {
                    per_unit: per,
                    projected: per * steps * SEARCH_TRIALS,
                }
            }
            None => Cost {
                per_unit: 0.0,
                projected: 0.0,
            },
        })
        .collect()
}

/// Per method, why its empirical search is left out (`None`: it runs): the searches that fit
/// `budget` (s, summed), cheapest first, run; each projected by [`search_costs`] (`costs`).
pub(super) fn searches_over_budget(
    names: &[String],
    costs: &[crate::measure::probe::Cost],
    budget: f64,
) -> Result<Vec<Option<String>>> {
    use crate::measure::probe::{check_budget, split_by_budget};
    check_budget(budget)?;
    let what = format!("its empirical search (about {SEARCH_TRIALS} trials over the horizon)");
    let (_, left) = split_by_budget(names.to_vec(), costs, budget, &what, "step");
    Ok(names
        .iter()
        .map(|n| left.iter().find(|l| l.0 == *n).map(|l| l.1.clone()))
        .collect())
}

/// Trials an empirical search typically takes, for its projected cost: bracketing by doubling
/// or halving (one to three), then bisection to a 0.1 % bracket (about ten).
pub const SEARCH_TRIALS: f64 = 14.0;
