//! Timing advice's answers: every chosen run once, interleaved on one thread after all
//! accuracy runs, and the choices that carry those wall times.

use super::cost;
use super::verify::{Answer, Ctx};
use super::Choice;
use crate::error::Result;
use crate::measure::case::{CaseResult, TimedRun};
use crate::measure::tolerance::Judge;

/// The verified `answers` as choices (unranked), each with its repeated timing.
pub(super) fn timed_choices(ctx: &Ctx, answers: &[&Answer], judge: &Judge) -> Result<Vec<Choice>> {
    let (scene, cfg) = (ctx.scene, ctx.cfg);
    let run_of = |c: &CaseResult| TimedRun {
        method: c.method.clone(),
        dt: c.dt,
        steps: c.steps,
        substeps: None,
    };
    let wanted: Vec<(TimedRun, f64)> = answers
        .iter()
        .map(|a| (run_of(&a.chosen), a.chosen.wall_seconds))
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
    answers
        .iter()
        .map(|a| {
            Choice::new(
                &cfg.common.registry,
                &a.chosen,
                a.predicted,
                judge,
                timed.of(&run_of(&a.chosen)),
            )
        })
        .collect()
}
