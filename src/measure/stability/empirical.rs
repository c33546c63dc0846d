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
    let mut runs = 0;
    let mut stable = |h: f64| -> Result<bool> {
        runs += 1;
        let mut stepper = method.create(opts);
        let plan = RunPlan {
            dt: h,
            steps: trial_steps(crit, h),
            substeps: 1,
            blowup_factor: crit.blowup_factor,
            stop_at_verdict: true,
        };
        Ok(
            run(sys, stepper.as_mut(), s0.clone(), &plan, &mut NoObserver)?
                .status
                .is_ok(),
        )
    };
    let mut h = start.clamp(crit.dt_min, crit.dt_max);
    let (mut lo, mut hi);
    if stable(h)? {
        lo = h;
        loop {
            h *= 2.0;
            if h > crit.dt_max {
                return Ok(Empirical {
                    verdict: Verdict::UnconditionallyStable,
                    max_stable_dt: None,
                    runs,
                });
            }
            if !stable(h)? {
                hi = h;
                break;
            }
            lo = h;
        }
    } else {
        hi = h;
        loop {
            h *= 0.5;
            if h < crit.dt_min {
                return Ok(Empirical {
                    verdict: Verdict::UnstableForAllDt,
                    max_stable_dt: None,
                    runs,
                });
            }
            if stable(h)? {
                lo = h;
                break;
            }
            hi = h;
        }
    }
    while hi / lo > 1.001 {
        let mid = (lo * hi).sqrt();
        if stable(mid)? {
            lo = mid
        } else {
            hi = mid
        }
    }
    Ok(Empirical {
        verdict: Verdict::StableBelow,
        max_stable_dt: Some(lo),
        runs,
    })
}

/// Per method, why its empirical search is left out (`None`: it runs): the searches that fit
/// `budget` (s, summed), cheapest first, run; each projected at [`SEARCH_TRIALS`] trials of
/// `horizon / start` steps at its probed time per step.
pub(super) fn searches_over_budget(
    sys: &System,
    s0: &State,
    cfg: &StabilityConfig,
    names: &[String],
    starts: &[Option<f64>],
    horizon: f64,
    budget: f64,
) -> Result<Vec<Option<String>>> {
    use crate::measure::probe::{check_budget, seconds_per_step, split_by_budget, Cost};
    check_budget(budget)?;
    let costs: Vec<Cost> = names
        .iter()
        .zip(starts)
        .map(|(name, start)| match start {
            Some(h) => {
                let steps = (horizon / h).ceil().max(MIN_TRIAL_STEPS as f64);
                let per =
                    seconds_per_step(sys, s0, &cfg.registry, &cfg.options, name, *h, steps as u64)
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
        .collect();
    let what = format!("its empirical search (about {SEARCH_TRIALS} trials over the horizon)");
    let (_, left) = split_by_budget(names.to_vec(), &costs, budget, &what, "step");
    Ok(names
        .iter()
        .map(|n| left.iter().find(|l| l.0 == *n).map(|l| l.1.clone()))
        .collect())
}

/// Trials an empirical search typically takes, for its projected cost: bracketing by doubling
/// or halving (one to three), then bisection to a 0.1 % bracket (about ten).
pub const SEARCH_TRIALS: f64 = 14.0;
