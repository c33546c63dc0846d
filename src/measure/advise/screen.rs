//! The screen: advice spends its runs where a user would look. Every candidate's modelled cost
//! ([`crate::measure::probe`]: counted work, so the screen decides the same on every re-run and
//! any thread count) is priced at each grid step before anything runs; once a candidate is
//! verified, a candidate whose least possible cost is more than [`SCREEN_FACTOR`] times the
//! cheapest verified answer's is not run, and the grid steps of the others that would cost
//! more than that are not run either. Both are named in the advice with the figures.
//!
//! A candidate's least possible cost (its floor) is its modelled cost per simulated second at
//! the largest step it could use: the grid's largest, or, where the linear stability theory
//! applies (a fact of its registry entry), [`STABILITY_SLACK`] times its theoretical limit when
//! that is smaller (the theory linearises the scene at its initial state, and growth just past
//! the limit can be too slow to show over the horizon, so a run a little past it may still
//! pass). Why the screen never drops the pick: a candidate's verified cost is at least its
//! floor, so one whose floor is ten times a verified answer's costs at least ten times it; and
//! the grid steps a pick's answer is made from (its passing steps, one grid step finer than
//! its answer at most) cost well under ten times that answer.

use super::config::AdviseConfig;
use crate::error::{significant, Result};
use crate::measure::case::CaseResult;
use crate::measure::probe::{seconds_per_step, sig3};
use crate::model::System;
use crate::scenario::Scenario;
use rayon::prelude::*;
use serde::Serialize;

/// How far above the cheapest verified answer's modelled cost a candidate, or a grid step of
/// one, may be and still run (10: an answer ten times the cost of a verified one is not an
/// alternative anyone takes, and the factor stays well clear of the model's error, about 20 %).
pub const SCREEN_FACTOR: f64 = 10.0;

/// How far past its theoretical stability limit a candidate's floor step may lie (2: see the
/// module docs).
pub const STABILITY_SLACK: f64 = 2.0;

/// Refuses a screen factor below 1 (it would screen out the verified answer itself), naming
/// `--screen`.
pub fn check_factor(factor: f64) -> Result<()> {
    if factor >= 1.0 {
        return Ok(());
    }
    Err(crate::error::Error::option(
        "--screen",
        format!(
            "must be ≥ 1 (inf runs every candidate), got {}",
            crate::error::num(factor)
        ),
    ))
}

/// A candidate's modelled cost over the step grid.
#[derive(Debug, Clone)]
pub(super) struct Priced {
    /// Method name.
    pub name: String,
    /// Modelled seconds per simulated second of a run at each grid step (the grid's order);
    /// 0 where the probe could not run (the run itself then reports why).
    pub per_second: Vec<f64>,
    /// The step of its floor (s).
    pub floor_dt: f64,
    /// Its least possible modelled cost per simulated second: at `floor_dt`.
    pub floor: f64,
    /// True when `floor_dt` is set by its stability limit: its floor is near what it will
    /// cost, which is why such candidates are verified first.
    pub bounded: bool,
}

impl Priced {
    /// Whether grid step `k` runs under a screen at `limit` (s/s; None: no screen yet).
    pub fn runs_at(&self, k: usize, limit: Option<f64>) -> bool {
        limit.is_none_or(|l| self.per_second[k] <= l)
    }
}

/// Prices every candidate of `names` on `grid` ((step, steps) ascending in the step): each
/// one's modelled seconds per step probed at every grid step, and its floor.
pub(super) fn price(
    (scene, sys): (&Scenario, &System),
    cfg: &AdviseConfig,
    names: &[String],
    grid: &[(f64, u64)],
) -> Result<Vec<Priced>> {
    let s0 = scene.initial_state();
    let limits = crate::measure::stability::theory_limits(
        &cfg.common.registry,
        &cfg.common.options,
        sys,
        &s0,
        names,
    )?;
    let jobs: Vec<(usize, usize)> = (0..names.len())
        .flat_map(|i| (0..grid.len()).map(move |k| (i, k)))
        .collect();
    let per_step: Vec<f64> = jobs
        .par_iter()
        .map(|&(i, k)| {
            let (dt, steps) = grid[k];
            seconds_per_step(
                sys,
                &s0,
                &cfg.common.registry,
                &cfg.common.options,
                &names[i],
                dt,
                steps,
            )
            .unwrap_or(0.0)
        })
        .collect();
    let dt_max = grid.last().map_or(0.0, |g| g.0);
    Ok(names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let row = &per_step[i * grid.len()..(i + 1) * grid.len()];
            let per_second: Vec<f64> = row.iter().zip(grid).map(|(p, g)| p / g.0).collect();
            let limit = limits[i].map(|h| STABILITY_SLACK * h);
            let floor_dt = limit.map_or(dt_max, |l| l.min(dt_max));
            // Priced per step as at the largest grid step within it (the finest, when none is).
            let k = grid.iter().rposition(|g| g.0 <= floor_dt).unwrap_or(0);
            Priced {
                name: name.clone(),
                floor: row[k] / floor_dt,
                floor_dt,
                bounded: limit.is_some_and(|l| l < dt_max),
                per_second,
            }
        })
        .collect())
}

/// The answer a screen is held to: the cheapest verified answer, or, where waves are verified
/// together (`waves`), the cheapest grid run that met the bound.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Basis {
    /// Method name.
    pub method: String,
    /// Its run's modelled seconds per simulated second (s/s).
    pub modelled_per_second: f64,
    /// Its run's step (s).
    pub dt: f64,
    /// True for a grid run that met tolerance / safety, false for a verified answer.
    pub grid_run: bool,
}

impl Basis {
    /// The basis of method `name`'s run `c`.
    pub(super) fn of(name: &str, c: &CaseResult, grid_run: bool) -> Self {
        Basis {
            method: name.to_string(),
            modelled_per_second: c.modelled_seconds / (c.dt * c.steps as f64),
            dt: c.dt,
            grid_run,
        }
    }

    /// The cheaper of `a` and `b` (`a` on a tie: the earlier in the order of the work).
    pub(super) fn cheaper(a: Option<Basis>, b: Basis) -> Option<Basis> {
        match a {
            Some(a) if a.modelled_per_second <= b.modelled_per_second => Some(a),
            _ => Some(b),
        }
    }

    /// "rk4's verified answer", or "rk4's run at dt = … s, which met the bound on the grid".
    fn words(&self) -> String {
        if self.grid_run {
            format!(
                "{}'s run at dt = {} s, which met the bound on the grid",
                self.method,
                sig3(self.dt)
            )
        } else {
            format!("{}'s verified answer", self.method)
        }
    }
}

/// A candidate advice did not run, or did not run below a step, because it models far above
/// a verified answer ([`SCREEN_FACTOR`]).
#[derive(Debug, Clone, Serialize)]
pub struct Screened {
    /// Method name.
    pub method: String,
    /// The finest step it was run at (s); None: not run at all.
    pub finest_run: Option<f64>,
    /// The modelled cost that put it over the screen (s/s): its floor when not run, else its
    /// cost at the next grid step below `finest_run`.
    pub modelled_per_second: f64,
    /// The step that cost is at (s).
    pub dt: f64,
    /// The answer it was held to.
    pub basis: Basis,
    /// In words, with the figures.
    pub reason: String,
}

impl Screened {
    /// A candidate whose grid runs (`errors`: step and error, finest first) missed `target`
    /// (tolerance / safety) at its finest step run, finer grid steps left out for costing
    /// more than `factor` times `basis`; None when no finer step was left out (it is unable,
    /// not screened).
    pub(super) fn missed(
        p: &Priced,
        grid: &[(f64, u64)],
        errors: &[(f64, Option<f64>)],
        (basis, factor): (&Basis, f64),
        target: f64,
    ) -> Option<Self> {
        let Some(&(finest, error)) = errors.first() else {
            return Some(Self::no_step_within(p, grid, basis));
        };
        // The next finer grid step, left out for its cost.
        let (k, g) = grid.iter().enumerate().rfind(|(_, g)| g.0 < finest)?;
        let words = match error {
            Some(e) => format!(
                "its error at the finest step run is {}, above tolerance/safety {}",
                significant(e, 4),
                significant(target, 4)
            ),
            None => "it is unstable at the finest step run".to_string(),
        };
        Some(Self::not_run_below(
            &p.name,
            finest,
            (g.0, p.per_second[k]),
            (basis, factor),
            &words,
        ))
    }

    /// A candidate not run: its floor is above the screen.
    pub(super) fn not_run(p: &Priced, basis: &Basis) -> Self {
        let how = if p.bounded {
            format!(
                "at best, at {}× its stability limit",
                crate::error::num(STABILITY_SLACK)
            )
        } else {
            "at best, at the grid's largest step".to_string()
        };
        Self::not_run_at(&p.name, (p.floor, p.floor_dt), &how, basis)
    }

    /// A candidate none of whose grid steps is within the screen: not run, named with its
    /// cheapest grid step's cost.
    fn no_step_within(p: &Priced, grid: &[(f64, u64)], basis: &Basis) -> Self {
        let (k, cost) = p
            .per_second
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, p.floor));
        let dt = grid.get(k).map_or(p.floor_dt, |g| g.0);
        Self::not_run_at(&p.name, (cost, dt), "at its cheapest grid step", basis)
    }

    fn not_run_at(name: &str, (cost, dt): (f64, f64), how: &str, basis: &Basis) -> Self {
        Screened {
            method: name.to_string(),
            finest_run: None,
            modelled_per_second: cost,
            dt,
            basis: basis.clone(),
            reason: format!(
                "not run: at least {}× the cost of {} (modelled {} s per simulated second {how}, dt = {} s, vs {})",
                sig3(cost / basis.modelled_per_second),
                basis.words(),
                sig3(cost),
                sig3(dt),
                sig3(basis.modelled_per_second),
            ),
        }
    }

    /// A candidate whose steps down to `finest` (s) ran without meeting the bound, the next
    /// finer grid step `next` (s) modelled at `cost` (s/s) above `factor` times the basis;
    /// `errors` says how the finest step run missed.
    fn not_run_below(
        name: &str,
        finest: f64,
        (next, cost): (f64, f64),
        (basis, factor): (&Basis, f64),
        errors: &str,
    ) -> Self {
        Screened {
            method: name.to_string(),
            finest_run: Some(finest),
            modelled_per_second: cost,
            dt: next,
            basis: basis.clone(),
            reason: format!(
                "not run below {} s: finer steps model above {}× the cost of {} (modelled {} s per simulated second at dt = {} s vs {}); {errors}",
                sig3(finest),
                crate::error::num(factor),
                basis.words(),
                sig3(cost),
                sig3(next),
                sig3(basis.modelled_per_second),
            ),
        }
    }
}
