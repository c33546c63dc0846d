//! Timing advice's answers: every chosen run and each frame rate's best entry, once each,
//! interleaved on one thread after all accuracy runs, and the choices and frame view that
//! carry those wall times.

use super::cost;
use super::frames::{FramePlan, FrameRate};
use super::verify::{Answer, Ctx};
use super::Choice;
use crate::error::Result;
use crate::measure::case::{CaseResult, TimedRun};
use crate::measure::tolerance::Judge;

/// The verified `answers` as choices (unranked) and the frame-rate view, each with its
/// repeated timing.
pub(super) fn timed_view(
    ctx: &Ctx,
    answers: &[&Answer],
    judge: &Judge,
) -> Result<(Vec<Choice>, Vec<FrameRate>)> {
    let (scene, cfg, rates) = (ctx.scene, ctx.cfg, ctx.rates);
    let names: Vec<String> = answers.iter().map(|a| a.name.clone()).collect();
    let plan = FramePlan::new(
        ctx.horizon,
        &answers.iter().map(|a| a.verify_dt).collect::<Vec<_>>(),
        rates,
    );
    let frame_runs: Vec<CaseResult> = (0..rates.len())
        .flat_map(|fi| {
            answers
                .iter()
                .flat_map(move |a| [a.frames[fi].0.clone(), a.frames[fi].1.clone()])
        })
        .collect();
    let mut view = plan.entries(
        &cfg.common.registry,
        &names,
        &frame_runs,
        judge,
        &scene.name,
    )?;
    // Timing: every chosen run and each frame rate's best entry, once each, interleaved on
    // this thread after all accuracy runs.
    let run_of = |c: &CaseResult| TimedRun {
        method: c.method.clone(),
        dt: c.dt,
        steps: c.steps,
        substeps: None,
    };
    let wanted: Vec<(TimedRun, f64)> = answers
        .iter()
        .map(|a| (run_of(&a.chosen), a.chosen.wall_seconds))
        .chain(plan.timed_runs(&view))
        .collect();
    let timed = {
        let _stage = crate::run::progress_stage(
            format!("advise {}: timing", scene.name),
            cfg.common.progress,
        );
        cost::time_once(
            ctx.sys,
            &scene.initial_state(),
            &wanted,
            ctx.set,
            &cfg.timing,
        )?
    };
    let timing_of = |r: &TimedRun| timed.of(r);
    let choices: Vec<Choice> = answers
        .iter()
        .map(|a| {
            Choice::new(
                &cfg.common.registry,
                &a.chosen,
                a.predicted,
                judge,
                timing_of(&run_of(&a.chosen)),
            )
        })
        .collect::<Result<_>>()?;
    plan.apply_timings(&mut view, &timing_of);
    Ok((choices, view))
}
