//! The order of advice's work: candidates run in waves, cheapest floor first
//! ([`super::screen`]), each wave's grid runs followed by its verification (and its frame-rate
//! runs), so the cheapest candidates are verified before the dear ones run and the screen can
//! hold those to them. Verifying a wave takes a reference of its steps: where the grid's
//! reference is a kept solve ([`crate::measure::reference::Reference::solve_id`]) or a closed
//! form, that is a resampling, and each wave is verified at once; where it is not (a scene whose solve is too
//! big to keep), each would be a solve of its own, so the waves are verified together after
//! the last one and the screen holds the rest to the cheapest grid run that met the bound
//! (tolerance / safety, against the same reference), which costs no less than its candidate's
//! verified answer.
//!
//! The first wave is the [`FIRST_WAVE`] candidates first in floor order (floors within the
//! ranking's tie band taken highest order of accuracy first) among those whose floor is set by
//! their stability limit (the floor of an unconditionally stable method or an engine, its cost
//! at the grid's largest step, says little about the step it will need), else of all; while
//! nothing is verified, each next wave is the next [`FIRST_WAVE`] by floor, each candidate's
//! grid row run first down to the finest step within the screen factor times its own floor,
//! and the rest of its row only when that predicts nothing. Once an answer is verified, every
//! candidate left whose floor is above the screen factor
//! ([`super::screen::SCREEN_FACTOR`] unless asked otherwise) times the cheapest verified
//! answer's cost is not run, and the rest run in one more wave, each down to the finest grid
//! step within the screen; a candidate predicted before (under its own floor's screen) runs
//! its further steps within it there too, and is verified again should its prediction change.
//! Every grid run is judged against one reference of the whole grid.

use super::config::AdviseConfig;
use super::cost::TIE_BAND;
use super::screen::{Basis, Priced, Screened};
use super::search::{extend, predict_row, reference_for, run_on, unable_reason};
use super::search::{Decided, Prediction, Row, Unable};
use super::verify::{verify, Answer, Ctx};
use crate::error::Result;
use crate::measure::case::CaseResult;
use crate::measure::grid::{max_samples_for, TimeGrid, DEFAULT_BUDGET_BYTES};
use crate::measure::reference::{Reference, ReferenceInfo};
use crate::measure::tolerance::Judge;

/// Candidates in each wave while nothing is verified (1: a grid row's runs already fill the
/// cores, its finest run taking about half its time, so a second candidate would double the
/// work before the screen can cut it without finishing sooner).
pub const FIRST_WAVE: usize = 1;

/// What happened to one candidate.
#[derive(Debug, Clone)]
enum Fate {
    /// Verified.
    Answered(Box<Answer>),
    /// Cannot meet the bound on the grid, with why.
    Unable(String),
    /// Screened out.
    Screened(Box<Screened>),
}

/// What the waves found: the reference of the grid runs, each candidate's fate (candidate
/// order; None for one left for the grid's extension), every step run, and each candidate's
/// grid runs (for the extension).
pub(super) struct Waves {
    reference: ReferenceInfo,
    fates: Vec<Option<Fate>>,
    tried: Vec<f64>,
    rows: Vec<Row>,
}

/// The order candidates are taken in: by floor, the cheapest remaining candidate and every
/// other within [`TIE_BAND`] of it forming a group (as the ranking groups costs), a group
/// ordered by the registry's order of accuracy, highest first (of two methods that cost the
/// same per step, the higher order meets a tolerance at the larger step), then by name.
fn by_floor(priced: &[Priced], orders: &[u32]) -> Vec<usize> {
    let mut rest: Vec<usize> = (0..priced.len()).collect();
    rest.sort_by(|&a, &b| {
        priced[a]
            .floor
            .total_cmp(&priced[b].floor)
            .then_with(|| priced[a].name.cmp(&priced[b].name))
    });
    let mut order = Vec::with_capacity(rest.len());
    while let Some(&lead) = rest.first() {
        let limit = priced[lead].floor * (1.0 + TIE_BAND);
        let (mut group, others): (Vec<usize>, Vec<usize>) =
            rest.iter().partition(|&&i| priced[i].floor <= limit);
        group.sort_by(|&a, &b| {
            orders[b]
                .cmp(&orders[a])
                .then_with(|| priced[a].name.cmp(&priced[b].name))
        });
        order.extend(group);
        rest = others;
    }
    order
}

/// The next wave from `pending` (in floor order): everything left once an answer is
/// verified, else the first [`FIRST_WAVE`] bounded candidates (any, when none is bounded).
fn next_wave(priced: &[Priced], pending: &[usize], verified: bool) -> Vec<usize> {
    if verified {
        return pending.to_vec();
    }
    let bounded: Vec<usize> = pending
        .iter()
        .copied()
        .filter(|&i| priced[i].bounded)
        .take(FIRST_WAVE)
        .collect();
    if bounded.is_empty() {
        pending.iter().copied().take(FIRST_WAVE).collect()
    } else {
        bounded
    }
}

/// What the waves have found so far: each candidate's grid runs (per grid step), its current
/// prediction, and its fate.
struct Found {
    runs: Vec<Vec<Option<CaseResult>>>,
    preds: Vec<Option<Prediction>>,
    fates: Vec<Option<Fate>>,
}

impl Found {
    /// Candidate `i`'s runs, ascending in the step.
    fn row(&self, i: usize) -> Vec<CaseResult> {
        self.runs[i].iter().flatten().cloned().collect()
    }

    /// What the waves found, against the grid's `reference`: the steps run and each
    /// candidate's runs.
    fn into_waves(self, priced: &[Priced], grid: &[(f64, u64)], reference: ReferenceInfo) -> Waves {
        let n = priced.len();
        let tried = grid
            .iter()
            .enumerate()
            .filter(|(k, _)| self.runs.iter().any(|r| r[*k].is_some()))
            .map(|(_, g)| g.0)
            .collect();
        let rows = (0..n)
            .filter(|&i| self.runs[i].iter().any(Option::is_some))
            .map(|i| (priced[i].name.clone(), self.row(i)))
            .collect();
        Waves {
            reference,
            fates: self.fates,
            tried,
            rows,
        }
    }

    /// The grid steps of candidate `i` not yet run whose modelled cost is within `limit`
    /// (s/s; None: every one).
    fn missing(&self, i: usize, p: &Priced, limit: Option<f64>) -> Vec<(usize, usize)> {
        (0..self.runs[i].len())
            .filter(|&k| self.runs[i][k].is_none() && p.runs_at(k, limit))
            .map(|k| (i, k))
            .collect()
    }
}

/// The grid's reference, the judge it decided and the samples per run.
struct OnGrid<'a> {
    reference: &'a Reference,
    judge: &'a Judge,
    max_samples: u64,
}

/// Runs `jobs` (candidate, grid step) against the grid's reference, keeping each run in
/// `found`.
fn run_jobs(
    ctx: &Ctx,
    priced: &[Priced],
    on: &OnGrid,
    (jobs, label): (&[(usize, usize)], &str),
    found: &mut Found,
) -> Result<()> {
    let named: Vec<(String, usize)> = jobs
        .iter()
        .map(|&(i, k)| (priced[i].name.clone(), k))
        .collect();
    let cases = run_on(
        (ctx.scene, ctx.sys),
        on.reference,
        &named,
        ctx.set,
        (label, ctx.cfg.common.progress),
    )?;
    for (&(i, k), c) in jobs.iter().zip(cases) {
        found.runs[i][k] = Some(c);
    }
    Ok(())
}

/// The grid runs of one wave: the fresh candidates `fresh`, each down to the finest step within
/// the screen at `limit` (s/s) or, with no screen yet, within [`super::screen::SCREEN_FACTOR`]
/// times its own floor first and, when that predicts nothing, the rest of its row; and the
/// steps within the screen that earlier candidates have not run yet. Returns the candidates
/// whose runs changed.
fn grid_wave(
    ctx: &Ctx,
    priced: &[Priced],
    (fresh, wave_no): (&[usize], usize),
    (on, limit): (&OnGrid, Option<f64>),
    found: &mut Found,
) -> Result<Vec<usize>> {
    let factor = ctx.cfg.screen_factor;
    let mut jobs: Vec<(usize, usize)> = Vec::new();
    for &i in fresh {
        let own = limit.unwrap_or(factor * priced[i].floor);
        jobs.extend(found.missing(i, &priced[i], Some(own)));
    }
    if let Some(l) = limit {
        // A candidate predicted before the screen was known, or under a looser one.
        for i in (0..priced.len()).filter(|&i| found.preds[i].is_some()) {
            jobs.extend(found.missing(i, &priced[i], Some(l)));
        }
    }
    let label = format!("grid runs (wave {wave_no})");
    run_jobs(ctx, priced, on, (&jobs, &label), found)?;
    if limit.is_none() {
        let rest: Vec<(usize, usize)> = fresh
            .iter()
            .filter(|&&i| predict(ctx, on, &found.row(i), &priced[i].name).is_err())
            .flat_map(|&i| found.missing(i, &priced[i], None))
            .collect();
        run_jobs(ctx, priced, on, (&rest, &label), found)?;
        jobs.extend(rest);
    }
    let mut touched: Vec<usize> = fresh.to_vec();
    touched.extend(jobs.iter().map(|j| j.0).filter(|i| !fresh.contains(i)));
    touched.sort_unstable();
    touched.dedup();
    Ok(touched)
}

/// The prediction of candidate `name` from its runs `row` ([`predict_row`]).
fn predict(
    ctx: &Ctx,
    on: &OnGrid,
    row: &[CaseResult],
    name: &str,
) -> std::result::Result<Prediction, Vec<(f64, Option<f64>)>> {
    let target = (ctx.horizon, on.max_samples);
    predict_row(name, row, target, on.judge, ctx.cfg.safety)
}

/// Whether two predictions ask the same verification: the same step and fallback run.
fn same_prediction(a: &Prediction, b: &Prediction) -> bool {
    a.1 == b.1 && a.3.dt == b.3.dt
}

/// Runs the candidates `priced` over `grid` in waves (see the module docs).
pub(super) fn run_waves(
    ctx: &Ctx,
    priced: &[Priced],
    grid: &[(f64, u64)],
    decided: &mut Decided,
) -> Result<Waves> {
    let cfg = ctx.cfg;
    let max_samples = max_samples_for(DEFAULT_BUDGET_BYTES, grid.len() * 2, ctx.sys.len());
    let grids: Vec<TimeGrid> = grid
        .iter()
        .map(|&(dt, s)| TimeGrid::new(dt, s, max_samples))
        .collect();
    let reference = reference_for(ctx.scene, cfg, &grids, ctx.horizon, decided)?;
    let judge = decided.judge.clone().expect("decided by the reference");
    let on = OnGrid {
        reference: &reference,
        judge: &judge,
        max_samples,
    };
    let n = priced.len();
    let mut found = Found {
        runs: vec![vec![None; grid.len()]; n],
        preds: vec![None; n],
        fates: vec![None; n],
    };
    let mut pending = by_floor(priced, &orders_of(cfg, priced));
    let mut basis: Option<Basis> = None;
    // Where the reference is a kept solve (or a closed form: no solver step or evaluation),
    // verifying a wave resamples it: each wave is verified at once, and the screen holds the
    // rest to verified answers. Otherwise each verification would solve the reference again,
    // so all are verified together after the last wave, and the screen holds the rest to the
    // cheapest grid run that met the bound.
    let closed_form = reference.info.solver_steps == 0 && reference.info.solver_evals == 0;
    let verify_each = reference.solve_id().is_some() || closed_form;
    let mut wave_no = 0;
    loop {
        let limit = basis
            .as_ref()
            .map(|b| cfg.screen_factor * b.modelled_per_second);
        if let (Some(l), Some(b)) = (limit, &basis) {
            screen_out(priced, &mut pending, l, b, &mut found);
        }
        let fresh = next_wave(priced, &pending, basis.is_some());
        pending.retain(|i| !fresh.contains(i));
        wave_no += 1;
        let touched = grid_wave(ctx, priced, (&fresh, wave_no), (&on, limit), &mut found)?;
        if touched.is_empty() {
            break;
        }
        let mut changed: Vec<(usize, Prediction)> = Vec::new();
        for i in touched {
            match predict(ctx, &on, &found.row(i), &priced[i].name) {
                Ok(p) => {
                    if !found.preds[i]
                        .as_ref()
                        .is_some_and(|q| same_prediction(q, &p))
                    {
                        found.preds[i] = Some(p.clone());
                        changed.push((i, p));
                    }
                }
                Err(errors) => {
                    found.preds[i] = None;
                    let fate = missed(&priced[i], grid, &errors, basis.as_ref(), &judge, cfg);
                    found.fates[i] = Some(fate);
                }
            }
        }
        if !verify_each {
            for (_, p) in &changed {
                basis = Basis::cheaper(basis, Basis::of(&p.0, &p.3, true));
            }
            continue;
        }
        let preds: Vec<Prediction> = changed.iter().map(|(_, p)| p.clone()).collect();
        let label = format!("verification (wave {wave_no})");
        let answers = verify(ctx, &preds, decided, &label)?;
        for ((i, _), a) in changed.iter().zip(answers) {
            basis = Basis::cheaper(basis, Basis::of(&a.name, &a.chosen, false));
            found.fates[*i] = Some(Fate::Answered(Box::new(a)));
        }
    }
    if !verify_each {
        verify_together(ctx, decided, &mut found)?;
    }
    Ok(found.into_waves(priced, grid, reference.info))
}

/// The registry's order of accuracy of each candidate (`u32::MAX` for exact, 0 unknown), for
/// the floor order's ties.
fn orders_of(cfg: &AdviseConfig, priced: &[Priced]) -> Vec<u32> {
    priced
        .iter()
        .map(|p| {
            cfg.common
                .registry
                .info(&p.name)
                .map_or(0, |m| m.order.finite().unwrap_or(u32::MAX))
        })
        .collect()
}

/// Screens out of `pending` every candidate whose floor is above `limit` (s/s), the screen
/// held to `basis`, recording each one's fate in `found`.
fn screen_out(
    priced: &[Priced],
    pending: &mut Vec<usize>,
    limit: f64,
    basis: &Basis,
    found: &mut Found,
) {
    for &i in pending.iter().filter(|&&i| priced[i].floor > limit) {
        let s = Screened::not_run(&priced[i], basis);
        found.fates[i] = Some(Fate::Screened(Box::new(s)));
    }
    pending.retain(|&i| priced[i].floor <= limit);
}

/// Verifies every candidate with a prediction at once, after the last wave (a reference that
/// is not kept is solved once for them all).
fn verify_together(ctx: &Ctx, decided: &mut Decided, found: &mut Found) -> Result<()> {
    let n = found.preds.len();
    let idx: Vec<usize> = (0..n).filter(|&i| found.preds[i].is_some()).collect();
    let preds: Vec<Prediction> = idx.iter().filter_map(|&i| found.preds[i].clone()).collect();
    let answers = verify(ctx, &preds, decided, "verification")?;
    for (&i, a) in idx.iter().zip(answers) {
        found.fates[i] = Some(Fate::Answered(Box::new(a)));
    }
    Ok(())
}

/// The fate of a candidate whose grid runs (`errors`: step and error, finest first) missed
/// tolerance / safety at its finest step run: screened ([`Screened::missed`]), else unable.
fn missed(
    p: &Priced,
    grid: &[(f64, u64)],
    errors: &[(f64, Option<f64>)],
    basis: Option<&Basis>,
    judge: &Judge,
    cfg: &AdviseConfig,
) -> Fate {
    let target = judge.bound / cfg.safety;
    match basis.and_then(|b| Screened::missed(p, grid, errors, (b, cfg.screen_factor), target)) {
        Some(s) => Fate::Screened(Box::new(s)),
        None => Fate::Unable(unable_reason(errors, judge.bound, cfg.safety)),
    }
}

/// What advice settles on after its waves: the reference of its last grid, every step tried
/// (ascending), the answers, the candidates screened and those unable, in candidate order.
pub(super) struct Settled {
    pub reference: ReferenceInfo,
    pub tried: Vec<f64>,
    pub answers: Vec<Answer>,
    pub screened: Vec<Screened>,
    pub unable: Vec<Unable>,
}

/// Settles the waves of candidates `names` on `grid`: when nothing was answered, the grid is
/// extended downwards ([`extend`]) and its predictions verified.
pub(super) fn settle(
    ctx: &Ctx,
    names: &[String],
    (waves, grid): (Waves, &[(f64, u64)]),
    decided: &mut Decided,
) -> Result<Settled> {
    let (mut reference, mut tried, mut fates) = (waves.reference, waves.tried, waves.fates);
    let answered = fates.iter().any(|f| matches!(f, Some(Fate::Answered(_))));
    let cant: Vec<Unable> = names
        .iter()
        .zip(&fates)
        .filter_map(|(n, f)| match f {
            Some(Fate::Unable(r)) => Some((n.clone(), r.clone())),
            _ => None,
        })
        .collect();
    let extended = if answered {
        None
    } else {
        extend(
            (ctx.scene, ctx.sys),
            ctx.cfg,
            (ctx.set, ctx.horizon),
            (waves.rows, grid.to_vec()),
            cant.clone(),
            decided,
        )?
    };
    let mut unable = Vec::new();
    match extended {
        Some(ext) => {
            reference = ext.reference;
            tried.extend(ext.tried);
            let label = "verification (extended grid)";
            for a in verify(ctx, &ext.predictions, decided, label)? {
                let i = names
                    .iter()
                    .position(|n| *n == a.name)
                    .expect("a candidate");
                fates[i] = Some(Fate::Answered(Box::new(a)));
            }
            unable.extend(ext.dropped);
            unable.extend(ext.cant);
        }
        None => unable.extend(cant),
    }
    tried.sort_by(f64::total_cmp);
    tried.dedup();
    let (mut answers, mut screened) = (Vec::new(), Vec::new());
    for f in fates.into_iter().flatten() {
        match f {
            Fate::Answered(a) => answers.push(*a),
            Fate::Screened(s) => screened.push(*s),
            Fate::Unable(_) => {}
        }
    }
    Ok(Settled {
        reference,
        tried,
        answers,
        screened,
        unable,
    })
}
