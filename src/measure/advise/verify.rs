//! Verification: each predicted step re-run against a reference sampled on its own steps; the
//! verification run is the judgment (the last passing grid run stands in when it misses the
//! bound).

use super::config::AdviseConfig;
use super::search::{run_grids, Decided, Prediction};
use crate::error::Result;
use crate::measure::case::{CaseResult, CaseSettings};
use crate::measure::grid::TimeGrid;
use crate::model::System;
use crate::scenario::Scenario;

/// What advice runs on: the scene, its system, the options, the run settings and the horizon
/// (s).
pub(super) struct Ctx<'a> {
    pub scene: &'a Scenario,
    pub sys: &'a System,
    pub cfg: &'a AdviseConfig,
    pub set: &'a CaseSettings,
    pub horizon: f64,
}

/// One candidate's verified answer.
#[derive(Debug, Clone)]
pub(super) struct Answer {
    /// Method name.
    pub name: String,
    /// The chosen run: the verification run when it met the bound, else the last passing
    /// grid run.
    pub chosen: CaseResult,
    /// The chosen run's predicted error.
    pub predicted: f64,
}

/// Verifies `preds`: re-runs each at its predicted step against a reference of those steps;
/// the chosen run is the verification run when it meets the bound, else the last passing
/// grid run.
pub(super) fn verify(
    ctx: &Ctx,
    preds: &[Prediction],
    decided: &mut Decided,
    label: &str,
) -> Result<Vec<Answer>> {
    if preds.is_empty() {
        return Ok(Vec::new());
    }
    let jobs: Vec<(String, TimeGrid)> = preds.iter().map(|p| (p.0.clone(), p.1)).collect();
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
    Ok(preds
        .iter()
        .enumerate()
        .map(|(pi, (name, _, pred, fallback))| {
            let (chosen, predicted) = match judge.error(&res[pi]) {
                Some(e) if e <= judge.bound => (res[pi].clone(), *pred),
                _ => (fallback.clone(), judge.error(fallback).unwrap_or(0.0)),
            };
            Answer {
                name: name.clone(),
                chosen,
                predicted,
            }
        })
        .collect())
}
