//! Verification: each predicted step re-run against a reference sampled on its own steps, with
//! the frame-rate view's runs of the same candidates; the verification run is the judgment
//! (the last passing grid run stands in when it misses the bound).

use super::config::AdviseConfig;
use super::frames::FramePlan;
use super::search::{run_grids, Decided, Prediction};
use crate::error::Result;
use crate::measure::case::{CaseResult, CaseSettings};
use crate::measure::grid::TimeGrid;
use crate::model::System;
use crate::scenario::Scenario;

/// What advice runs on: the scene, its system, the options, the run settings, the horizon (s)
/// and the frame rates of the game view (Hz).
pub(super) struct Ctx<'a> {
    pub scene: &'a Scenario,
    pub sys: &'a System,
    pub cfg: &'a AdviseConfig,
    pub set: &'a CaseSettings,
    pub horizon: f64,
    pub rates: &'a [f64],
}

/// One candidate's verified answer.
#[derive(Debug, Clone)]
pub(super) struct Answer {
    /// Method name.
    pub name: String,
    /// The step it was verified at (s): the frame view's substeps come from it.
    pub verify_dt: f64,
    /// The chosen run: the verification run when it met the bound, else the last passing
    /// grid run.
    pub chosen: CaseResult,
    /// The chosen run's predicted error.
    pub predicted: f64,
    /// Per frame rate: the run at one step per frame and the substepped run.
    pub frames: Vec<(CaseResult, CaseResult)>,
}

/// Verifies `preds`: re-runs each at its predicted step (and runs its frame-rate view) against
/// a reference of those steps; the chosen run is the verification run when it meets the
/// bound, else the last passing grid run.
pub(super) fn verify(
    ctx: &Ctx,
    preds: &[Prediction],
    max_samples: u64,
    decided: &mut Decided,
    label: &str,
) -> Result<Vec<Answer>> {
    if preds.is_empty() {
        return Ok(Vec::new());
    }
    let steps: Vec<f64> = preds.iter().map(|p| p.1.dt).collect();
    let plan = FramePlan::new(ctx.horizon, &steps, ctx.rates);
    let jobs: Vec<(String, TimeGrid)> = preds
        .iter()
        .map(|p| (p.0.clone(), p.1))
        .chain(
            plan.grids(max_samples)
                .into_iter()
                .map(|(pi, g)| (preds[pi].0.clone(), g)),
        )
        .collect();
    let (_, res) = run_grids(
        ctx.scene,
        ctx.cfg,
        &jobs,
        (ctx.horizon, ctx.set),
        decided,
        label,
    )?;
    let judge = decided
        .judge
        .as_ref()
        .expect("decided by the first reference");
    let np = preds.len();
    Ok(preds
        .iter()
        .enumerate()
        .map(|(pi, (name, g, pred, fallback))| {
            let (chosen, predicted) = match judge.error(&res[pi]) {
                Some(e) if e <= judge.bound => (res[pi].clone(), *pred),
                _ => (fallback.clone(), judge.error(fallback).unwrap_or(0.0)),
            };
            Answer {
                name: name.clone(),
                verify_dt: g.dt,
                chosen,
                predicted,
                frames: (0..ctx.rates.len())
                    .map(|fi| {
                        let k = np + 2 * (fi * np + pi);
                        (res[k].clone(), res[k + 1].clone())
                    })
                    .collect(),
            }
        })
        .collect())
}
