//! A method's modelled cost per step ([`crate::run::cost`]), counted over a few steps before a
//! command commits to its runs (or priced from the scene alone, for an engine): the figure the
//! budgets of `sweep`, `compare`, `stability`, `advise`, `framerate` and the study's engine
//! choices project their costs from. It is counted work, not a clock, so every budget decides
//! the same on every re-run; whatever it decides is stated with the figure.

use crate::method::MethodOptions;
use crate::method::Registry;
use crate::model::{State, System};

/// Default time budget of the commands that have one (`sweep`, `compare`, …): modelled
/// seconds of runs ([`crate::run::cost`]), summed over methods and steps (one thread's worth).
pub const DEFAULT_BUDGET_SECONDS: f64 = 120.0;

/// Steps of a probe.
pub const PROBE_STEPS: u64 = 40;

/// Modelled seconds per step of method `name` at step `dt`: its
/// [`Stepper::modelled_frame_seconds`](crate::integrate::Stepper::modelled_frame_seconds)
/// where it has one (an engine's frame, its `options.substeps` solver substeps included), else
/// the work counted over at most `steps` (capped at [`PROBE_STEPS`]) steps from `s0`; `None`
/// when the method cannot be made or run on the scene (the command's own run then reports
/// why). The price of one frame of one step: [`seconds_per_frame`] without substeps.
pub fn seconds_per_step(
    sys: &System,
    s0: &State,
    registry: &Registry,
    options: &MethodOptions,
    name: &str,
    dt: f64,
    steps: u64,
) -> Option<f64> {
    let framing = Framing {
        dt,
        frames: steps,
        substeps: None,
    };
    seconds_per_frame(sys, s0, registry, options, name, framing)
}

/// How a run is framed: the frame step, the number of frames and the substeps each frame is
/// split into. Bundled because a frame's price depends on all three together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Framing {
    /// Frame step (s).
    pub dt: f64,
    /// Frames of the run.
    pub frames: u64,
    /// Substeps per frame (None: one step per frame, and the options' engine substeps).
    pub substeps: Option<u64>,
}

/// Modelled seconds per frame of method `name` in a run `framing`: its frames of `dt`, each
/// split into `substeps` the way the run splits it ([`crate::measure::case::frame_setup`]): a native
/// method's `substeps` steps of `dt / substeps`, counted over about [`PROBE_STEPS`] of them; an
/// engine's one frame with that many solver substeps, priced by its cost model (and the
/// runner's step, [`crate::run::cost::CostModel`], as the run books it). Either way the
/// frame's substeps are inside the price, so a run of F frames projects to F times it: the
/// figure the run then books. `None` as for [`seconds_per_step`].
pub fn seconds_per_frame(
    sys: &System,
    s0: &State,
    registry: &Registry,
    options: &MethodOptions,
    name: &str,
    framing: Framing,
) -> Option<f64> {
    let Framing {
        dt,
        frames,
        substeps,
    } = framing;
    let n = substeps.unwrap_or(1).max(1);
    let mut options = options.clone();
    if substeps.is_some() {
        options.substeps = n as usize;
    }
    let mut stepper = registry.create(name, &options).ok()?;
    stepper.check(sys).ok()?;
    if let Some(frame) = stepper.modelled_frame_seconds(sys) {
        // The runner books its own step on top of the engine's frame (one per frame).
        let step = crate::run::cost::Work {
            steps: 1,
            ..Default::default()
        };
        return Some(frame + crate::run::cost::CostModel::of(sys).seconds(&step));
    }
    let probe_frames = (PROBE_STEPS / n).max(1).min(frames.max(1));
    let mut plan = crate::run::RunPlan::new(dt, probe_frames);
    plan.substeps = n;
    let out = crate::run::run(
        sys,
        &mut stepper,
        s0.clone(),
        &plan,
        &mut crate::run::NoObserver,
    )
    .ok()?;
    (out.steps_done > 0).then(|| out.modelled_seconds / out.steps_done as f64)
}

/// Refuses a budget that is not a positive number of seconds, naming `--budget`.
pub fn check_budget(budget: f64) -> crate::error::Result<()> {
    if budget.is_finite() && budget > 0.0 {
        return Ok(());
    }
    Err(crate::error::Error::option(
        "--budget",
        format!(
            "{} (must be a positive number of seconds)",
            crate::error::num(budget)
        ),
    ))
}

/// Which of the projected costs (s) fit `budget` together, taken cheapest first: the fill
/// that keeps the most runs. Ties keep their order.
pub fn cheapest_within(projected: &[f64], budget: f64) -> Vec<bool> {
    let mut order: Vec<usize> = (0..projected.len()).collect();
    order.sort_by(|&a, &b| projected[a].total_cmp(&projected[b]));
    let mut spent = 0.0;
    let mut keep = vec![false; projected.len()];
    for i in order {
        if spent + projected[i] <= budget {
            spent += projected[i];
            keep[i] = true;
        }
    }
    keep
}

/// A method's probed cost: modelled seconds per unit (a step, or a substep) and the projected
/// modelled seconds of the runs a command would make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cost {
    /// Modelled seconds per unit.
    pub per_unit: f64,
    /// Projected modelled seconds of the command's runs of it.
    pub projected: f64,
}

/// Splits `names` (with their `costs`) into those that fit `budget` together, cheapest first
/// ([`cheapest_within`]), in their order, and the rest, each with why: "left out: WHAT would
/// take about … s (… ms per UNIT by the cost model), beyond what the budget of … s leaves".
/// The one rule every command's budget applies; the sweep's water-filling refines it per step.
pub fn split_by_budget(
    names: Vec<String>,
    costs: &[Cost],
    budget: f64,
    what: &str,
    unit: &str,
) -> (Vec<String>, Vec<(String, String)>) {
    let keep = cheapest_within(
        &costs.iter().map(|c| c.projected).collect::<Vec<_>>(),
        budget,
    );
    let (mut kept, mut left) = (Vec::new(), Vec::new());
    for ((n, c), k) in names.into_iter().zip(costs).zip(keep) {
        if k {
            kept.push(n);
        } else {
            let why = format!(
                "left out: {what} would take about {} s ({} ms per {unit} by the cost model), beyond what the budget of {} s leaves; `--budget` raises it",
                sig3(c.projected),
                sig3(c.per_unit * 1e3),
                sig3(budget)
            );
            left.push((n, why));
        }
    }
    (kept, left)
}

/// A measured figure with three significant digits ([`crate::error::significant`], the
/// tables' rule), as budget notes print their figures.
pub fn sig3(x: f64) -> String {
    crate::error::significant(x, 3)
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the greedy fill by hand: costs 5, 1, 3 in a budget of 4 keep 1 and 3.
    #[test]
    fn the_cheapest_runs_that_fit_are_kept() {
        assert_eq!(cheapest_within(&[5.0, 1.0, 3.0], 4.0), [false, true, true]);
        assert_eq!(cheapest_within(&[5.0, 1.0, 3.0], 9.0), [true, true, true]);
        assert!(check_budget(0.0).is_err() && check_budget(f64::NAN).is_err());
        assert!(check_budget(1e-9).is_ok());
    }

    // Oracle: three significant digits by hand (zero prints as the tables print it).
    #[test]
    fn figures_have_three_significant_digits() {
        assert_eq!(sig3(1.4836), "1.48");
        assert_eq!(sig3(0.011628), "0.0116");
        assert_eq!(sig3(2706.2), "2706");
        assert_eq!(sig3(180.0), "180");
        assert_eq!(sig3(1e-6), "1.00e-6");
        assert_eq!(sig3(0.0), "0");
    }
}
