//! `summary.json`: per method, the observed order at the small-step end (or why there
//! is none), computed from the rows only so a merged sweep summarises exactly as the
//! unsharded one.

use super::extend::{method_fit, next_step, Run, Stop};
use super::plan::theoretical_order;
use super::plan::GridRule;
use super::SweepResult;
use crate::measure::fit::OrderFit;
use crate::measure::reference::ReferenceInfo;
use serde::Serialize;

/// Per-method summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodSummary {
    /// Method name.
    pub method: String,
    /// Order the method is designed to have (None for exact or engine methods).
    pub theoretical_order: Option<u32>,
    /// Points that ran to the end.
    pub stable_points: usize,
    /// Points that blew up.
    pub unstable_points: usize,
    /// Observed order (least-squares slope of log error_max vs log dt over the asymptotic
    /// window at the small-step end); None with the reason in `fit`.
    pub observed_order: Option<f64>,
    /// The fit: quality, range used and what was excluded.
    pub fit: OrderFit,
    /// Smallest step the method ran (s).
    pub finest_dt: f64,
    /// Particle-steps the method ran (steps × particles over its runs).
    pub particle_steps: f64,
    /// Why the method ran no smaller step.
    pub extension_stop: Stop,
}

/// `summary.json` of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSummary {
    /// The command that re-creates this document (`--out DIR` is added where it is written).
    pub command: String,
    /// Scenario name.
    pub scenario: String,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Simulated time (s).
    pub duration: f64,
    /// Every step some method ran (s), ascending.
    pub dts: Vec<f64>,
    /// How the grid was chosen, the extension switch and the cost cap.
    pub grid_rule: GridRule,
    /// Which error the orders are fitted to.
    pub order_metric: String,
    /// Saturation bound (m).
    pub saturation: f64,
    /// Per method.
    pub methods: Vec<MethodSummary>,
    /// Methods that do not apply, with the reason.
    pub skipped: Vec<(String, String)>,
    /// The time budget and what it allowed each method, when one was set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<super::budget::SweepBudget>,
}

/// The summary of a full (unsharded or merged) sweep, computed from its rows only.
pub fn summarise(res: &SweepResult) -> SweepSummary {
    let plan = &res.plan;
    let p = plan.dts.len();
    let methods = plan
        .methods
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let runs: Vec<Run> = res
                .rows
                .iter()
                .zip(&res.case_indices)
                .filter(|(_, &k)| k / p == i)
                .map(|(r, &k)| r.run(k % p))
                .collect();
            let mut fit = method_fit(plan, &res.floors, res.saturation, name, &runs);
            let stop = next_step(plan, &res.floors, res.saturation, name, &runs)
                .err()
                .unwrap_or(Stop::Incomplete);
            if fit.observed_order.is_none() {
                let why = stop.describe(plan, name);
                fit.note = Some(match fit.note.take() {
                    Some(n) => format!("{n}; refinement stopped: {why}"),
                    None => why,
                });
            }
            MethodSummary {
                method: name.clone(),
                theoretical_order: theoretical_order(&res.plan, name),
                stable_points: runs.iter().filter(|r| r.ok).count(),
                unstable_points: runs.iter().filter(|r| !r.ok).count(),
                observed_order: fit.observed_order,
                fit,
                finest_dt: runs
                    .iter()
                    .map(|r| plan.dts[r.j])
                    .fold(f64::INFINITY, f64::min),
                particle_steps: runs.iter().map(|r| plan.cost(r.j)).sum(),
                extension_stop: stop,
            }
        })
        .collect();
    let mut used: Vec<usize> = res.case_indices.iter().map(|k| k % p).collect();
    used.sort_unstable();
    used.dedup();
    SweepSummary {
        command: res.plan.command.clone(),
        scenario: plan.scenario.clone(),
        reference: res.reference.clone(),
        duration: plan.duration,
        dts: used.iter().map(|&j| plan.dts[j]).collect(),
        grid_rule: plan.rule.clone(),
        order_metric: "error_max".into(),
        saturation: res.saturation,
        methods,
        skipped: plan.skipped.clone(),
        budget: plan.budget.clone(),
    }
}
