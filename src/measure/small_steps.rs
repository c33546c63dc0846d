//! "Small Steps in Physics Simulation" (Macklin et al., SCA 2019), replicated: at a fixed
//! frame step, does XPBD with n substeps × 1 iteration beat 1 step × n iterations at equal
//! cost (n constraint sweeps per frame)?
//!
//! For each scene and each budget n, both splits run the scene's duration at the frame step
//! and are compared at every frame with the scene's reference solution
//! ([`Reference::compute`]: DOP853 at 1e-12 for spring scenes, with its own uncertainty):
//! position error (max over particles, then over the frames within the reference's
//! predictable range), stretch error (the largest relative spring extension (|d| − L)/L of a
//! frame against the reference's at the same frame: a compliant scene stretches physically,
//! so less stretch is not better, closer is), the energy the position solve removed (numerical
//! dissipation: E₀ − E_end − booked dissipation), and cost (constraint sweeps and wall time).
//! Each budget gets a verdict per measure, and the scene a sentence saying where the paper's
//! claim holds and where it does not.

use crate::error::{Error, Result};
use crate::integrate::Xpbd;
use crate::measure::reference::{Reference, ReferenceInfo};
use crate::method::Registry;
use crate::model::{State, System, Vec3};
use crate::run::{run_with, EnergyRecord, Observer, RunPlan, Status};
use crate::scenario::Scenario;
use serde::Serialize;

/// The registered method these runs are: its facts say how it meets the runner.
pub(crate) const XPBD: &str = "xpbd";

/// The paper's frame rate: 60 Hz.
pub const FRAME_DT: f64 = 1.0 / 60.0;

/// The scene files the comparison runs on by default (in the shipped scenario folder): a stiff
/// chain and the cloth, the two the report's Small Steps page shows.
pub const DEFAULT_SCENES: [&str; 2] = ["stiff_chain.toml", "cloth.toml"];

/// Default budgets n (sweeps per frame).
pub const DEFAULT_BUDGETS: [usize; 7] = [1, 2, 4, 8, 16, 32, 64];

/// What to measure.
#[derive(Debug, Clone, PartialEq)]
pub struct SmallStepsConfig {
    /// Frame step (s).
    pub frame_dt: f64,
    /// Simulated time (s); `None`: the scene's `[run]` duration.
    pub duration: Option<f64>,
    /// Budgets n: sweeps per frame, each run as n substeps × 1 iteration and 1 step × n
    /// iterations.
    pub budgets: Vec<usize>,
    /// Time budget (modelled seconds) of each scene's runs and reference, checked before they
    /// start ([`super::small_steps_budget`]); `None`: none.
    pub budget_seconds: Option<f64>,
}

impl Default for SmallStepsConfig {
    fn default() -> Self {
        SmallStepsConfig {
            frame_dt: FRAME_DT,
            duration: None,
            budgets: DEFAULT_BUDGETS.to_vec(),
            budget_seconds: None,
        }
    }
}

/// One split of a budget: `substeps` × `iterations` per frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SplitRun {
    /// Substeps per frame.
    pub substeps: usize,
    /// Gauss–Seidel sweeps per substep.
    pub iterations: usize,
    /// Constraint sweeps over the whole run (substeps × iterations × frames).
    pub sweeps: u64,
    /// Wall time of the steps alone (s).
    pub wall_seconds: f64,
    /// Largest position error (m): max over particles, then over the compared frames.
    pub error_max: Option<f64>,
    /// Position error at the last compared frame (m).
    pub error_final: Option<f64>,
    /// Largest relative spring extension (|d| − L)/L over springs and frames.
    pub stretch_max: Option<f64>,
    /// Mean over frames of the largest relative extension.
    pub stretch_mean: Option<f64>,
    /// Largest |stretch − reference stretch| over the compared frames, where stretch is a
    /// frame's largest relative extension.
    pub stretch_error: Option<f64>,
    /// Energy the position solve removed (J): E₀ − E_end − booked dissipation.
    pub numerical_dissipation: Option<f64>,
    /// `ok`, or why the run stopped (non-finite state).
    pub status: String,
}

/// Both splits of one budget and which is better on each measure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Budget {
    /// Sweeps per frame.
    pub n: usize,
    /// n substeps × 1 iteration.
    pub substeps: SplitRun,
    /// 1 step × n iterations.
    pub iterations: SplitRun,
    /// Substeps have the smaller error (None when either run failed).
    pub substeps_lower_error: Option<bool>,
    /// Substeps have the smaller stretch error.
    pub substeps_lower_stretch_error: Option<bool>,
    /// Wall time of the substeps split over that of the iterations split: equal sweeps are
    /// not equal wall time (each substep also predicts, updates velocities and sums the
    /// dampers' power).
    pub wall_ratio: f64,
}

/// One scene's comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneSmallSteps {
    /// Scene name.
    pub scene: String,
    /// Frame step (s).
    pub frame_dt: f64,
    /// Simulated time (s).
    pub duration: f64,
    /// Frames compared with the reference (those before its predictability horizon).
    pub compared_frames: u64,
    /// The reference used.
    pub reference: ReferenceInfo,
    /// Largest relative spring extension of the reference over the frames.
    pub reference_stretch_max: f64,
    /// One entry per budget.
    pub budgets: Vec<Budget>,
    /// True when substeps win on position error and on stretch error at every budget n > 1.
    pub claim_holds: bool,
    /// Where the claim holds and where it does not, in words.
    pub verdict: String,
}

/// The whole document.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SmallSteps {
    /// The command line that re-creates it.
    pub command: String,
    /// One entry per scene.
    pub scenes: Vec<SceneSmallSteps>,
}

/// Largest relative extension (|d| − L)/L over the springs of `sys` (0 without springs).
pub fn stretch(sys: &System, x: &[Vec3]) -> f64 {
    let sp = &sys.springs;
    (0..sp.len())
        .filter(|&s| sp.l0[s] > 0.0)
        .map(|s| ((x[sp.j[s] as usize] - x[sp.i[s] as usize]).norm() - sp.l0[s]) / sp.l0[s])
        .fold(0.0, f64::max)
}

/// Watches one split's frames: stretch over every frame, error against the reference over
/// the compared ones.
struct SplitObserver<'a> {
    sys: &'a System,
    reference: &'a Reference,
    compared: u64,
    err_max: f64,
    err_final: f64,
    st_max: f64,
    st_sum: f64,
    st_err: f64,
}

impl Observer for SplitObserver<'_> {
    fn observe(&mut self, f: u64, s: &State, _e: &EnergyRecord) -> Result<()> {
        if f == 0 {
            return Ok(());
        }
        let st = stretch(self.sys, &s.x);
        self.st_max = self.st_max.max(st);
        self.st_sum += st;
        if f <= self.compared {
            if let Some(xr) = self.reference.positions(0, f) {
                let e = crate::measure::metrics::position_error(&s.x, xr);
                self.err_max = self.err_max.max(e);
                self.err_final = e;
                self.st_err = self.st_err.max((st - stretch(self.sys, xr)).abs());
            }
        }
        Ok(())
    }
}

/// Runs one split against the reference, through the runner and its one verdict.
fn run_split(
    sys: &System,
    s0: &State,
    reference: &Reference,
    frames: u64,
    compared: u64,
    frame_dt: f64,
    (substeps, iterations): (usize, usize),
) -> Result<SplitRun> {
    let mut stepper = Xpbd::new(substeps, iterations);
    let mut obs = SplitObserver {
        sys,
        reference,
        compared,
        err_max: 0.0,
        err_final: 0.0,
        st_max: 0.0,
        st_sum: 0.0,
        st_err: 0.0,
    };
    let registry = Registry::builtin();
    let out = run_with(
        sys,
        &mut stepper,
        registry.info(XPBD)?,
        s0.clone(),
        &RunPlan::new(frame_dt, frames),
        &mut obs,
    )?;
    let (status, ok) = match &out.status {
        Status::Ok => ("ok".to_string(), true),
        Status::Unstable { step, reason, .. } => {
            (format!("unstable at frame {step}: {reason}"), false)
        }
    };
    let (e0, e1) = (out.initial_energy, out.final_energy);
    Ok(SplitRun {
        substeps,
        iterations,
        sweeps: stepper.sweeps,
        wall_seconds: out.wall_seconds,
        error_max: ok.then_some(obs.err_max),
        error_final: ok.then_some(obs.err_final),
        stretch_max: ok.then_some(obs.st_max),
        stretch_mean: ok.then_some(obs.st_sum / frames as f64),
        stretch_error: ok.then_some(obs.st_err),
        numerical_dissipation: ok
            .then_some(e0.mechanical() - e1.mechanical() - (e1.dissipated - e0.dissipated)),
        status,
    })
}

fn lower(a: Option<f64>, b: Option<f64>) -> Option<bool> {
    Some(a? < b?)
}

/// In words: at which budgets substeps win or lose on each measure.
fn verdict(budgets: &[Budget]) -> (bool, String) {
    let mut lose = Vec::new();
    let mut unknown = Vec::new();
    for b in budgets.iter().filter(|b| b.n > 1) {
        match (b.substeps_lower_error, b.substeps_lower_stretch_error) {
            (Some(true), Some(true)) => {}
            (Some(e), Some(s)) => {
                let what = match (e, s) {
                    (false, false) => "position and stretch error",
                    (false, true) => "position error",
                    _ => "stretch error",
                };
                lose.push(format!("n = {} ({what})", b.n));
            }
            _ => unknown.push(format!("n = {}", b.n)),
        }
    }
    let holds = lose.is_empty() && unknown.is_empty();
    // Equal sweeps are not equal wall time; the measured ratios (`wall_ratio`) are kept in
    // timing.json, apart from this text, which a re-run reproduces.
    let cost = if budgets.iter().any(|b| b.n > 1) {
        " (at equal constraint sweeps; each split's wall time is in timing.json)".to_string()
    } else {
        String::new()
    };
    let text = if holds {
        "the claim holds: at every budget n > 1, n substeps × 1 iteration have a smaller position error and a smaller stretch error than 1 step × n iterations".to_string()
    } else {
        let mut parts = Vec::new();
        if !lose.is_empty() {
            parts.push(format!(
                "1 step × n iterations does as well or better at {}",
                lose.join(", ")
            ));
        }
        if !unknown.is_empty() {
            parts.push(format!(
                "a run failed (no comparison) at {}",
                unknown.join(", ")
            ));
        }
        format!("the claim does not hold everywhere: {}", parts.join("; "))
    };
    (holds, text + &cost)
}

/// The comparison on one scene.
pub fn small_steps_scene(scene: &Scenario, cfg: &SmallStepsConfig) -> Result<SceneSmallSteps> {
    if !(cfg.frame_dt.is_finite() && cfg.frame_dt > 0.0) {
        return Err(Error::option(
            "--dt",
            format!(
                "must be a finite number > 0, got {}",
                crate::error::num(cfg.frame_dt)
            ),
        ));
    }
    if cfg.budgets.is_empty() || cfg.budgets.contains(&0) {
        return Err(Error::option(
            "--budgets",
            "must be a non-empty list of whole numbers ≥ 1",
        ));
    }
    let duration = crate::scenario::Timing::duration(scene, cfg.duration)?;
    let flag = if cfg.duration.is_some() {
        "--duration"
    } else {
        "--dt"
    };
    // A frame longer than the run is refused as `run` refuses it, before any reference solve.
    crate::scenario::Timing::step_fits(scene, cfg.frame_dt, Some(flag), duration)?;
    let frames = crate::scenario::Timing::steps_within(flag, cfg.frame_dt, duration)?;
    super::small_steps_budget::check_steps(&cfg.budgets, frames, cfg.frame_dt)?;
    let sys = scene.build();
    let s0 = scene.initial_state();
    // Every frame compared while the reference's samples fit memory (compare's grid).
    let grid = crate::measure::grid::run_grid(cfg.frame_dt, frames, sys.len());
    let limit = match cfg.budget_seconds {
        Some(b) => Some(super::small_steps_budget::check(
            &sys,
            &s0,
            &grid,
            &cfg.budgets,
            b,
        )?),
        None => None,
    };
    let reference = Reference::compute_within(&sys, &s0, &[grid], grid.time(frames), limit)?;
    let compared = match reference.info.predictability_horizon {
        Some(h) => (1..=frames)
            .take_while(|&f| grid.time(f) < h)
            .last()
            .unwrap_or(0),
        None => frames,
    };
    let reference_stretch_max = (1..=frames)
        .filter_map(|f| reference.positions(0, f))
        .map(|x| stretch(&sys, x))
        .fold(0.0, f64::max);
    let budgets: Vec<Budget> = cfg
        .budgets
        .iter()
        .map(|&n| {
            let run =
                |split| run_split(&sys, &s0, &reference, frames, compared, cfg.frame_dt, split);
            let (sub, it) = (run((n, 1))?, run((1, n))?);
            Ok(Budget {
                n,
                substeps_lower_error: lower(sub.error_max, it.error_max),
                substeps_lower_stretch_error: lower(sub.stretch_error, it.stretch_error),
                wall_ratio: sub.wall_seconds / it.wall_seconds.max(f64::MIN_POSITIVE),
                substeps: sub,
                iterations: it,
            })
        })
        .collect::<Result<_>>()?;
    let (claim_holds, verdict) = verdict(&budgets);
    Ok(SceneSmallSteps {
        scene: scene.name.clone(),
        frame_dt: cfg.frame_dt,
        duration: grid.time(frames),
        compared_frames: compared,
        reference: reference.info.clone(),
        reference_stretch_max,
        budgets,
        claim_holds,
        verdict,
    })
}

/// The comparison on every scene, with the command line that re-creates it.
pub fn small_steps(scenes: &[Scenario], cfg: &SmallStepsConfig) -> Result<SmallSteps> {
    let mut words = vec!["springlab".to_string(), "small-steps".to_string()];
    words.extend(scenes.iter().map(|s| s.source.display().to_string()));
    let mut cmd = words
        .iter()
        .map(|w| super::command::shell_word(w))
        .collect::<Vec<_>>()
        .join(" ");
    cmd += &format!(" --dt {}", cfg.frame_dt);
    if let Some(d) = cfg.duration {
        cmd += &format!(" --duration {d}");
    }
    let b: Vec<String> = cfg.budgets.iter().map(|n| n.to_string()).collect();
    cmd += &format!(" --budgets {}", b.join(","));
    if let Some(budget) = cfg.budget_seconds {
        cmd += &format!(" --budget {budget}");
    }
    Ok(SmallSteps {
        command: cmd,
        scenes: scenes
            .iter()
            .map(|s| small_steps_scene(s, cfg))
            .collect::<Result<_>>()?,
    })
}

/// CSV header of [`to_csv`].
pub const CSV_HEADER: &str = "scene,n,substeps,iterations,sweeps,wall_seconds,error_max,error_final,stretch_max,stretch_mean,stretch_error,numerical_dissipation,status";

/// One row per run (both splits of every budget of every scene); empty cells where a run
/// failed.
pub fn to_csv(doc: &SmallSteps) -> String {
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for sc in &doc.scenes {
        for b in &sc.budgets {
            for r in [&b.substeps, &b.iterations] {
                out += &format!(
                    "{},{},{},{},{},{:e},{},{},{},{},{},{},{}\n",
                    sc.scene,
                    b.n,
                    r.substeps,
                    r.iterations,
                    r.sweeps,
                    r.wall_seconds,
                    opt(r.error_max),
                    opt(r.error_final),
                    opt(r.stretch_max),
                    opt(r.stretch_mean),
                    opt(r.stretch_error),
                    opt(r.numerical_dissipation),
                    super::command::shell_word(&r.status).replace(',', ";"),
                );
            }
        }
    }
    out
}

/// Writes `small_steps.json` (with its `"command"` naming `dir` as `--out`) and
/// `small_steps.csv` into `dir`, atomically; returns the two paths.
pub fn write_small_steps(
    dir: &std::path::Path,
    doc: &SmallSteps,
) -> Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| crate::error::Error::Write {
        file: dir.to_path_buf(),
        source: e,
    })?;
    let doc = SmallSteps {
        command: super::command::with_out(&doc.command, dir),
        ..doc.clone()
    };
    let mut json = serde_json::to_vec_pretty(&doc).expect("serialisable");
    json.push(b'\n');
    let mut files = crate::output::write_document(dir.join("small_steps.json"), &json)?;
    files.extend(crate::output::write_document(
        dir.join("small_steps.csv"),
        to_csv(&doc).as_bytes(),
    )?);
    Ok(files)
}
