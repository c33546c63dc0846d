//! What `small-steps` may run: every split within the step limit, and all of them with the
//! reference within the time budget, checked before anything runs.
//!
//! A split of budget n runs n substeps (or n iterations) in every frame, so its work grows
//! linearly in n: each split is priced at n = 1 and n = 2 over a few frames (counted work,
//! [`crate::run::cost`]), and a budget's price per frame is the line through them. The
//! reference is projected from the scene ([`super::reference::cost`]).

use super::probe::{check_budget, sig3};
use crate::error::{num, Error, Result};
use crate::integrate::Xpbd;
use crate::measure::grid::TimeGrid;
use crate::method::Registry;
use crate::model::{State, System};
use crate::run::{run_with, NoObserver, RunPlan};
use crate::scenario::MAX_STEPS;

/// Frames each split is priced over (fewer when the run is shorter).
pub const PRICE_FRAMES: u64 = 4;

/// Refuses a budget n whose substeps (or sweeps) over `frames` frames of `frame_dt` pass the
/// step limit, naming `--budgets`, as `run` refuses a run of too many steps.
pub fn check_steps(budgets: &[usize], frames: u64, frame_dt: f64) -> Result<()> {
    for &n in budgets {
        let total = frames as f64 * n as f64;
        if total > MAX_STEPS as f64 {
            return Err(Error::option(
                "--budgets",
                format!(
                    "n = {n} over {frames} frames of {} s (--dt, --duration) is {} substeps (or sweeps), above the limit of {}",
                    num(frame_dt),
                    num(total),
                    num(MAX_STEPS as f64)
                ),
            ));
        }
    }
    Ok(())
}

/// Modelled seconds per frame of xpbd with `substeps` × `iterations` per frame at `frame_dt`.
fn per_frame(sys: &System, s0: &State, frame_dt: f64, frames: u64, split: (usize, usize)) -> f64 {
    let mut stepper = Xpbd::new(split.0, split.1);
    let probe = frames.clamp(1, PRICE_FRAMES);
    let registry = Registry::builtin();
    let Ok(facts) = registry.info(super::small_steps::XPBD) else {
        return 0.0;
    };
    run_with(
        sys,
        &mut stepper,
        facts,
        s0.clone(),
        &RunPlan::new(frame_dt, probe),
        &mut NoObserver,
    )
    .map_or(0.0, |o| o.modelled_seconds / probe as f64)
}

/// The projected modelled seconds of both splits of every budget n over `frames` frames.
pub fn runs_seconds(
    sys: &System,
    s0: &State,
    frame_dt: f64,
    frames: u64,
    budgets: &[usize],
) -> f64 {
    // Both lines start from the same run, one substep of one iteration: probed once.
    let one = per_frame(sys, s0, frame_dt, frames, (1, 1));
    let line = |split: fn(usize) -> (usize, usize)| {
        let two = per_frame(sys, s0, frame_dt, frames, split(2));
        (one, (two - one).max(0.0))
    };
    let sub = line(|n| (n, 1));
    let it = line(|n| (1, n));
    budgets
        .iter()
        .map(|&n| {
            let k = (n - 1) as f64;
            frames as f64 * ((sub.0 + k * sub.1) + (it.0 + k * it.1))
        })
        .sum()
}

/// Checks the whole comparison on one scene against `budget` (s): refuses at once, naming the
/// figures and `--budget`, when the reference and the runs together would pass it; else returns
/// the modelled seconds the reference may spend (the budget less the runs).
pub fn check(
    sys: &System,
    s0: &State,
    grid: &TimeGrid,
    budgets: &[usize],
    budget: f64,
) -> Result<f64> {
    check_budget(budget)?;
    let horizon = grid.time(grid.steps);
    let reference = super::reference::cost::project(sys, s0, &[*grid], horizon);
    let runs = runs_seconds(sys, s0, grid.dt, grid.steps, budgets);
    if reference.seconds + runs > budget {
        return Err(Error::option(
            "--budget",
            format!(
                "the comparison would take about {} s of modelled work ({} s for the xpbd runs of every budget n, {} s for {}), beyond the budget of {} s; give a larger --budget, fewer --budgets, a longer --dt or a shorter --duration",
                sig3(reference.seconds + runs),
                sig3(runs),
                sig3(reference.seconds),
                reference.what,
                sig3(budget)
            ),
        ));
    }
    Ok(budget - runs)
}
