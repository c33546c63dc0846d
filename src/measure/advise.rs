//! Timestep advice: the cheapest integrator and step whose error over a horizon stays within
//! a tolerance, verified by running it, with alternatives and the frame-rate view for games.
//!
//! Method: every candidate runs on a log grid of steps against one reference; for each, the
//! largest grid step below which every step met tolerance / safety is found, refined by
//! log-log interpolation towards the next (failing) step; that step is then run again
//! (against a reference sampled on its own grid) and accepted only when the verified error is
//! within the tolerance, else the last passing grid step is used. Candidates are ranked by
//! force evaluations per simulated second (wall time per simulated second breaks ties).

use super::case::{applicable, run_case, CaseResult, CaseSettings};
use super::grid::{max_samples_for, TimeGrid, DEFAULT_BUDGET_BYTES};
use super::reference::{Reference, ReferenceInfo};
use super::sweep::step_grid;
use crate::error::{Error, Result};
use crate::integrate::IntegratorOptions;
use crate::method::{Order, Registry};
use crate::scenario::Scenario;
use rayon::prelude::*;
use serde::Serialize;

/// Which error the tolerance bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AdviseMetric {
    /// Maximum position error over the horizon (m).
    Position,
    /// Maximum |relative energy error| over the horizon.
    Energy,
}

impl std::str::FromStr for AdviseMetric {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "position" => Ok(AdviseMetric::Position),
            "energy" => Ok(AdviseMetric::Energy),
            _ => Err(Error::option(
                "--metric",
                format!("expected position or energy, got '{s}'"),
            )),
        }
    }
}

/// Frame rates of the game view (Hz).
pub const FRAME_RATES: [f64; 4] = [30.0, 60.0, 144.0, 240.0];

/// Options of [`advise`].
#[derive(Debug, Clone)]
pub struct AdviseConfig {
    /// Error bound (m for position, relative for energy).
    pub tolerance: f64,
    /// Which error.
    pub metric: AdviseMetric,
    /// Horizon (s; default the scene's duration).
    pub horizon: Option<f64>,
    /// Candidates (empty: every applicable integrator except the closed form).
    pub integrators: Vec<String>,
    /// The methods to choose from (built-ins unless a library user added theirs).
    pub methods: Registry,
    /// Integrator options.
    pub options: IntegratorOptions,
    /// Predictions aim at tolerance / safety (default 2).
    pub safety: f64,
    /// Grid points (default 10).
    pub points: usize,
    /// Smallest grid step (default: scene dt / 30).
    pub dt_min: Option<f64>,
    /// Largest grid step (default: min(10 × scene dt, horizon / 4)).
    pub dt_max: Option<f64>,
    /// Progress bar on a terminal.
    pub progress: bool,
}

impl Default for AdviseConfig {
    fn default() -> Self {
        AdviseConfig {
            tolerance: 1e-3,
            metric: AdviseMetric::Position,
            horizon: None,
            integrators: vec![],
            methods: Registry::builtin(),
            options: IntegratorOptions::default(),
            safety: 2.0,
            points: 10,
            dt_min: None,
            dt_max: None,
            progress: false,
        }
    }
}

/// One candidate's recommendation.
#[derive(Debug, Clone, Serialize)]
pub struct Choice {
    /// Integrator name.
    pub integrator: String,
    /// Recommended step (s).
    pub dt: f64,
    /// Error predicted for that step from the grid.
    pub predicted_error: f64,
    /// Error measured by running it.
    pub verified_error: f64,
    /// Force evaluations per simulated second.
    pub cost_per_second: f64,
    /// Integrator wall time per simulated second (s/s).
    pub wall_per_second: f64,
}

/// How one integrator fares at one frame rate.
#[derive(Debug, Clone, Serialize)]
pub struct FrameEntry {
    /// Integrator name.
    pub integrator: String,
    /// Status with one step per frame.
    pub one_step_status: String,
    /// Error with one step per frame (None when unstable).
    pub one_step_error: Option<f64>,
    /// Substeps per frame needed to meet the tolerance (from its recommended step).
    pub substeps: u64,
    /// Error verified at that many substeps (None when unstable).
    pub substep_error: Option<f64>,
    /// Whether the substepped run meets the tolerance.
    pub meets_tolerance: bool,
    /// Force evaluations per simulated second at that many substeps.
    pub cost_per_second: f64,
}

/// The game view at one frame rate.
#[derive(Debug, Clone, Serialize)]
pub struct FrameRate {
    /// Frames per second.
    pub fps: f64,
    /// Frame time (s).
    pub frame_dt: f64,
    /// Cheapest integrator meeting the tolerance at this frame rate.
    pub best: Option<String>,
    /// Per integrator.
    pub entries: Vec<FrameEntry>,
}

/// `advice.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Advice {
    /// The command that re-creates this document (`--out DIR` is added where it is written).
    pub command: String,
    /// Scenario name.
    pub scenario: String,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Tolerance.
    pub tolerance: f64,
    /// Metric.
    pub metric: AdviseMetric,
    /// Horizon (s).
    pub horizon: f64,
    /// Safety factor.
    pub safety: f64,
    /// The pick (None when nothing meets the tolerance on the grid).
    pub integrator: Option<String>,
    /// Its step (s).
    pub dt: Option<f64>,
    /// Its predicted error.
    pub predicted_error: Option<f64>,
    /// Its verified error.
    pub verified_error: Option<f64>,
    /// Its force evaluations per simulated second.
    pub cost_per_second: Option<f64>,
    /// Its wall time per simulated second.
    pub wall_per_second: Option<f64>,
    /// Every candidate meeting the tolerance, cheapest first (the pick included).
    pub alternatives: Vec<Choice>,
    /// Candidates that cannot meet the tolerance on the grid, with the reason.
    pub unable: Vec<(String, String)>,
    /// The step grid tried (s).
    pub grid: Vec<f64>,
    /// The frame-rate view.
    pub frame_rates: Vec<FrameRate>,
}

fn error_of(c: &CaseResult, m: AdviseMetric) -> Option<f64> {
    let e = match m {
        AdviseMetric::Position => c.metrics.error_max,
        AdviseMetric::Energy => c.metrics.energy_error_max,
    };
    c.ok().then_some(e)
}

fn run_grids(
    scene: &Scenario,
    jobs: &[(String, TimeGrid)],
    horizon: f64,
    set: &CaseSettings,
    progress: bool,
) -> Result<(ReferenceInfo, Vec<CaseResult>)> {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let mut grids: Vec<TimeGrid> = Vec::new();
    let idx: Vec<usize> = jobs
        .iter()
        .map(|(_, g)| match grids.iter().position(|h| h == g) {
            Some(i) => i,
            None => {
                grids.push(*g);
                grids.len() - 1
            }
        })
        .collect();
    let reference = Reference::compute(&sys, &s0, &grids, horizon)?;
    let pb = super::progress::bar(
        jobs.len() as u64,
        &format!("advise {}", scene.name),
        progress,
    );
    let out: Vec<Result<CaseResult>> = jobs
        .par_iter()
        .zip(&idx)
        .map(|((name, _), &g)| {
            let r = run_case(&sys, &s0, &reference, g, name, set);
            pb.inc(1);
            r
        })
        .collect();
    pb.finish_and_clear();
    Ok((reference.info, out.into_iter().collect::<Result<_>>()?))
}

/// Finds the cheapest verified integrator and step for the tolerance.
pub fn advise(scene: &Scenario, cfg: &AdviseConfig) -> Result<Advice> {
    if !(cfg.tolerance.is_finite() && cfg.tolerance > 0.0) {
        return Err(Error::option(
            "--tolerance",
            format!("must be a finite number > 0, got {}", cfg.tolerance),
        ));
    }
    if cfg.safety.is_nan() || cfg.safety < 1.0 {
        return Err(Error::option(
            "--safety",
            format!("must be ≥ 1, got {}", cfg.safety),
        ));
    }
    let sys = scene.build();
    let horizon = cfg
        .horizon
        .or(scene.run.duration)
        .or_else(|| scene.run.steps.zip(scene.run.dt).map(|(n, d)| n as f64 * d))
        .ok_or_else(|| {
            Error::option(
                "--horizon",
                "no horizon: give --horizon or set [run].duration",
            )
        })?;
    if !(horizon.is_finite() && horizon > 0.0) {
        return Err(Error::option(
            "--horizon",
            format!("must be a finite number > 0, got {horizon}"),
        ));
    }
    let base = scene.run.dt.unwrap_or(horizon / 1000.0);
    let dt_max = cfg.dt_max.unwrap_or((10.0 * base).min(horizon / 4.0));
    let dt_min = cfg.dt_min.unwrap_or(base / 30.0);
    if !(dt_min > 0.0 && dt_min <= dt_max) {
        return Err(Error::option(
            "--dt-min",
            format!("need 0 < dt-min ≤ dt-max, got {dt_min} and {dt_max}"),
        ));
    }
    let (mut names, mut unable) = applicable(&cfg.methods, &sys, &cfg.integrators, &cfg.options)?;
    if cfg.integrators.is_empty() {
        // Exact methods are closed forms for special scenes, not general integrators.
        let exact: Vec<String> = names
            .iter()
            .filter(|n| cfg.methods.info(n).is_ok_and(|m| m.order == Order::Exact))
            .cloned()
            .collect();
        for n in exact {
            names.retain(|m| *m != n);
            unable.push((n, "closed form for this scene only, not a general integrator (ask for it with --integrators to include it)".into()));
        }
    }
    let grid = step_grid(dt_min, dt_max, cfg.points.max(2), horizon);
    let max_samples = max_samples_for(DEFAULT_BUDGET_BYTES, grid.len() * 2, sys.len());
    let set = CaseSettings {
        methods: cfg.methods.clone(),
        options: cfg.options,
        blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
        series_points: 0,
        repeat_short: true,
        trace: None,
    };
    let jobs: Vec<(String, TimeGrid)> = names
        .iter()
        .flat_map(|n| {
            grid.iter()
                .map(move |&(dt, s)| (n.clone(), TimeGrid::new(dt, s, max_samples)))
        })
        .collect();
    let (reference, cases) = run_grids(scene, &jobs, horizon, &set, cfg.progress)?;
    let target = cfg.tolerance / cfg.safety;
    // Per integrator: the prediction from the grid.
    let mut predictions: Vec<(String, TimeGrid, f64, CaseResult)> = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let row = &cases[i * grid.len()..(i + 1) * grid.len()];
        let mut last_pass = None;
        for (j, c) in row.iter().enumerate() {
            match error_of(c, cfg.metric) {
                Some(e) if e <= target => last_pass = Some(j),
                _ => break,
            }
        }
        let Some(j) = last_pass else {
            let best = row
                .iter()
                .filter_map(|c| error_of(c, cfg.metric))
                .fold(f64::INFINITY, f64::min);
            unable.push((name.clone(), if best.is_finite() {
                format!("smallest error on the grid {best:.3e} exceeds tolerance/safety {target:.3e} (try a smaller --dt-min)")
            } else {
                "unstable at every step of the grid".into()
            }));
            continue;
        };
        let ej = error_of(&row[j], cfg.metric).expect("passed");
        let (mut dt, mut pred) = (row[j].dt, ej);
        if let Some(next) = row.get(j + 1) {
            if let Some(en) = error_of(next, cfg.metric) {
                if ej > 0.0 && en > ej {
                    let slope = (en / ej).ln() / (next.dt / row[j].dt).ln();
                    let d = row[j].dt * (target / ej).powf(1.0 / slope);
                    dt = d.clamp(row[j].dt, next.dt);
                    pred = ej * (dt / row[j].dt).powf(slope);
                }
            }
        }
        let steps = ((horizon / dt).ceil() as u64).max(1);
        let g = TimeGrid::new(horizon / steps as f64, steps, max_samples);
        predictions.push((name.clone(), g, pred, row[j].clone()));
    }
    // Verification runs, and the frame-rate runs, against one more reference.
    let mut vjobs: Vec<(String, TimeGrid)> =
        predictions.iter().map(|p| (p.0.clone(), p.1)).collect();
    let frames: Vec<u64> = FRAME_RATES
        .iter()
        .map(|f| ((horizon * f).round() as u64).max(1))
        .collect();
    let substeps: Vec<Vec<u64>> = FRAME_RATES
        .iter()
        .map(|&fps| {
            predictions
                .iter()
                .map(|p| ((1.0 / fps) / p.1.dt).ceil().max(1.0) as u64)
                .collect()
        })
        .collect();
    for (fi, &fps) in FRAME_RATES.iter().enumerate() {
        for (pi, p) in predictions.iter().enumerate() {
            let frame = 1.0 / fps;
            vjobs.push((p.0.clone(), TimeGrid::new(frame, frames[fi], max_samples)));
            let n = substeps[fi][pi];
            vjobs.push((
                p.0.clone(),
                TimeGrid::new(frame / n as f64, frames[fi] * n, max_samples),
            ));
        }
    }
    let (_, vres) = run_grids(scene, &vjobs, horizon, &set, cfg.progress)?;
    let mut alternatives: Vec<Choice> = Vec::new();
    for (pi, (name, g, pred, fallback)) in predictions.iter().enumerate() {
        let v = &vres[pi];
        let choice = |c: &CaseResult, pred: f64| Choice {
            integrator: name.clone(),
            dt: c.dt,
            predicted_error: pred,
            verified_error: error_of(c, cfg.metric).unwrap_or(f64::INFINITY),
            cost_per_second: c.force_evals as f64 / (c.dt * c.steps as f64),
            wall_per_second: c.wall_seconds / (c.dt * c.steps as f64),
        };
        match error_of(v, cfg.metric) {
            Some(e) if e <= cfg.tolerance => alternatives.push(choice(v, *pred)),
            _ => {
                let _ = g;
                alternatives.push(choice(
                    fallback,
                    error_of(fallback, cfg.metric).unwrap_or(0.0),
                ))
            }
        }
    }
    alternatives.sort_by(|a, b| {
        a.cost_per_second
            .total_cmp(&b.cost_per_second)
            .then(a.wall_per_second.total_cmp(&b.wall_per_second))
            .then(a.integrator.cmp(&b.integrator))
    });
    let np = predictions.len();
    let frame_rates = FRAME_RATES
        .iter()
        .enumerate()
        .map(|(fi, &fps)| {
            let entries: Vec<FrameEntry> = predictions
                .iter()
                .enumerate()
                .map(|(pi, p)| {
                    let one = &vres[np + 2 * (fi * np + pi)];
                    let sub = &vres[np + 2 * (fi * np + pi) + 1];
                    let se = error_of(sub, cfg.metric);
                    FrameEntry {
                        integrator: p.0.clone(),
                        one_step_status: one.status.clone(),
                        one_step_error: error_of(one, cfg.metric),
                        substeps: substeps[fi][pi],
                        substep_error: se,
                        meets_tolerance: se.is_some_and(|e| e <= cfg.tolerance),
                        cost_per_second: sub.force_evals as f64 / (sub.dt * sub.steps as f64),
                    }
                })
                .collect();
            let best = entries
                .iter()
                .filter(|e| e.meets_tolerance)
                .min_by(|a, b| a.cost_per_second.total_cmp(&b.cost_per_second))
                .map(|e| e.integrator.clone());
            FrameRate {
                fps,
                frame_dt: 1.0 / fps,
                best,
                entries,
            }
        })
        .collect();
    let pick = alternatives.first().cloned();
    let metric = match cfg.metric {
        AdviseMetric::Position => "position",
        AdviseMetric::Energy => "energy",
    };
    let mut asked = cfg.integrators.clone();
    if asked.is_empty() {
        asked = cfg.methods.names().into_iter().map(String::from).collect();
    }
    let command = super::command::CommandLine::new("advise", &scene.source)
        .flag("tolerance", cfg.tolerance)
        .flag("metric", metric)
        .flag("horizon", horizon)
        .list("integrators", &asked)
        .flag("safety", cfg.safety)
        .flag("points", cfg.points)
        .flag_opt("dt-min", cfg.dt_min)
        .flag_opt("dt-max", cfg.dt_max)
        .flag("substeps", cfg.options.substeps)
        .flag("iterations", cfg.options.constraint_iterations)
        .render();
    Ok(Advice {
        command,
        scenario: scene.name.clone(),
        reference,
        tolerance: cfg.tolerance,
        metric: cfg.metric,
        horizon,
        safety: cfg.safety,
        integrator: pick.as_ref().map(|p| p.integrator.clone()),
        dt: pick.as_ref().map(|p| p.dt),
        predicted_error: pick.as_ref().map(|p| p.predicted_error),
        verified_error: pick.as_ref().map(|p| p.verified_error),
        cost_per_second: pick.as_ref().map(|p| p.cost_per_second),
        wall_per_second: pick.as_ref().map(|p| p.wall_per_second),
        alternatives,
        unable,
        grid: grid.iter().map(|g| g.0).collect(),
        frame_rates,
    })
}

/// Writes `advice.json` into `dir` (with `--out dir` in its command).
pub fn write_advice(dir: &std::path::Path, adv: &Advice) -> Result<std::path::PathBuf> {
    let doc = Advice {
        command: super::command::with_out(&adv.command, dir),
        ..adv.clone()
    };
    let mut json = serde_json::to_vec_pretty(&doc).expect("serialisable");
    json.push(b'\n');
    crate::output::write_atomic(dir.join("advice.json"), &json)
}
