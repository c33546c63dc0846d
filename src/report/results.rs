//! What the report collects per scene, before it becomes charts and tables: runs with their
//! decimated time series, the step-size sweep and the stability scan (serde, so the same
//! shapes can come from `measure` once it lands).

use crate::run::{EnergyRecord, Status};
use serde::Serialize;

/// One sample of a run on the report's decimated time grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Energy account at `t`.
    pub energy: EnergyRecord,
    /// RMS position error of the free particles against the reference (m), when known.
    pub pos_error: Option<f64>,
}

/// One backend run at the scene's step.
#[derive(Debug, Clone, Serialize)]
pub struct RunRecord {
    /// Integrator or backend name.
    pub backend: String,
    /// Its theoretical order.
    pub order: u32,
    /// How it ended.
    pub status: Status,
    /// Accepted steps.
    pub steps_done: u64,
    /// Force evaluations made.
    pub force_evals: u64,
    /// Wall time inside the integrator (s); not reproducible bit for bit.
    pub wall_seconds: f64,
    /// Decimated samples (every accepted sample step, and the last accepted step).
    pub samples: Vec<Sample>,
    /// Positions of the tracked particles at each sample, `paths[p][k]`.
    pub paths: Vec<Vec<[f64; 3]>>,
    /// Full snapshots (time, all positions) for chains and cloths.
    pub snapshots: Vec<(f64, Vec<[f64; 3]>)>,
    /// Collision metrics (contact events, bounces, penetration), for scenes with obstacles.
    pub contacts: Option<crate::measure::contacts::ContactReport>,
}

/// A backend the scene could not use, and why.
#[derive(Debug, Clone, Serialize)]
pub struct Skipped {
    /// Integrator or backend name.
    pub backend: String,
    /// The reason it gave.
    pub reason: String,
}

/// One run of the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SweepPoint {
    /// Step (s).
    pub dt: f64,
    /// RMS position error at the end against the sweep reference (m); `None` when unstable.
    pub error: Option<f64>,
    /// Blow-up time when the run blew up.
    pub blowup_time: Option<f64>,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Force evaluations.
    pub force_evals: u64,
}

/// One integrator's sweep over step sizes.
#[derive(Debug, Clone, Serialize)]
pub struct SweepLine {
    /// Integrator name.
    pub integrator: String,
    /// Theoretical order.
    pub order: u32,
    /// Points, coarsest step first.
    pub points: Vec<SweepPoint>,
}

/// The step-size sweep of a scene.
#[derive(Debug, Clone, Serialize)]
pub struct Sweep {
    /// Simulated time of every sweep run (s), a whole number of the coarsest step.
    pub duration: f64,
    /// The reference the errors are taken against, in words.
    pub reference: String,
    /// One line per integrator.
    pub lines: Vec<SweepLine>,
}

/// One integrator's row of the stability scan.
#[derive(Debug, Clone, Serialize)]
pub struct ScanRow {
    /// Integrator name.
    pub integrator: String,
    /// (h·ω, dt, stable) in increasing h·ω.
    pub cells: Vec<(f64, f64, bool)>,
    /// Textbook limit on h·ω for the undamped linear oscillator (∞: always, 0: never stable).
    pub theory: Option<f64>,
}

/// The stability scan of a scene.
#[derive(Debug, Clone, Serialize)]
pub struct Scan {
    /// ω the step is scaled by (rad/s).
    pub omega: f64,
    /// How ω was obtained.
    pub omega_note: String,
    /// Simulated time per scan run is the scene's duration, capped at this many steps.
    pub max_steps: u64,
    /// One row per integrator.
    pub rows: Vec<ScanRow>,
}

/// Everything collected for one scene.
#[derive(Debug, Clone, Serialize)]
pub struct SceneResults {
    /// Scene name.
    pub scene: String,
    /// Scene description.
    pub description: String,
    /// Step of the comparison runs (s).
    pub dt: f64,
    /// Planned steps of the comparison runs.
    pub steps: u64,
    /// The reference of the comparison, in words.
    pub reference: String,
    /// Energy scale the relative energy error divides by (J).
    pub energy_scale: f64,
    /// Comparison runs, in registry order.
    pub runs: Vec<RunRecord>,
    /// Backends that refused the scene.
    pub skipped: Vec<Skipped>,
    /// Step-size sweep, when any integrator applies.
    pub sweep: Option<Sweep>,
    /// Stability scan, when the scene has springs.
    pub scan: Option<Scan>,
    /// Indices of the two coordinate axes of the scene's main plane.
    pub plane: [usize; 2],
    /// Tracked particle indices (the `paths` of each run).
    pub tracked: Vec<usize>,
    /// Chains and cloths, for snapshots.
    pub blocks: Vec<crate::scenario::Block>,
}
