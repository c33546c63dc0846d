//! Work-precision sweeps: every integrator over a log-spaced grid of steps against one
//! reference, the observed order per integrator, and deterministic sharding.
//!
//! Cases are numbered integrator-major (case k = integrator i, step j with k = i·points + j);
//! shard I/N runs the cases with k mod N = I. Cases run in parallel (rayon) and are collected
//! in case order, so every output except `wall_seconds` is bit-identical whatever the thread
//! count, and a merge of all shards equals the unsharded sweep.

use super::case::{applicable, run_case, CaseResult, CaseSettings};
use super::fit::{fit_order, OrderFit};
use super::grid::{max_samples_for, TimeGrid, DEFAULT_BUDGET_BYTES};
use super::reference::{Reference, ReferenceInfo};
use crate::error::{Error, Result};
use crate::integrate::IntegratorOptions;
use crate::method::Registry;
use crate::output::write_atomic;
use crate::scenario::Scenario;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The I-th of N deterministic slices of a sweep (0 ≤ I < N).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Slice index, 0-based.
    pub index: usize,
    /// Number of slices.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let bad = |m: &str| {
            Error::option(
                "--shard",
                format!("{m}: expected I/N with 0 ≤ I < N, got '{s}'"),
            )
        };
        let (i, n) = s.split_once('/').ok_or_else(|| bad("missing '/'"))?;
        let index: usize = i.trim().parse().map_err(|_| bad("I is not a number"))?;
        let count: usize = n.trim().parse().map_err(|_| bad("N is not a number"))?;
        if count == 0 || index >= count {
            return Err(bad("out of range"));
        }
        Ok(Shard { index, count })
    }
}

/// What to sweep.
#[derive(Debug, Clone)]
pub struct SweepConfig {
    /// Integrators (empty: every applicable native method and external backend).
    pub integrators: Vec<String>,
    /// Smallest step (default: the scene's dt / 30).
    pub dt_min: Option<f64>,
    /// Largest step (default: 10 × the scene's dt).
    pub dt_max: Option<f64>,
    /// Number of steps in the grid (default 12).
    pub points: usize,
    /// Simulated time (default: the scene's duration).
    pub duration: Option<f64>,
    /// The methods to choose from (built-ins unless a library user added theirs).
    pub methods: Registry,
    /// Integrator options.
    pub options: IntegratorOptions,
    /// Blow-up factor of the runner.
    pub blowup_factor: f64,
    /// Run only one slice.
    pub shard: Option<Shard>,
    /// Memory budget for the reference samples (bytes).
    pub budget_bytes: usize,
    /// Show a progress bar on a terminal.
    pub progress: bool,
    /// Repeat short runs for the wall time.
    pub repeat_short: bool,
}

impl Default for SweepConfig {
    fn default() -> Self {
        SweepConfig {
            integrators: Vec::new(),
            dt_min: None,
            dt_max: None,
            points: 12,
            duration: None,
            methods: Registry::builtin(),
            options: IntegratorOptions::default(),
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
            shard: None,
            budget_bytes: DEFAULT_BUDGET_BYTES,
            progress: false,
            repeat_short: true,
        }
    }
}

/// One row of `sweep.csv`. Error and energy columns are empty for unstable runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRow {
    /// Integrator name.
    pub integrator: String,
    /// Step (s).
    pub dt: f64,
    /// Steps planned.
    pub steps: u64,
    /// Force evaluations.
    pub force_evals: u64,
    /// Integrator wall time (s): the one column that varies between identical runs.
    pub wall_seconds: f64,
    /// Final position error (m).
    pub error_final: Option<f64>,
    /// Max position error (m).
    pub error_max: Option<f64>,
    /// RMS position error (m).
    pub error_rms: Option<f64>,
    /// Relative energy drift (1/s).
    pub energy_drift: Option<f64>,
    /// `ok` or `unstable`.
    pub status: String,
}

/// The CSV header of `sweep.csv`.
pub const SWEEP_HEADER: &str =
    "integrator,dt,steps,force_evals,wall_seconds,error_final,error_max,error_rms,energy_drift,status";

impl SweepRow {
    fn from_case(c: &CaseResult) -> Self {
        let ok = c.ok();
        let m = &c.metrics;
        SweepRow {
            integrator: c.integrator.clone(),
            dt: c.dt,
            steps: c.steps,
            force_evals: c.force_evals,
            wall_seconds: c.wall_seconds,
            error_final: ok.then_some(m.error_final),
            error_max: ok.then_some(m.error_max),
            error_rms: ok.then_some(m.error_rms),
            energy_drift: ok.then_some(m.energy_drift),
            status: c.status.clone(),
        }
    }
    fn csv_line(&self) -> String {
        let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
        format!(
            "{},{:e},{},{},{:e},{},{},{},{},{}",
            self.integrator,
            self.dt,
            self.steps,
            self.force_evals,
            self.wall_seconds,
            o(self.error_final),
            o(self.error_max),
            o(self.error_rms),
            o(self.energy_drift),
            self.status
        )
    }
}

/// Everything that defines a sweep's cases; shards of one sweep share it exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepPlan {
    /// Scenario name.
    pub scenario: String,
    /// Simulated time (s).
    pub duration: f64,
    /// The step grid (s), each dividing the duration into whole steps.
    pub dts: Vec<f64>,
    /// Steps per grid point.
    pub steps: Vec<u64>,
    /// Compare every stride-th step per grid point.
    pub strides: Vec<u64>,
    /// Applicable integrators, in case order.
    pub integrators: Vec<String>,
    /// Integrators skipped (name, reason).
    pub skipped: Vec<(String, String)>,
    /// Blow-up factor.
    pub blowup_factor: f64,
    /// Constraint iterations of verlet_constraints.
    pub constraint_iterations: usize,
    /// Substeps of external backends.
    pub substeps: usize,
}

impl SweepPlan {
    /// Number of cases.
    pub fn case_count(&self) -> usize {
        self.integrators.len() * self.dts.len()
    }
    fn grid(&self, j: usize) -> TimeGrid {
        TimeGrid {
            dt: self.dts[j],
            steps: self.steps[j],
            stride: self.strides[j],
        }
    }
}

/// `shard.json`: what a shard ran, so `merge` can check and join shards.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardFile {
    /// The sweep's plan (identical in every shard).
    pub plan: SweepPlan,
    /// This shard.
    pub shard: Shard,
    /// Case indices of the rows of this shard's `sweep.csv`, in order.
    pub cases: Vec<usize>,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Error floor (m) per grid point, for the order fits.
    pub floors: Vec<f64>,
    /// Saturation bound (m) for the order fits.
    pub saturation: f64,
}

/// Per-integrator summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IntegratorSummary {
    /// Integrator name.
    pub integrator: String,
    /// Order the method is designed to have (None for exact or external methods).
    pub theoretical_order: Option<u32>,
    /// Points that ran to the end.
    pub stable_points: usize,
    /// Points that blew up.
    pub unstable_points: usize,
    /// Observed order (least-squares slope of log error_max vs log dt, asymptotic range).
    pub observed_order: Option<f64>,
    /// The fit: quality, range used and what was excluded.
    pub fit: OrderFit,
}

/// `summary.json` of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSummary {
    /// Scenario name.
    pub scenario: String,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Simulated time (s).
    pub duration: f64,
    /// The step grid (s).
    pub dts: Vec<f64>,
    /// Which error the orders are fitted to.
    pub order_metric: String,
    /// Saturation bound (m).
    pub saturation: f64,
    /// Per integrator.
    pub integrators: Vec<IntegratorSummary>,
    /// Integrators that do not apply, with the reason.
    pub skipped: Vec<(String, String)>,
}

/// A sweep's results: rows (CSV), full case results (for plots) and the summary.
#[derive(Debug, Clone, Serialize)]
pub struct SweepResult {
    /// The plan.
    pub plan: SweepPlan,
    /// Shard run, if any.
    pub shard: Option<Shard>,
    /// Case indices of `rows`.
    pub case_indices: Vec<usize>,
    /// `sweep.csv` rows.
    pub rows: Vec<SweepRow>,
    /// Full results with every metric (empty after a merge: rows only).
    pub cases: Vec<CaseResult>,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Per-grid-point error floors (m).
    pub floors: Vec<f64>,
    /// Saturation bound (m).
    pub saturation: f64,
    /// The summary (None for a shard: merge computes it).
    pub summary: Option<SweepSummary>,
}

/// Builds the step grid: `points` log-spaced steps in [dt_min, dt_max], each adjusted so a
/// whole number of steps spans `duration`; duplicates dropped.
pub fn step_grid(dt_min: f64, dt_max: f64, points: usize, duration: f64) -> Vec<(f64, u64)> {
    let mut out: Vec<(f64, u64)> = Vec::new();
    for k in 0..points {
        let f = if points > 1 {
            k as f64 / (points - 1) as f64
        } else {
            0.0
        };
        let dt = dt_min * (dt_max / dt_min).powf(f);
        let steps = ((duration / dt).round() as u64).max(1);
        if out.last().is_none_or(|&(_, s)| s != steps) && !out.iter().any(|&(_, s)| s == steps) {
            out.push((duration / steps as f64, steps));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

fn positive(name: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::option(
            name,
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

/// Resolves the configuration against the scene into a [`SweepPlan`].
pub fn plan_sweep(scene: &Scenario, cfg: &SweepConfig) -> Result<SweepPlan> {
    let sys = scene.build();
    let duration = match cfg.duration.or(scene.run.duration).or_else(|| {
        scene
            .run
            .steps
            .zip(scene.run.dt)
            .map(|(n, dt)| n as f64 * dt)
    }) {
        Some(d) => positive("--duration", d)?,
        None => {
            return Err(Error::option(
                "--duration",
                format!(
                    "{}: no duration: give --duration or set [run].duration",
                    scene.source.display()
                ),
            ))
        }
    };
    let base = scene.run.dt;
    let dt_max = match cfg.dt_max.or(base.map(|d| 10.0 * d)) {
        Some(v) => positive("--dt-max", v)?,
        None => {
            return Err(Error::option(
                "--dt-max",
                "no [run].dt in the scene: give --dt-min and --dt-max",
            ))
        }
    };
    let dt_min = match cfg.dt_min.or(base.map(|d| d / 30.0)) {
        Some(v) => positive("--dt-min", v)?,
        None => {
            return Err(Error::option(
                "--dt-min",
                "no [run].dt in the scene: give --dt-min and --dt-max",
            ))
        }
    };
    if dt_min > dt_max {
        return Err(Error::option(
            "--dt-min",
            format!("{dt_min} exceeds --dt-max {dt_max}"),
        ));
    }
    if cfg.points == 0 {
        return Err(Error::option("--points", "must be at least 1"));
    }
    if duration / dt_min > crate::scenario::MAX_STEPS as f64 {
        return Err(Error::option(
            "--dt-min",
            format!("{dt_min} s over {duration} s exceeds the step limit"),
        ));
    }
    let grid = step_grid(dt_min, dt_max.min(duration), cfg.points, duration);
    let max_samples = max_samples_for(cfg.budget_bytes, grid.len(), sys.len());
    let (integrators, skipped) = applicable(&cfg.methods, &sys, &cfg.integrators, &cfg.options)?;
    Ok(SweepPlan {
        scenario: scene.name.clone(),
        duration,
        dts: grid.iter().map(|g| g.0).collect(),
        steps: grid.iter().map(|g| g.1).collect(),
        strides: grid
            .iter()
            .map(|g| TimeGrid::new(g.0, g.1, max_samples).stride)
            .collect(),
        integrators,
        skipped,
        blowup_factor: cfg.blowup_factor,
        constraint_iterations: cfg.options.constraint_iterations,
        substeps: cfg.options.substeps,
    })
}

/// Runs a sweep (or one shard of it).
pub fn run_sweep(scene: &Scenario, cfg: &SweepConfig) -> Result<SweepResult> {
    let plan = plan_sweep(scene, cfg)?;
    let sys = scene.build();
    let s0 = scene.initial_state();
    let all: Vec<usize> = (0..plan.case_count()).collect();
    let mine: Vec<usize> = match cfg.shard {
        Some(sh) => all
            .into_iter()
            .filter(|k| k % sh.count == sh.index)
            .collect(),
        None => all,
    };
    let points = plan.dts.len();
    // Only the grids this shard uses; the horizon is the full sweep's so every shard's
    // reference takes the same solver steps.
    let mut used: Vec<usize> = mine.iter().map(|k| k % points).collect();
    used.sort_unstable();
    used.dedup();
    let grids: Vec<TimeGrid> = used.iter().map(|&j| plan.grid(j)).collect();
    let horizon = (0..points)
        .map(|j| plan.grid(j).time(plan.steps[j]))
        .fold(0.0, f64::max);
    let reference = Reference::compute(&sys, &s0, &grids, horizon)?;
    let set = CaseSettings {
        methods: cfg.methods.clone(),
        options: cfg.options,
        blowup_factor: cfg.blowup_factor,
        series_points: 0,
        repeat_short: cfg.repeat_short,
        trace: None,
    };
    let pb = super::progress::bar(
        mine.len() as u64,
        &format!("sweep {}", scene.name),
        cfg.progress,
    );
    let cases: Vec<Result<CaseResult>> = mine
        .par_iter()
        .map(|&k| {
            let (i, j) = (k / points, k % points);
            let g = used.binary_search(&j).expect("grid used");
            let r = run_case(&sys, &s0, &reference, g, &plan.integrators[i], &set);
            pb.inc(1);
            r
        })
        .collect();
    pb.finish_and_clear();
    let cases: Vec<CaseResult> = cases.into_iter().collect::<Result<_>>()?;
    let rows = cases.iter().map(SweepRow::from_case).collect();
    let scale = reference.motion_scale();
    let floors = plan
        .steps
        .iter()
        .map(|&n| {
            (10.0 * reference.info.accuracy).max(4.0 * f64::EPSILON * scale * (n as f64).sqrt())
        })
        .collect();
    let mut res = SweepResult {
        shard: cfg.shard,
        case_indices: mine,
        rows,
        cases,
        reference: reference.info.clone(),
        floors,
        saturation: 0.1 * scale,
        summary: None,
        plan,
    };
    if cfg.shard.is_none() {
        res.summary = Some(summarise(&res));
    }
    Ok(res)
}

/// Theoretical order of a named method (None for exact and external ones).
pub fn theoretical_order(name: &str) -> Option<u32> {
    Registry::builtin()
        .info(name)
        .ok()
        .filter(|m| !m.engine)
        .and_then(|m| m.order.finite())
}

/// The summary of a full (unsharded or merged) sweep, computed from its rows only.
pub fn summarise(res: &SweepResult) -> SweepSummary {
    let points = res.plan.dts.len();
    let integrators = res
        .plan
        .integrators
        .iter()
        .map(|name| {
            let pts: Vec<(f64, f64, bool, f64)> = res
                .rows
                .iter()
                .zip(&res.case_indices)
                .filter(|(r, _)| &r.integrator == name)
                .map(|(r, &k)| {
                    (
                        r.dt,
                        r.error_max.unwrap_or(f64::INFINITY),
                        r.status == "ok",
                        res.floors[k % points],
                    )
                })
                .collect();
            let fit = fit_order(&pts, res.saturation);
            IntegratorSummary {
                integrator: name.clone(),
                theoretical_order: theoretical_order(name),
                stable_points: pts.iter().filter(|p| p.2).count(),
                unstable_points: pts.iter().filter(|p| !p.2).count(),
                observed_order: fit.observed_order,
                fit,
            }
        })
        .collect();
    SweepSummary {
        scenario: res.plan.scenario.clone(),
        reference: res.reference.clone(),
        duration: res.plan.duration,
        dts: res.plan.dts.clone(),
        order_metric: "error_max".into(),
        saturation: res.saturation,
        integrators,
        skipped: res.plan.skipped.clone(),
    }
}

fn json<T: Serialize>(v: &T) -> Vec<u8> {
    let mut b = serde_json::to_vec_pretty(v).expect("serialisable");
    b.push(b'\n');
    b
}

/// Writes `sweep.csv` and, for a full sweep, `summary.json`; for a shard, `shard.json`.
pub fn write_sweep(dir: &Path, res: &SweepResult) -> Result<Vec<PathBuf>> {
    let mut csv = String::from(SWEEP_HEADER);
    csv.push('\n');
    for r in &res.rows {
        csv.push_str(&r.csv_line());
        csv.push('\n');
    }
    let mut out = vec![write_atomic(dir.join("sweep.csv"), csv.as_bytes())?];
    match (&res.summary, res.shard) {
        (Some(s), _) => out.push(write_atomic(dir.join("summary.json"), &json(s))?),
        (None, Some(shard)) => {
            let f = ShardFile {
                plan: res.plan.clone(),
                shard,
                cases: res.case_indices.clone(),
                reference: res.reference.clone(),
                floors: res.floors.clone(),
                saturation: res.saturation,
            };
            out.push(write_atomic(dir.join("shard.json"), &json(&f))?);
        }
        (None, None) => {}
    }
    Ok(out)
}

fn read_rows(path: &Path) -> Result<Vec<SweepRow>> {
    let bad = |line: usize, m: String| Error::invalid(path, format!("line {line}"), m);
    let text = std::fs::read_to_string(path).map_err(|source| Error::Read {
        file: path.to_path_buf(),
        source,
    })?;
    let mut lines = text.lines();
    if lines.next() != Some(SWEEP_HEADER) {
        return Err(bad(1, format!("header must be '{SWEEP_HEADER}'")));
    }
    let mut rows = Vec::new();
    for (i, l) in lines.enumerate() {
        let n = i + 2;
        let f: Vec<&str> = l.split(',').collect();
        if f.len() != 10 {
            return Err(bad(n, format!("expected 10 fields, got {}", f.len())));
        }
        let num = |k: usize, name: &str| -> Result<f64> {
            f[k].parse::<f64>()
                .map_err(|_| bad(n, format!("{name}: not a number: '{}'", f[k])))
        };
        let opt = |k: usize, name: &str| -> Result<Option<f64>> {
            if f[k].is_empty() {
                Ok(None)
            } else {
                num(k, name).map(Some)
            }
        };
        let int = |k: usize, name: &str| -> Result<u64> {
            f[k].parse::<u64>()
                .map_err(|_| bad(n, format!("{name}: not a whole number: '{}'", f[k])))
        };
        rows.push(SweepRow {
            integrator: f[0].to_string(),
            dt: num(1, "dt")?,
            steps: int(2, "steps")?,
            force_evals: int(3, "force_evals")?,
            wall_seconds: num(4, "wall_seconds")?,
            error_final: opt(5, "error_final")?,
            error_max: opt(6, "error_max")?,
            error_rms: opt(7, "error_rms")?,
            energy_drift: opt(8, "energy_drift")?,
            status: f[9].to_string(),
        });
    }
    Ok(rows)
}

/// Joins the shard directories of one sweep into the full result (rows in case order and
/// the summary); errors name the directory and what does not match.
pub fn merge(dirs: &[PathBuf]) -> Result<SweepResult> {
    if dirs.is_empty() {
        return Err(Error::option("merge", "give at least one shard directory"));
    }
    let mut first: Option<ShardFile> = None;
    let mut slots: Vec<Option<SweepRow>> = Vec::new();
    let mut seen: Vec<bool> = Vec::new();
    for d in dirs {
        let sp = d.join("shard.json");
        let text = std::fs::read_to_string(&sp).map_err(|source| Error::Read {
            file: sp.clone(),
            source,
        })?;
        let sf: ShardFile = serde_json::from_str(&text)
            .map_err(|e| Error::invalid(&sp, "(document)", e.to_string()))?;
        let rows = read_rows(&d.join("sweep.csv"))?;
        if rows.len() != sf.cases.len() {
            return Err(Error::invalid(
                d.join("sweep.csv"),
                "(rows)",
                format!(
                    "{} rows but shard.json lists {} cases",
                    rows.len(),
                    sf.cases.len()
                ),
            ));
        }
        match &first {
            None => {
                slots = vec![None; sf.plan.case_count()];
                seen = vec![false; sf.shard.count];
                first = Some(sf.clone());
            }
            Some(f) => {
                if f.plan != sf.plan || f.reference != sf.reference || f.floors != sf.floors {
                    return Err(Error::invalid(
                        &sp,
                        "plan",
                        "this shard belongs to a different sweep (plan, reference or grid differ)",
                    ));
                }
                if f.shard.count != sf.shard.count {
                    return Err(Error::invalid(
                        &sp,
                        "shard.count",
                        format!(
                            "{} but the first shard says {}",
                            sf.shard.count, f.shard.count
                        ),
                    ));
                }
            }
        }
        if std::mem::replace(&mut seen[sf.shard.index], true) {
            return Err(Error::invalid(
                &sp,
                "shard.index",
                format!("shard {} given twice", sf.shard.index),
            ));
        }
        for (k, r) in sf.cases.iter().zip(rows) {
            if *k >= slots.len() {
                return Err(Error::invalid(
                    &sp,
                    "cases",
                    format!("case {k} out of range"),
                ));
            }
            slots[*k] = Some(r);
        }
    }
    let f = first.expect("at least one shard");
    if let Some(missing) = seen.iter().position(|s| !s) {
        return Err(Error::option(
            "merge",
            format!("shard {missing}/{} is missing", f.shard.count),
        ));
    }
    let rows: Vec<SweepRow> = slots
        .into_iter()
        .enumerate()
        .map(|(k, r)| r.ok_or_else(|| Error::option("merge", format!("case {k} is missing"))))
        .collect::<Result<_>>()?;
    let mut res = SweepResult {
        case_indices: (0..rows.len()).collect(),
        rows,
        cases: Vec::new(),
        reference: f.reference,
        floors: f.floors,
        saturation: f.saturation,
        summary: None,
        shard: None,
        plan: f.plan,
    };
    res.summary = Some(summarise(&res));
    Ok(res)
}
