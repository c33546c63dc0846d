//! The extension rule: after the base grid, which step a method runs next, or why it stops.
//!
//! One function decides, from the method's own rows only, both during the sweep (to pick the
//! next run) and in the summary (to state why the method stopped), so a merged sweep states
//! exactly what the unsharded one did.

use super::plan::theoretical_order;
use super::plan::SweepPlan;
use crate::measure::fit::{fit_order, OrderFit};
use serde::{Deserialize, Serialize};

/// Why a method ran no smaller step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The small-step end is asymptotic: the order fit succeeded.
    Asymptotic,
    /// The finest run's error is at the reference's floor: smaller steps measure nothing.
    Floor,
    /// The next halving would take the method's particle-steps over the cost cap.
    CostCap,
    /// The next halving would pass the step limit or the most extension points.
    StepLimit,
    /// The error of the finest step is not below half the error three refinements coarser (all
    /// four stable and above the floor): refining does not converge at an affordable cost
    /// (e.g. saturated errors of a chaotic scene, or a reference that misses the physics).
    NotConverging,
    /// The grid was fixed by the user (`--dt-min` without `--extend`): no extension.
    FixedGrid,
    /// The rows end before the rule says they should (a hand-edited or truncated sweep).
    Incomplete,
    /// The sweep's time budget allows no smaller step for this method.
    Budget,
}

impl Stop {
    /// A sentence for notes and the terminal.
    pub fn describe(&self, plan: &SweepPlan, name: &str) -> String {
        match self {
            Stop::Budget => match plan.budget.as_ref().and_then(|b| Some((b, b.of(name)?))) {
                Some((b, m)) => b.sentence(m),
                None => "the sweep's time budget".into(),
            },
            Stop::Asymptotic => "asymptotic range reached".into(),
            Stop::Floor => "the finest step's error is at the reference floor".into(),
            Stop::CostCap => format!(
                "cost cap of {} particle-steps per method reached",
                crate::error::num(plan.rule.cost_cap_particle_steps)
            ),
            Stop::StepLimit => "no smaller step allowed (step limit)".into(),
            Stop::NotConverging => format!(
                "the error fell by less than {STALL_FACTOR}× over the last three refinements (not converging)"
            ),
            Stop::FixedGrid => "grid fixed by --dt-min (no extension)".into(),
            Stop::Incomplete => "the sweep's rows end before the extension rule".into(),
        }
    }
}

/// Refinement stops when the finest error is above 1/STALL_FACTOR of the error three refinements coarser.
pub const STALL_FACTOR: f64 = 2.0;

/// One run of a method as the rule sees it: grid index, max error, stable.
#[derive(Debug, Clone, Copy)]
pub struct Run {
    /// Index of the step in the plan's `dts`.
    pub j: usize,
    /// Max position error (m), None when unstable.
    pub error: Option<f64>,
    /// True when the run finished.
    pub ok: bool,
}

/// The order fit of `name` over its runs: the one place the fit's inputs are built.
pub fn method_fit(
    plan: &SweepPlan,
    floors: &[f64],
    saturation: f64,
    name: &str,
    runs: &[Run],
) -> OrderFit {
    let pts: Vec<(f64, f64, bool, f64)> = runs
        .iter()
        .map(|r| {
            (
                plan.dts[r.j],
                r.error.unwrap_or(f64::INFINITY),
                r.ok,
                floors[r.j],
            )
        })
        .collect();
    fit_order(
        &pts,
        saturation,
        theoretical_order(plan, name).map(f64::from),
    )
}

/// The next step for `name` to run (`Ok(j)`), or why it stops.
pub fn next_step(
    plan: &SweepPlan,
    floors: &[f64],
    saturation: f64,
    name: &str,
    runs: &[Run],
) -> Result<usize, Stop> {
    let Some(finest) = runs.iter().min_by_key(|r| r.j) else {
        return Err(Stop::Incomplete);
    };
    if (plan.base_start(name)..plan.dts.len()).any(|j| !runs.iter().any(|r| r.j == j)) {
        return Err(Stop::Incomplete);
    }
    if method_fit(plan, floors, saturation, name, runs)
        .observed_order
        .is_some()
    {
        return Err(Stop::Asymptotic);
    }
    if finest.ok && finest.error.is_some_and(|e| e <= floors[finest.j]) {
        return Err(Stop::Floor);
    }
    let mut by_j: Vec<&Run> = runs.iter().collect();
    by_j.sort_by_key(|r| r.j);
    if let [a, b, c, d, ..] = by_j[..] {
        let err = |r: &Run| r.error.filter(|_| r.ok);
        if let (Some(ea), Some(_), Some(_), Some(ed)) = (err(a), err(b), err(c), err(d)) {
            if ea * STALL_FACTOR > ed {
                return Err(Stop::NotConverging);
            }
        }
    }
    if finest.j <= plan.finest(name) && finest.j > 0 {
        return Err(Stop::Budget);
    }
    if !plan.rule.extend {
        return Err(Stop::FixedGrid);
    }
    if finest.j == 0 {
        let spent: f64 = runs.iter().map(|r| plan.cost(r.j)).sum();
        let next = 2.0 * plan.cost(0);
        return Err(if spent + next > plan.rule.cost_cap_particle_steps {
            Stop::CostCap
        } else {
            Stop::StepLimit
        });
    }
    Ok(finest.j - 1)
}
