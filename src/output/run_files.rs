//! `springlab run`'s outputs: `trajectory.csv`, `energy.csv` and `summary.json`.

use super::atomic::{write_atomic, AtomicFile};
use crate::error::{Error, Result};
use crate::model::State;
use crate::run::{EnergyRecord, Observer, RunOutcome, Status};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// An observer streaming `trajectory.csv` (every `every`-th step and the last) and
/// `energy.csv` (same steps) to temporary files; [`RunFiles::commit`] renames them into place.
pub struct RunFiles {
    traj: AtomicFile,
    energy: AtomicFile,
    every: u64,
    last_written: Option<u64>,
    dt: f64,
}

fn werr(file: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |source| Error::Write {
        file: file.to_path_buf(),
        source,
    }
}

impl RunFiles {
    /// Starts both files in `dir`, writing every `every`-th step (`every` ≥ 1).
    pub fn create(dir: &Path, every: u64, dt: f64) -> Result<Self> {
        let mut traj = AtomicFile::create(dir.join("trajectory.csv"))?;
        let mut energy = AtomicFile::create(dir.join("energy.csv"))?;
        let tp = traj.target().to_path_buf();
        writeln!(traj.writer(), "step,t,particle,x,y,z,vx,vy,vz").map_err(werr(&tp))?;
        let ep = energy.target().to_path_buf();
        writeln!(
            energy.writer(),
            "step,t,kinetic,gravity,elastic,dissipated,injected,created,total"
        )
        .map_err(werr(&ep))?;
        Ok(RunFiles {
            traj,
            energy,
            every: every.max(1),
            last_written: None,
            dt,
        })
    }

    fn write(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        if self.last_written == Some(step) {
            return Ok(());
        }
        let t = step as f64 * self.dt;
        let tp = self.traj.target().to_path_buf();
        let w = self.traj.writer();
        for (p, (x, v)) in s.x.iter().zip(&s.v).enumerate() {
            writeln!(
                w,
                "{step},{t},{p},{},{},{},{},{},{}",
                x.x, x.y, x.z, v.x, v.y, v.z
            )
            .map_err(werr(&tp))?;
        }
        let ep = self.energy.target().to_path_buf();
        writeln!(
            self.energy.writer(),
            "{step},{t},{},{},{},{},{},{},{}",
            e.kinetic,
            e.gravity,
            e.elastic,
            e.dissipated,
            e.injected,
            e.created,
            e.total
        )
        .map_err(werr(&ep))?;
        self.last_written = Some(step);
        Ok(())
    }

    /// Renames both files into place; returns their paths.
    pub fn commit(self) -> Result<Vec<PathBuf>> {
        Ok(vec![self.traj.commit()?, self.energy.commit()?])
    }
}

impl Observer for RunFiles {
    fn observe(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        if step % self.every == 0 {
            self.write(step, s, e)?;
        }
        Ok(())
    }
    fn finish(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        self.write(step, s, e)
    }
}

/// `summary.json` of one run.
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    /// Scenario name.
    pub scenario: String,
    /// Integrator or backend name.
    pub integrator: String,
    /// Frame step (s): the step of every output row.
    pub dt: f64,
    /// Frames asked for.
    pub steps: u64,
    /// Substeps per frame (native methods: equal steps of dt/substeps; Rapier: its solver
    /// substeps).
    pub substeps: u64,
    /// When impulses took effect: `exact` or `frame` (the scene's `[run] events`).
    pub events: &'static str,
    /// Frames completed.
    pub steps_done: u64,
    /// Force evaluations (every substep's).
    pub force_evals: u64,
    /// Wall time inside the integrator (s).
    pub wall_seconds: f64,
    /// Wall time inside the integrator per completed frame (s).
    pub wall_seconds_per_frame: f64,
    /// `ok` or `unstable`.
    pub status: &'static str,
    /// For unstable runs: step, time and reason.
    pub unstable: Option<Status>,
    /// Energy account at t = 0.
    pub initial_energy: EnergyRecord,
    /// Energy account at the last accepted step.
    pub final_energy: EnergyRecord,
    /// Change of the energy balance (`total`) over the run (J); `None` when the run stopped
    /// before its last frame (diverged or past the cap): there is no balance over the run.
    pub energy_change: Option<f64>,
    /// `energy_change` relative to the initial |kinetic| + |gravity| + |elastic|; `None` when
    /// the run stopped, or when those are all 0 (a scene starting at rest at the origin of its
    /// potentials), where only the change in joules means anything.
    pub energy_error: Option<f64>,
}

impl RunSummary {
    /// Summarises an outcome of one step per frame with exact events (set `substeps` and
    /// `events` afterwards for other runs).
    pub fn new(scenario: &str, integrator: &str, dt: f64, steps: u64, out: &RunOutcome) -> Self {
        let e0 = out.initial_energy;
        let scale = e0.kinetic.abs() + e0.gravity.abs() + e0.elastic.abs();
        let d = out.final_energy.total - e0.total;
        let finished = out.steps_done == steps;
        RunSummary {
            scenario: scenario.into(),
            integrator: integrator.into(),
            dt,
            steps,
            substeps: 1,
            events: "exact",
            steps_done: out.steps_done,
            force_evals: out.force_evals,
            wall_seconds: out.wall_seconds,
            wall_seconds_per_frame: out.wall_seconds / out.steps_done.max(1) as f64,
            status: out.status.label(),
            unstable: (!out.status.is_ok()).then(|| out.status.clone()),
            initial_energy: e0,
            final_energy: out.final_energy,
            energy_change: finished.then_some(d),
            energy_error: (finished && scale > 0.0).then(|| d / scale),
        }
    }
}

/// Writes `summary.json` into `dir` atomically.
pub fn write_run(dir: &Path, summary: &RunSummary) -> Result<PathBuf> {
    let json = serde_json::to_vec_pretty(summary).expect("summary serialises");
    write_atomic(dir.join("summary.json"), &json)
}
