//! Advice's search: the candidates, their runs over the step grid against one reference, the
//! predicted step of each, and the grid's extension downwards while nothing meets the bound.

use super::config::AdviseConfig;
use crate::error::{significant, Result};
use crate::measure::case::{run_case, CaseResult, CaseSettings};
use crate::measure::grid::{max_samples_for, TimeGrid, DEFAULT_BUDGET_BYTES};
use crate::measure::reference::{Reference, ReferenceInfo};
use crate::measure::statistics::Ensemble;
use crate::measure::sweep::step_grid;
use crate::measure::tolerance::Judge;
use crate::method::Order;
use crate::model::System;
use crate::scenario::Scenario;
use rayon::prelude::*;

/// What the first reference of an advice decides for the rest: the judge, and the ensemble
/// the statistics metric needs (computed once, shared by the verification's reference).
#[derive(Default)]
pub(super) struct Decided {
    pub(super) judge: Option<Judge>,
    pub(super) ensemble: Option<Ensemble>,
    pub(super) metric_note: Option<String>,
}

/// The reference of `grids` for `scene`; the first call decides the judge (and the ensemble,
/// for the statistics metric) in `decided`, later ones take its ensemble.
pub(super) fn reference_for(
    scene: &Scenario,
    cfg: &AdviseConfig,
    grids: &[TimeGrid],
    horizon: f64,
    decided: &mut Decided,
) -> Result<Reference> {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let stage = crate::run::progress_stage(
        format!("advise {}: reference", scene.name),
        cfg.common.progress,
    );
    let mut reference = Reference::compute(&sys, &s0, grids, horizon)?;
    drop(stage);
    match &decided.judge {
        None => {
            let _stage = crate::run::progress_stage(
                format!("advise {}: judge (tolerance, ensemble)", scene.name),
                cfg.common.progress,
            );
            let (judge, note) = crate::measure::tolerance::decide(
                cfg.metric,
                cfg.tolerance,
                scene,
                &mut reference,
                &sys,
                &s0,
                cfg.ensemble.as_ref(),
            )?;
            decided.ensemble = reference.ensemble.clone();
            decided.metric_note = note;
            decided.judge = Some(judge);
        }
        Some(j) => {
            if let Some(e) = &decided.ensemble {
                reference.use_ensemble(e, j.tolerance.value);
            }
        }
    }
    Ok(reference)
}

/// Runs `jobs` (method, index of its grid in `reference`) against `reference`, in parallel,
/// collected in order; a bar labelled `label` counts them.
pub(super) fn run_on(
    (scene, sys): (&Scenario, &System),
    reference: &Reference,
    jobs: &[(String, usize)],
    set: &CaseSettings,
    (label, progress): (&str, bool),
) -> Result<Vec<CaseResult>> {
    let s0 = scene.initial_state();
    let pb = crate::run::progress_bar(
        jobs.len() as u64,
        &format!("advise {}: {label}", scene.name),
        progress,
    );
    let out: Vec<Result<CaseResult>> = jobs
        .par_iter()
        .map(|(name, g)| {
            let r = run_case(sys, &s0, reference, *g, name, set);
            pb.inc(1);
            r
        })
        .collect();
    pb.finish_and_clear();
    out.into_iter().collect()
}

/// Runs `jobs` (method, grid) against one reference of their grids ([`reference_for`]), with
/// a bar labelled `label`.
pub(super) fn run_grids(
    scene: &Scenario,
    cfg: &AdviseConfig,
    jobs: &[(String, TimeGrid)],
    (horizon, set): (f64, &CaseSettings),
    decided: &mut Decided,
    label: &str,
) -> Result<(ReferenceInfo, Vec<CaseResult>)> {
    let mut grids: Vec<TimeGrid> = Vec::new();
    let idx: Vec<(String, usize)> = jobs
        .iter()
        .map(|(n, g)| match grids.iter().position(|h| h == g) {
            Some(i) => (n.clone(), i),
            None => {
                grids.push(*g);
                (n.clone(), grids.len() - 1)
            }
        })
        .collect();
    let reference = reference_for(scene, cfg, &grids, horizon, decided)?;
    let out = run_on(
        (scene, &scene.build()),
        &reference,
        &idx,
        set,
        (label, cfg.common.progress),
    )?;
    Ok((reference.info, out))
}

/// The methods whose grid runs fit `budget` (s, summed), cheapest first; each projected from
/// its time per step probed at the grid's smallest step, over the grid's steps, doubled for
/// the verification and frame-rate runs that follow. The rest go to `unable` with the figures.
fn within_budget(
    scene: &Scenario,
    cfg: &AdviseConfig,
    names: Vec<String>,
    grid: &[(f64, u64)],
    budget: f64,
    unable: &mut Vec<(String, String)>,
) -> Result<Vec<String>> {
    use crate::measure::probe::{check_budget, seconds_per_step, split_by_budget, Cost};
    check_budget(budget)?;
    let (sys, s0) = (scene.build(), scene.initial_state());
    let Some(&(dt, steps)) = grid.iter().min_by(|a, b| a.0.total_cmp(&b.0)) else {
        return Ok(names);
    };
    let total: f64 = grid.iter().map(|g| g.1 as f64).sum::<f64>() * 2.0;
    let costs: Vec<Cost> = names
        .iter()
        .map(|n| {
            let per = seconds_per_step(
                &sys,
                &s0,
                &cfg.common.registry,
                &cfg.common.options,
                n,
                dt,
                steps,
            )
            .unwrap_or(0.0);
            Cost {
                per_unit: per,
                projected: per * total,
            }
        })
        .collect();
    let (kept, left) = split_by_budget(names, &costs, budget, "its runs", "step");
    unable.extend(left);
    Ok(kept)
}

/// Most times the grid is extended downwards (each time by [`EXTENSION_FACTOR`], or the grid's
/// own span when smaller) when no candidate meets the bound on it; only candidates still
/// converging (ok at the finest step, their smallest error there) go on.
pub const GRID_EXTENSIONS: usize = 2;

/// Largest factor by which one extension lowers the grid's smallest step (or the grid's own
/// span, when smaller).
pub const EXTENSION_FACTOR: f64 = 30.0;

/// Largest run of an extended grid, in particle-steps: a finer grid than this is not tried.
pub const EXTENSION_PARTICLE_STEPS: f64 = 5e7;

/// A candidate's grid runs, ascending in the step.
pub(super) type Row = (String, Vec<CaseResult>);

/// A method advice cannot use, with why.
pub(super) type Unable = (String, String);

/// One candidate's prediction from its grid row: the step, its predicted error and the last
/// passing grid run; or why it cannot meet the bound.
pub(super) type Prediction = (String, TimeGrid, f64, CaseResult);

/// A candidate's prediction from its row of grid runs `row` (ascending in the step, the
/// finest first; a screened row starts at its finest step run): the largest step below which
/// every step run met tolerance / `safety`, refined by log-log interpolation towards the next
/// (failing) step; or, when its finest step misses, the (step, error) of every run.
pub(super) fn predict_row(
    name: &str,
    row: &[CaseResult],
    (horizon, max_samples): (f64, u64),
    judge: &Judge,
    safety: f64,
) -> std::result::Result<Prediction, Vec<(f64, Option<f64>)>> {
    let target = judge.bound / safety;
    let mut last_pass = None;
    for (j, c) in row.iter().enumerate() {
        match judge.error(c) {
            Some(e) if e <= target => last_pass = Some(j),
            _ => break,
        }
    }
    let Some(j) = last_pass else {
        return Err(row.iter().map(|c| (c.dt, judge.error(c))).collect());
    };
    let ej = judge.error(&row[j]).expect("passed");
    let (mut dt, mut pred) = (row[j].dt, ej);
    if let Some(next) = row.get(j + 1) {
        if let Some(en) = judge.error(next) {
            if ej > 0.0 && en > ej {
                let slope = (en / ej).ln() / (next.dt / row[j].dt).ln();
                let d = row[j].dt * (target / ej).powf(1.0 / slope);
                dt = d.clamp(row[j].dt, next.dt);
                pred = ej * (dt / row[j].dt).powf(slope);
            }
        }
    }
    let steps = crate::model::covering_steps(horizon, dt);
    let g = TimeGrid::new(horizon / steps as f64, steps, max_samples);
    Ok((name.to_string(), g, pred, row[j].clone()))
}

/// The methods advice may pick: those that apply (the rest, with why, in the second list),
/// less closed forms unless asked for by name, less those whose runs the budget cannot afford.
pub(super) fn candidates(
    (scene, sys): (&Scenario, &System),
    cfg: &AdviseConfig,
    grid: &[(f64, u64)],
) -> Result<(Vec<String>, Vec<Unable>)> {
    let (mut names, mut unable) = cfg.common.applicable(sys)?;
    if cfg.common.methods.is_empty() {
        // Exact methods are closed forms for special scenes, not general-purpose schemes.
        let exact: Vec<String> = names
            .iter()
            .filter(|n| {
                cfg.common
                    .registry
                    .info(n)
                    .is_ok_and(|m| m.order == Order::Exact)
            })
            .cloned()
            .collect();
        for n in exact {
            names.retain(|m| *m != n);
            unable.push((n, "closed form for this scene only, not a general method (ask for it with --methods to include it)".into()));
        }
    }
    if let Some(b) = cfg.common.budget_seconds {
        names = within_budget(scene, cfg, names, grid, b, &mut unable)?;
    }
    Ok((names, unable))
}

/// What the grid's extension found: the reference of its last grid, the predictions, the
/// methods that cannot meet the bound, every step it tried, and the methods dropped on the
/// way (not converging).
pub(super) struct Extended {
    pub(super) reference: ReferenceInfo,
    pub(super) predictions: Vec<Prediction>,
    pub(super) cant: Vec<Unable>,
    pub(super) tried: Vec<f64>,
    pub(super) dropped: Vec<Unable>,
}

/// Whether a row of runs (ascending in the step) is still converging: ok at its finest step,
/// and its error there the smallest of the row.
pub(super) fn converging(row: &[CaseResult], judge: &Judge) -> bool {
    let errors: Vec<Option<f64>> = row.iter().map(|c| judge.error(c)).collect();
    errors
        .first()
        .copied()
        .flatten()
        .is_some_and(|e0| errors.iter().flatten().all(|&e| e0 <= e))
}

/// The grid below the current one: its finest step, the ratio of its largest step to it,
/// the finest step of the next grid below, and whether runs down to that step stay affordable.
struct Below {
    /// The current grid's finest step (s).
    finest: f64,
    /// The current grid's largest step over its finest.
    span: f64,
    /// The next grid's finest step (s): the span again below, at most [`EXTENSION_FACTOR`].
    next_min: f64,
    /// Whether runs down to `next_min` stay within [`EXTENSION_PARTICLE_STEPS`] and the step
    /// limit.
    affordable: bool,
}

impl Below {
    /// The grid below `grid` for a scene of `particles` particles over `horizon` s.
    fn of(grid: &[(f64, u64)], particles: usize, horizon: f64) -> Below {
        let finest = grid.iter().map(|g| g.0).fold(f64::INFINITY, f64::min);
        let span = grid.iter().map(|g| g.0).fold(0.0, f64::max) / finest;
        let next_min = finest / span.min(EXTENSION_FACTOR);
        let affordable = particles as f64 * horizon / next_min <= EXTENSION_PARTICLE_STEPS
            && crate::scenario::Timing::steps_within("--dt-min", next_min, horizon).is_ok();
        Below {
            finest,
            span,
            next_min,
            affordable,
        }
    }
}

/// The runs of every method in `going` at every grid step of `steps`, method by method.
fn grid_jobs(going: &[String], steps: &[(f64, u64)], max_samples: u64) -> Vec<(String, TimeGrid)> {
    going
        .iter()
        .flat_map(|n| {
            steps
                .iter()
                .map(move |&(dt, s)| (n.clone(), TimeGrid::new(dt, s, max_samples)))
        })
        .collect()
}

/// The prediction of each row of runs `done` over `horizon` s, or why its method cannot meet
/// the bound.
fn predict_rows(
    done: &[Row],
    horizon: f64,
    max_samples: u64,
    judge: &Judge,
    cfg: &AdviseConfig,
) -> (Vec<Prediction>, Vec<Unable>) {
    let (mut predictions, mut missed) = (Vec::new(), Vec::new());
    for (n, row) in done {
        match predict_row(n, row, (horizon, max_samples), judge, cfg.safety) {
            Ok(p) => predictions.push(p),
            Err(errors) => {
                missed.push((n.clone(), unable_reason(&errors, judge.bound, cfg.safety)))
            }
        }
    }
    (predictions, missed)
}

/// When nothing met the bound on `grid` (every candidate's `rows` run in full), extends the
/// grid downwards (at most [`GRID_EXTENSIONS`] times, within [`EXTENSION_PARTICLE_STEPS`]) for
/// the candidates still converging, while nothing is predicted; `cant` holds why each
/// candidate missed on the grid so far. Each extension runs its coarser half first and its
/// finer half (most of its cost) only when the coarser predicts nothing. `None` when the grid
/// is not extended.
pub(super) fn extend(
    (scene, sys): (&Scenario, &System),
    cfg: &AdviseConfig,
    (set, horizon): (&CaseSettings, f64),
    (rows, mut grid): (Vec<Row>, Vec<(f64, u64)>),
    mut cant: Vec<Unable>,
    decided: &mut Decided,
) -> Result<Option<Extended>> {
    let mut dropped = Vec::new();
    let mut tried: Vec<f64> = Vec::new();
    let mut rows = rows;
    let mut reference = None;
    for extensions in 0..=GRID_EXTENSIONS {
        let judge = decided
            .judge
            .clone()
            .expect("decided by the first reference");
        let Below {
            finest,
            span,
            next_min,
            affordable,
        } = Below::of(&grid, sys.len(), horizon);
        let going: Vec<String> = rows
            .iter()
            .filter(|(_, r)| converging(r, &judge))
            .map(|(n, _)| n.clone())
            .collect();
        if going.is_empty()
            || cfg.dt_min.is_some()
            || extensions >= GRID_EXTENSIONS
            || !affordable
            || span.is_nan()
            || span <= 1.0
        {
            return Ok(reference.map(|reference| Extended {
                reference,
                predictions: Vec::new(),
                cant,
                tried,
                dropped,
            }));
        }
        dropped.extend(
            std::mem::take(&mut cant)
                .into_iter()
                .filter(|(n, _)| !going.contains(n)),
        );
        grid = step_grid(next_min, finest, cfg.points.max(2), horizon)
            .into_iter()
            .filter(|g| g.0 < finest)
            .collect();
        let max_samples = max_samples_for(DEFAULT_BUDGET_BYTES, grid.len() * 2, sys.len());
        // The coarser half first: its runs cost a fraction of the finer half's, and a
        // prediction there needs nothing finer (every run below it, down to the finest run,
        // met the bound).
        let half = grid.len() / 2;
        let mut done: Vec<Row> = going.iter().map(|n| (n.clone(), Vec::new())).collect();
        let parts = [(1, grid[half..].to_vec()), (2, grid[..half].to_vec())];
        for (part, steps) in parts {
            if steps.is_empty() {
                continue;
            }
            let jobs = grid_jobs(&going, &steps, max_samples);
            let (info, cases) = run_grids(
                scene,
                cfg,
                &jobs,
                (horizon, set),
                decided,
                &format!("extended grid {}, part {part} of 2", extensions + 1),
            )?;
            reference = Some(info);
            tried.extend(steps.iter().map(|g| g.0));
            for ((_, row), r) in done.iter_mut().zip(cases.chunks(steps.len())) {
                row.splice(0..0, r.iter().cloned());
            }
            let (predictions, missed) = predict_rows(&done, horizon, max_samples, &judge, cfg);
            cant = missed;
            if !predictions.is_empty() {
                return Ok(Some(Extended {
                    reference: reference.expect("just set"),
                    predictions,
                    cant,
                    tried,
                    dropped,
                }));
            }
        }
        rows = done;
    }
    unreachable!("the loop returns by its last extension")
}

/// Why a candidate whose smallest grid step misses tolerance / `safety` gets no advice, in
/// words that agree with its own grid errors (`errors`: (dt, error or None when not ok), from
/// the smallest step up): unstable everywhere; within the tolerance but not its margin; an
/// error that does not fall with the step (a coarser step's error below the target is an
/// aliased sample, not convergence); or above the tolerance at every step.
pub fn unable_reason(errors: &[(f64, Option<f64>)], tolerance: f64, safety: f64) -> String {
    let target = tolerance / safety;
    let Some((best_dt, best)) = errors
        .iter()
        .filter_map(|&(dt, e)| Some((dt, e?)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return "unstable at every step of the grid".into();
    };
    let first = errors
        .first()
        .map_or("unstable".to_string(), |&(dt, e)| match e {
            Some(e) => format!(
                "{} at the smallest step {} s",
                significant(e, 4),
                significant(dt, 5)
            ),
            None => format!("unstable at the smallest step {} s", significant(dt, 5)),
        });
    let (below_target, below_tolerance) = (best <= target, best <= tolerance);
    let (best, best_dt, target, tolerance) = (
        significant(best, 4),
        significant(best_dt, 5),
        significant(target, 4),
        significant(tolerance, 4),
    );
    if below_target {
        format!(
            "its error does not fall with the step on this grid: {first}, above tolerance/safety {target}, while a coarser step reads {best} at {best_dt} s (a sample that happens to be close, not convergence; try a smaller --dt-min)"
        )
    } else if below_tolerance {
        format!(
            "meets the tolerance {tolerance} on the grid (smallest error {best} at {best_dt} s) but not its safety margin: tolerance/safety = {target} (lower --safety, or a smaller --dt-min)"
        )
    } else {
        format!(
            "smallest error on the grid {best} (at {best_dt} s) exceeds the tolerance {tolerance} (try a smaller --dt-min)"
        )
    }
}
