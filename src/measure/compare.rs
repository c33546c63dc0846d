//! Every applicable method at one step against the reference, side by side.

use super::case::{applicable, asked_or_all, run_case, CaseResult, CaseSettings};
use super::command::{with_out, CommandLine};
use super::contacts::ContactReport;
use super::grid::{run_grid, scene_grid};
use super::metric_table;
use super::reference::{Reference, ReferenceInfo};
use super::trace::{longest_paths, TraceSpec};
use crate::error::Result;
use crate::measure::statistics::Ensemble;
use crate::measure::tolerance::Tolerance;
use crate::output::{write_atomic, write_document};
use crate::run::RunStatus;
use crate::scenario::{Scenario, Timing};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What to compare.
#[derive(Debug, Clone)]
pub struct CompareConfig {
    /// Methods, registry, options, blow-up factor, progress and budget: what every
    /// measuring command shares.
    pub common: crate::measure::Common,
    /// Step (default: the scene's).
    pub dt: Option<f64>,
    /// Simulated time (default: the scene's).
    pub duration: Option<f64>,
    /// Substeps per frame for every method (`--substeps`): `dt` is then the frame step,
    /// native methods take that many equal steps per frame and Rapier that many solver
    /// substeps. `None`: one step per frame, and `options.substeps` for Rapier.
    pub frame_substeps: Option<u64>,
    /// Points per time series (0: none).
    pub series_points: u64,
    /// Record paths and snapshots of each run (for pictures).
    pub trace: bool,
    /// Position tolerance (m) behind the statistics' floors; None: the scene's
    /// `[run] tolerance`, else 1 % of its motion scale.
    pub tolerance: Option<f64>,
}

impl Default for CompareConfig {
    fn default() -> Self {
        CompareConfig {
            dt: None,
            duration: None,
            frame_substeps: None,
            series_points: 2000,
            trace: false,
            tolerance: None,
            common: crate::measure::Common::default(),
        }
    }
}

/// A compare line's status: its run's ([`RunStatus`], spelt as it spells it), or that the
/// method was skipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntryStatus {
    /// The method ran.
    Ran(RunStatus),
    /// The method did not run (the line says why).
    Skipped,
}

impl EntryStatus {
    /// `ok`, `unstable` or `skipped`, as documents spell it.
    pub fn label(self) -> &'static str {
        match self {
            EntryStatus::Ran(s) => s.label(),
            EntryStatus::Skipped => "skipped",
        }
    }
}

impl Serialize for EntryStatus {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.label())
    }
}

impl std::fmt::Display for EntryStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.label())
    }
}

/// One method's line: a result, or why it was skipped.
#[derive(Debug, Clone, Serialize)]
pub struct CompareEntry {
    /// Method name.
    pub method: String,
    /// `ok`, `unstable` or `skipped`.
    pub status: EntryStatus,
    /// Why it was skipped.
    pub skip_reason: Option<String>,
    /// The run, unless skipped.
    pub result: Option<CaseResult>,
}

/// `summary.json` of a comparison (and the library result).
#[derive(Debug, Clone, Serialize)]
pub struct CompareResult {
    /// The command that re-creates this document (`--out DIR` is added where it is written).
    pub command: String,
    /// Scenario name.
    pub scenario: String,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Step (s).
    pub dt: f64,
    /// Steps.
    pub steps: u64,
    /// Simulated time (s).
    pub duration: f64,
    /// Solver substeps given to engine methods.
    pub substeps: usize,
    /// Substeps per frame of every method, when asked (`dt` is then the frame step).
    pub frame_substeps: Option<u64>,
    /// One entry per method, in the order asked.
    pub entries: Vec<CompareEntry>,
    /// The position tolerance behind the statistics' floors, and where it came from.
    pub position_tolerance: Tolerance,
    /// The reference's ensemble past its predictability horizon, when it has one: what each
    /// entry's `metrics.statistics` is judged against.
    pub ensemble: Option<Ensemble>,
}

/// The modelled cost the budget projects for method `name`'s run of `steps` frames of `dt`
/// under `cfg` (its frame substeps included once): the price per frame and `steps` times it.
/// A method that cannot be probed costs nothing here; its run reports why.
pub fn projected_cost(
    sys: &crate::model::System,
    s0: &crate::model::State,
    cfg: &CompareConfig,
    name: &str,
    dt: f64,
    steps: u64,
) -> super::probe::Cost {
    let per = super::probe::seconds_per_frame(
        sys,
        s0,
        &cfg.common.registry,
        &cfg.common.options,
        name,
        super::probe::Framing {
            dt,
            frames: steps,
            substeps: cfg.frame_substeps,
        },
    )
    .unwrap_or(0.0);
    super::probe::Cost {
        per_unit: per,
        projected: per * steps as f64,
    }
}

/// Samples of the reference when no method is left to compare with it (every one skipped):
/// enough to describe it, far fewer than a run's grid would store.
pub const NOTHING_COMPARED_SAMPLES: u64 = 64;

/// The runs a comparison makes: the scene's system and start, the settings, and the frames
/// (`steps` of `dt`). Bundled because pricing, tracing and running every method's run read
/// the same five.
struct Runs<'a> {
    sys: &'a crate::model::System,
    s0: &'a crate::model::State,
    cfg: &'a CompareConfig,
    dt: f64,
    steps: u64,
}

/// Runs the comparison.
pub fn compare(scene: &Scenario, cfg: &CompareConfig) -> Result<CompareResult> {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let Timing { dt, steps, .. } = Timing::resolve(scene, cfg.dt, cfg.duration)?;
    if let Some(n) = cfg.frame_substeps {
        Timing::substeps_within("--substeps", steps, n)?;
    }
    let runs = Runs {
        sys: &sys,
        s0: &s0,
        cfg,
        dt,
        steps,
    };
    let asked = asked_methods(scene, cfg);
    let (names, mut skipped) = applicable(&cfg.common.registry, &sys, &asked, &cfg.common.options)?;
    let grid = run_grid(dt, steps, sys.len());
    let horizon = grid.time(steps);
    let (names, limit) = runs.budgeted(names, &mut skipped, grid, horizon)?;
    // With no run left to compare, the reference is only described: a few samples do.
    let grid = if names.is_empty() {
        super::grid::TimeGrid::new(dt, steps, NOTHING_COMPARED_SAMPLES)
    } else {
        grid
    };
    let mut reference = Reference::compute_within(&sys, &s0, &[grid], horizon, limit)?;
    let position_tolerance = crate::measure::tolerance::resolve(
        cfg.tolerance,
        scene.run.tolerance,
        reference.motion_scale(),
    );
    let on = scene_grid(scene, sys.len(), horizon)?;
    reference.add_ensemble(&sys, &s0, position_tolerance.value, on)?;
    let entries = runs.entries(scene, &reference, &names, skipped)?;
    Ok(CompareResult {
        command: command_line(scene, cfg, &asked, dt, grid.time(steps)),
        scenario: scene.name.clone(),
        position_tolerance,
        ensemble: reference.ensemble.clone(),
        reference: reference.info,
        dt,
        steps,
        duration: grid.time(steps),
        substeps: cfg
            .frame_substeps
            .map_or(cfg.common.options.substeps, |n| n as usize),
        frame_substeps: cfg.frame_substeps,
        entries,
    })
}

/// The methods asked: by default the scene's own `[run].methods` next to every engine, else
/// every method.
fn asked_methods(scene: &Scenario, cfg: &CompareConfig) -> Vec<String> {
    if cfg.common.methods.is_empty() && !scene.run.methods.is_empty() {
        let ext = cfg
            .common
            .registry
            .engine_names()
            .into_iter()
            .map(String::from);
        scene.run.methods.iter().cloned().chain(ext).collect()
    } else {
        cfg.common.methods.clone()
    }
}

/// The command that re-creates a comparison of `scene` under `cfg` with the methods `asked`,
/// at step `dt` over `duration` (s).
fn command_line(
    scene: &Scenario,
    cfg: &CompareConfig,
    asked: &[String],
    dt: f64,
    duration: f64,
) -> String {
    let listed = asked_or_all(&cfg.common.registry, asked);
    CommandLine::new("compare", &scene.source)
        .flag("dt", dt)
        .flag("duration", duration)
        .flag_opt("substeps", cfg.frame_substeps)
        .flag("series-points", cfg.series_points)
        .switch("trace", cfg.trace)
        .common(&cfg.common, &listed)
        .render()
}

impl Runs<'_> {
    /// The methods of `names` within the budget, if there is one, and the reference's step
    /// limit (`grid` over `horizon`). The budget covers the reference too: refused at once
    /// when its projection alone passes the budget; the runs share what it leaves, and the
    /// reference may spend what they leave. The methods left out go to `skipped`.
    fn budgeted(
        &self,
        names: Vec<String>,
        skipped: &mut Vec<(String, String)>,
        grid: super::grid::TimeGrid,
        horizon: f64,
    ) -> Result<(Vec<String>, Option<f64>)> {
        let Some(b) = self.cfg.common.budget_seconds else {
            return Ok((names, None));
        };
        super::probe::check_budget(b)?;
        let p = super::reference::cost::check(self.sys, self.s0, &[grid], horizon, b)?;
        let left = b - p.seconds;
        let first = skipped.len();
        let (kept, runs) = self.within_budget(names, left, skipped)?;
        for (_, why) in &mut skipped[first..] {
            why.push_str(&format!(
                " (the budget of {} s less about {} s for the reference)",
                super::probe::sig3(b),
                super::probe::sig3(p.seconds)
            ));
        }
        Ok((kept, Some(b - runs)))
    }

    /// The methods of `names` whose runs fit `budget` (s, summed), cheapest first by their
    /// probed price per frame ([`super::probe::seconds_per_frame`]: a frame's
    /// `frame_substeps` are inside it, so `steps` frames cost `steps` times it); the rest go
    /// to `skipped` with the figures. Order is kept. Returns the kept methods and their
    /// projected cost (s) together.
    fn within_budget(
        &self,
        names: Vec<String>,
        budget: f64,
        skipped: &mut Vec<(String, String)>,
    ) -> Result<(Vec<String>, f64)> {
        use super::probe::split_by_budget;
        let costs: Vec<_> = names
            .iter()
            .map(|m| projected_cost(self.sys, self.s0, self.cfg, m, self.dt, self.steps))
            .collect();
        let unit = if self.cfg.frame_substeps.is_some() {
            "frame"
        } else {
            "step"
        };
        let price: Vec<(String, f64)> = names
            .iter()
            .cloned()
            .zip(costs.iter().map(|c| c.projected))
            .collect();
        let (kept, left) = split_by_budget(names, &costs, budget, "its run", unit);
        skipped.extend(left);
        let spent = price
            .iter()
            .filter(|(n, _)| kept.contains(n))
            .map(|(_, c)| c)
            .sum();
        Ok((kept, spent))
    }

    /// What to record of each run for pictures, when asked: the longest paths of the
    /// `reference`, snapshots of a scene with blocks, playback frames of a scene of many
    /// particles.
    fn trace(&self, scene: &Scenario, reference: &Reference) -> Option<TraceSpec> {
        let (cfg, steps) = (self.cfg, self.steps);
        cfg.trace.then(|| TraceSpec {
            tracked: longest_paths(
                reference,
                &self.sys.free,
                if scene.blocks.is_empty() { 2 } else { 1 },
            ),
            stride: steps.div_ceil(cfg.series_points.max(1)).max(1),
            snapshot_steps: if scene.blocks.is_empty() {
                Vec::new()
            } else {
                vec![0, steps / 3, 2 * steps / 3, steps]
            },
            frame_stride: if self.sys.len() > 1 {
                playback_stride(self.dt, steps)
            } else {
                0
            },
        })
    }

    /// Runs the methods `names` against `reference` (in parallel) and lists their entries,
    /// then those `skipped` with why.
    fn entries(
        &self,
        scene: &Scenario,
        reference: &Reference,
        names: &[String],
        skipped: Vec<(String, String)>,
    ) -> Result<Vec<CompareEntry>> {
        let cfg = self.cfg;
        let set = CaseSettings {
            series_points: cfg.series_points,
            repeat_short: true,
            trace: self.trace(scene, reference),
            contacts: true,
            substeps: cfg.frame_substeps,
            ..CaseSettings::measuring(
                cfg.common.registry.clone(),
                cfg.common.options.clone(),
                cfg.common.blowup_factor,
            )
        };
        let pb = crate::run::progress_bar(
            names.len() as u64,
            &format!("compare {}", scene.name),
            cfg.common.progress,
        );
        let runs: Vec<Result<CaseResult>> = names
            .par_iter()
            .map(|n| {
                let r = run_case(self.sys, self.s0, reference, 0, n, &set);
                pb.inc(1);
                r
            })
            .collect();
        pb.finish_and_clear();
        let mut entries: Vec<CompareEntry> = Vec::new();
        for r in runs {
            let r = r?;
            entries.push(CompareEntry {
                method: r.method.clone(),
                status: EntryStatus::Ran(r.status),
                skip_reason: None,
                result: Some(r),
            });
        }
        for (n, why) in skipped {
            entries.push(CompareEntry {
                method: n,
                status: EntryStatus::Skipped,
                skip_reason: Some(why),
                result: None,
            });
        }
        Ok(entries)
    }
}

/// The columns of `compare.csv` before the metrics.
const RUN_COLUMNS: &str =
    "method,status,skip_reason,dt,steps,steps_done,force_evals,modelled_seconds,wall_seconds";

/// The columns of `compare.csv` after the metrics.
const END_COLUMNS: &str = "unstable_time,unstable_reason,reference";

/// The header of `compare.csv`.
pub fn compare_header() -> String {
    format!("{RUN_COLUMNS},{},{END_COLUMNS}", metric_table::csv_header())
}

fn csv_text(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes `compare.csv` and `summary.json` into `dir`.
pub fn write_compare(dir: &Path, res: &CompareResult) -> Result<Vec<PathBuf>> {
    let header = compare_header();
    let mut csv = header.clone();
    csv.push('\n');
    let f = |v: f64| format!("{v:e}");
    for e in &res.entries {
        let mut cells = vec![e.method.clone(), e.status.label().to_string()];
        match &e.result {
            None => {
                cells.push(csv_text(e.skip_reason.as_deref().unwrap_or("")));
                cells.push(f(res.dt));
                cells.extend(["", "", "", "", ""].map(String::from));
                cells.extend(metric_table::csv_cells(None));
                cells.extend(["", ""].map(String::from));
            }
            Some(r) => {
                cells.push(String::new());
                cells.push(f(r.dt));
                cells.push(r.steps.to_string());
                cells.push(r.steps_done.to_string());
                cells.push(r.force_evals.to_string());
                cells.push(f(r.modelled_seconds));
                cells.push(f(r.wall_seconds));
                // Null for a run that is not ok: every accuracy cell is then empty.
                cells.extend(metric_table::csv_cells(r.metrics.as_ref()));
                cells.push(r.unstable_time.map_or(String::new(), f));
                cells.push(csv_text(r.unstable_reason.as_deref().unwrap_or("")));
            }
        }
        cells.push(res.reference.kind.name().to_string());
        debug_assert_eq!(cells.len(), header.split(',').count());
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    let doc = CompareResult {
        command: with_out(&res.command, dir),
        ..res.clone()
    };
    let mut json = serde_json::to_vec_pretty(&doc).expect("serialisable");
    json.push(b'\n');
    let mut files = write_document(dir.join("compare.csv"), csv.as_bytes())?;
    files.extend(write_document(dir.join("summary.json"), &json)?);
    if let Some(c) = contacts_doc(&doc) {
        let mut json = serde_json::to_vec_pretty(&c).expect("serialisable");
        json.push(b'\n');
        files.push(write_atomic(dir.join("contacts.json"), &json)?);
    }
    Ok(files)
}

/// `contacts.json` of a comparison: each method's collision metrics at the compared step.
#[derive(Debug, Clone, Serialize)]
pub struct ContactsDoc<'a> {
    /// The command that re-creates this document (the comparison's).
    pub command: &'a str,
    /// Scenario name.
    pub scenario: &'a str,
    /// Step (s).
    pub dt: f64,
    /// Per method that ran, in the comparison's order.
    pub methods: Vec<MethodContacts<'a>>,
}

/// One method's collision metrics.
#[derive(Debug, Clone, Serialize)]
pub struct MethodContacts<'a> {
    /// Method name.
    pub method: &'a str,
    /// What its contacts did.
    pub report: &'a ContactReport,
}

/// The contacts document of a comparison, `None` for a scene without obstacles.
pub fn contacts_doc(res: &CompareResult) -> Option<ContactsDoc<'_>> {
    let methods: Vec<MethodContacts> = res
        .entries
        .iter()
        .filter_map(|e| e.result.as_ref())
        .filter_map(|r| {
            r.contacts.as_ref().map(|c| MethodContacts {
                method: &r.method,
                report: c,
            })
        })
        .collect();
    (!methods.is_empty()).then(|| ContactsDoc {
        command: &res.command,
        scenario: &res.scenario,
        dt: res.dt,
        methods,
    })
}

/// Frames per simulated second of a compare run's playback frames.
pub const PLAYBACK_FPS: f64 = 30.0;

/// Most playback frames of one run (longer scenes play time-lapsed).
pub const PLAYBACK_MAX_FRAMES: u64 = 150;

/// Steps between playback frames of a run of `steps` steps of `dt`: one frame per
/// 1/[`PLAYBACK_FPS`] s of simulated time, at most [`PLAYBACK_MAX_FRAMES`] frames.
pub fn playback_stride(dt: f64, steps: u64) -> u64 {
    let per_frame = (1.0 / (PLAYBACK_FPS * dt)).round().max(1.0) as u64;
    per_frame.max(steps.div_ceil(PLAYBACK_MAX_FRAMES)).max(1)
}
