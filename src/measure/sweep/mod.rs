//! Work-precision sweeps: every method over a grid of steps drawn from the scene's
//! dynamics, refined per method until its error is asymptotic, against one reference; the
//! observed order per method; deterministic sharding.
//!
//! # The default grid
//! - ω_max is the highest natural frequency of the linearised scene (`measure::modes`).
//! - The largest step is [`plan::BEYOND_LIMIT`] × the widest theoretical stability limit
//!   among the swept methods ([`super::stability::theory_limit`]), so the sweep shows where
//!   each explicit method blows up; with no finite limit, hω_max = [`plan::H_OMEGA_MAX`]; never
//!   more than [`plan::MAX_STEP_FRACTION`] of the horizon.
//! - The smallest base step resolves the fastest mode at hω_max = [`plan::H_OMEGA_MIN`]
//!   (about 125 steps per period); the base grid is halving-spaced, between
//!   [`plan::MIN_BASE_POINTS`] and [`plan::MAX_BASE_POINTS`] points (without stiffness:
//!   [`plan::MIN_BASE_POINTS`] halvings below the largest step).
//! - Extension: below the base grid the plan lists halvings of its smallest step while one
//!   method's particle-steps (steps × particles, summed over its runs) stay within the cost
//!   cap ([`plan::DEFAULT_COST_CAP`], `--cost-cap`). After the base grid each method runs the
//!   next halving until its order fit succeeds at the small-step end (asymptotic), its finest
//!   error is at the reference floor, the cap is reached, or the error stopped falling (less
//!   than [`extend::STALL_FACTOR`]× over the last three refinements: saturated, chaotic, or a
//!   reference that misses the physics) ([`extend::next_step`]). The cap counts
//!   particle-steps, not wall time, so it is the same on every machine.
//! - Budget: `springlab sweep` also bounds wall time ([`budget`]): a probe measures each
//!   method's time per step, and where the projected total exceeds the budget the costliest
//!   methods lose their finest steps. That decision depends on the machine, so the plan records
//!   it (the measured costs and each method's finest allowed step) and the summary names it;
//!   it removes runs and never changes one. Library sweeps (the report's) have no budget.
//! - Overrides: `--dt-max`, `--dt-min` and `--points` replace their part of the rule exactly.
//!   Giving `--dt-min` fixes the small end, so no extension runs unless `--extend` asks.
//!
//! # Sharding
//! Case k is method i = k / P at candidate step j = k mod P (P = the plan's candidate
//! steps, ascending). Shard I/N runs every case of the methods with i mod N = I: the
//! extension of a method depends only on that method's own errors, so the shard that owns it
//! decides it alone, exactly as the unsharded sweep does. Every shard computes the reference
//! on every candidate step over the same horizon (the solver takes the same steps; samples
//! come from its dense output), so shards share reference and floors bit for bit. Cases run
//! in parallel (rayon), in rounds (the base grid, then one halving per still-refining method),
//! and are collected in case order, so every output except `wall_seconds` is bit-identical
//! whatever the thread count, and a merge of all shards equals the unsharded sweep. At most
//! one shard per method does work.

pub mod budget;
mod config;
pub mod extend;
pub mod plan;
pub mod shard;
pub mod summary;

pub use config::{Shard, SweepConfig};
pub use extend::Stop;
pub use plan::{plan_sweep, step_grid, theoretical_order, GridRule, SweepPlan, DEFAULT_COST_CAP};
pub use shard::{merge, write_sweep, ShardFile};
pub use summary::{summarise, MethodSummary, SweepSummary};

use super::case::{run_case, CaseResult, CaseSettings};
use super::grid::TimeGrid;
use super::reference::{Reference, ReferenceInfo};
use crate::error::Result;
use crate::scenario::Scenario;
use extend::{next_step, Run};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// One row of `sweep.csv`. Error and energy columns are empty for unstable runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRow {
    /// Method name.
    pub method: String,
    /// Step (s).
    pub dt: f64,
    /// Steps planned.
    pub steps: u64,
    /// Force evaluations.
    pub force_evals: u64,
    /// Modelled seconds of the run ([`crate::run::cost`]).
    pub modelled_seconds: f64,
    /// Stepping wall time (s): the one column that varies between identical runs.
    pub wall_seconds: f64,
    /// Final position error (m).
    pub error_final: Option<f64>,
    /// Max position error (m).
    pub error_max: Option<f64>,
    /// RMS position error (m).
    pub error_rms: Option<f64>,
    /// Relative energy drift (1/s).
    pub energy_drift: Option<f64>,
    /// `ok` or `unstable`.
    pub status: crate::run::RunStatus,
}

/// The CSV header of `sweep.csv`.
pub const SWEEP_HEADER: &str =
    "method,dt,steps,force_evals,modelled_seconds,wall_seconds,error_final,error_max,error_rms,energy_drift,status";

impl SweepRow {
    fn from_case(c: &CaseResult) -> Self {
        SweepRow {
            method: c.method.clone(),
            dt: c.dt,
            steps: c.steps,
            force_evals: c.force_evals,
            modelled_seconds: c.modelled_seconds,
            wall_seconds: c.wall_seconds,
            error_final: c.metric(|m| m.error_final),
            error_max: c.metric(|m| m.error_max),
            error_rms: c.metric(|m| m.error_rms),
            energy_drift: c.metric(|m| m.energy_drift),
            status: c.status,
        }
    }
    fn csv_line(&self) -> String {
        let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
        format!(
            "{},{:e},{},{},{:e},{:e},{},{},{},{},{}",
            self.method,
            self.dt,
            self.steps,
            self.force_evals,
            self.modelled_seconds,
            self.wall_seconds,
            o(self.error_final),
            o(self.error_max),
            o(self.error_rms),
            o(self.energy_drift),
            self.status
        )
    }
    fn run(&self, j: usize) -> Run {
        Run {
            j,
            error: self.error_max,
            ok: self.status.is_ok(),
        }
    }
}

/// A sweep's results: rows (CSV), full case results (for plots) and the summary.
#[derive(Debug, Clone, Serialize)]
pub struct SweepResult {
    /// The plan.
    pub plan: SweepPlan,
    /// Shard run, if any.
    pub shard: Option<Shard>,
    /// Case indices of `rows`, ascending.
    pub case_indices: Vec<usize>,
    /// `sweep.csv` rows.
    pub rows: Vec<SweepRow>,
    /// Full results with every metric (empty after a merge: rows only).
    pub cases: Vec<CaseResult>,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Per-candidate-step error floors (m).
    pub floors: Vec<f64>,
    /// Saturation bound (m).
    pub saturation: f64,
    /// The summary (None for a shard: merge computes it).
    pub summary: Option<SweepSummary>,
}

/// Runs a sweep (or one shard of it): the base grid, then extension rounds.
pub fn run_sweep(scene: &Scenario, cfg: &SweepConfig) -> Result<SweepResult> {
    let mut plan = plan_sweep(scene, cfg)?;
    let sys = scene.build();
    let s0 = scene.initial_state();
    if let (Some(seconds), None) = (cfg.common.budget_seconds, cfg.shard) {
        apply_budget(&mut plan, &sys, &s0, cfg, seconds)?;
    }
    let p = plan.dts.len();
    let owned: Vec<usize> = (0..plan.methods.len())
        .filter(|&i| cfg.shard.is_none_or(|s| s.owns(i)))
        .collect();
    // Every candidate step, whatever this shard runs: shards share the reference exactly.
    let grids: Vec<TimeGrid> = (0..p).map(|j| plan.grid(j)).collect();
    let horizon = grids.iter().map(|g| g.time(g.steps)).fold(0.0, f64::max);
    let reference = Reference::compute(&sys, &s0, &grids, horizon)?;
    let scale = reference.motion_scale();
    let floors: Vec<f64> = plan
        .steps
        .iter()
        .map(|&n| {
            (10.0 * reference.info.accuracy).max(4.0 * f64::EPSILON * scale * (n as f64).sqrt())
        })
        .collect();
    let saturation = 0.1 * scale;
    let set = CaseSettings {
        repeat_short: cfg.repeat_short,
        ..CaseSettings::measuring(
            cfg.common.registry.clone(),
            cfg.common.options.clone(),
            cfg.common.blowup_factor,
        )
    };
    let mut pending: Vec<usize> = owned
        .iter()
        .flat_map(|&i| (plan.base_start(&plan.methods[i])..p).map(move |j| i * p + j))
        .collect();
    let pb = crate::run::progress_bar(
        pending.len() as u64,
        &format!("sweep {}", scene.name),
        cfg.common.progress,
    );
    let mut done: Vec<CaseResult> = Vec::new();
    let mut done_k: Vec<usize> = Vec::new();
    while !pending.is_empty() {
        let round: Vec<Result<CaseResult>> = pending
            .par_iter()
            .map(|&k| {
                let r = run_case(&sys, &s0, &reference, k % p, &plan.methods[k / p], &set);
                pb.inc(1);
                r
            })
            .collect();
        for (k, r) in pending.iter().zip(round) {
            done.push(r?);
            done_k.push(*k);
        }
        pending = owned
            .iter()
            .filter_map(|&i| {
                let runs: Vec<Run> = done
                    .iter()
                    .zip(&done_k)
                    .filter(|(_, &k)| k / p == i)
                    .map(|(c, &k)| SweepRow::from_case(c).run(k % p))
                    .collect();
                next_step(&plan, &floors, saturation, &plan.methods[i], &runs)
                    .ok()
                    .map(|j| i * p + j)
            })
            .collect();
        pb.inc_length(pending.len() as u64);
    }
    pb.finish_and_clear();
    let mut order: Vec<usize> = (0..done.len()).collect();
    order.sort_by_key(|&n| done_k[n]);
    let cases: Vec<CaseResult> = order.iter().map(|&n| done[n].clone()).collect();
    let case_indices: Vec<usize> = order.iter().map(|&n| done_k[n]).collect();
    let mut res = SweepResult {
        shard: cfg.shard,
        case_indices,
        rows: cases.iter().map(SweepRow::from_case).collect(),
        cases,
        reference: reference.info.clone(),
        floors,
        saturation,
        summary: None,
        plan,
    };
    if cfg.shard.is_none() {
        res.summary = Some(summarise(&res));
    }
    Ok(res)
}

/// Probes every method of `plan` and, where the budget cuts, records its allotment in the plan;
/// a method that fits no step moves to `skipped` with the figures (see [`budget`]).
fn apply_budget(
    plan: &mut SweepPlan,
    sys: &crate::model::System,
    s0: &crate::model::State,
    cfg: &SweepConfig,
    seconds: f64,
) -> Result<()> {
    crate::measure::probe::check_budget(seconds)?;
    let j = plan.base_from;
    // A method whose probe fails costs nothing here: its case runs report the failure.
    let per_step: Vec<f64> = plan
        .methods
        .iter()
        .map(|name| {
            crate::measure::probe::seconds_per_step(
                sys,
                s0,
                &cfg.common.registry,
                &cfg.common.options,
                name,
                plan.dts[j],
                plan.steps[j],
            )
            .unwrap_or(0.0)
        })
        .collect();
    let b = budget::SweepBudget::new(&plan.steps, &plan.methods, seconds, &per_step);
    let none = plan.dts.len();
    let (kept, left): (Vec<_>, Vec<_>) = b.methods.iter().cloned().partition(|m| m.finest < none);
    for m in &left {
        let i = plan
            .methods
            .iter()
            .position(|n| *n == m.method)
            .expect("planned");
        plan.methods.remove(i);
        plan.orders.remove(i);
        plan.skipped
            .push((m.method.clone(), format!("left out: {}", b.sentence(m))));
    }
    // Recorded only where it acted: a budget that cut nothing leaves the documents as they
    // would be without it (measured costs vary from run to run).
    if !left.is_empty() || kept.iter().any(|m| m.finest > 0) {
        plan.budget = Some(budget::SweepBudget { methods: kept, ..b });
    }
    Ok(())
}
