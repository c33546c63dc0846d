//! `springlab run`'s outputs: `trajectory.csv`, `energy.csv` and `summary.json`.

use super::atomic::AtomicFile;
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
    /// Method name.
    pub method: String,
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
    /// The work the run counted.
    pub work: crate::run::Work,
    /// Modelled seconds of that work ([`crate::run::cost`]).
    pub modelled_seconds: f64,
    /// Stepping wall time (s; kept in `timing.json`).
    pub wall_seconds: f64,
    /// Stepping wall time per completed frame (s; kept in `timing.json`).
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
    /// Largest strain |l/l0 − 1| of any spring (l0 > 0) or distance constraint over the run
    /// (the measure layer's quality observables, as `compare` reports them); `None` for a run
    /// that is not ok, like the three below.
    pub strain_max: Option<f64>,
    /// Deepest penetration into any obstacle (m), as `contacts.json` has it; `None` also for a
    /// scene without obstacles.
    pub penetration_max: Option<f64>,
    /// Least-squares slope of the energy balance `total` − its initial value (J/s).
    pub energy_drift_rate: Option<f64>,
    /// Kinetic energy at the last frame over the scene's energy scale (meaningful for scenes
    /// that come to rest).
    pub rest_jitter: Option<f64>,
}

impl RunSummary {
    /// Summarises an outcome of one step per frame with exact events (set `substeps` and
    /// `events` afterwards for other runs, and the quality observables where they were
    /// measured).
    pub fn new(scenario: &str, method: &str, dt: f64, steps: u64, out: &RunOutcome) -> Self {
        let e0 = out.initial_energy;
        let scale = e0.kinetic.abs() + e0.gravity.abs() + e0.elastic.abs();
        let d = out.final_energy.total - e0.total;
        let finished = out.steps_done == steps;
        RunSummary {
            scenario: scenario.into(),
            method: method.into(),
            dt,
            steps,
            substeps: 1,
            events: "exact",
            steps_done: out.steps_done,
            force_evals: out.force_evals,
            work: out.work,
            modelled_seconds: out.modelled_seconds,
            wall_seconds: out.wall_seconds,
            wall_seconds_per_frame: out.wall_seconds / out.steps_done.max(1) as f64,
            status: out.status.label(),
            unstable: (!out.status.is_ok()).then(|| out.status.clone()),
            initial_energy: e0,
            final_energy: out.final_energy,
            energy_change: finished.then_some(d),
            energy_error: (finished && scale > 0.0).then(|| d / scale),
            strain_max: None,
            penetration_max: None,
            energy_drift_rate: None,
            rest_jitter: None,
        }
    }
}

/// Writes `summary.json` into `dir` atomically, its wall times in `timing.json`
/// ([`super::timing`]); returns the files written.
pub fn write_run(dir: &Path, summary: &RunSummary) -> Result<Vec<PathBuf>> {
    let json = serde_json::to_vec_pretty(summary).expect("summary serialises");
    super::timing::write_document(dir.join("summary.json"), &json)
}

/// Bytes of one output number as `run` prints it (a shortest round-trip decimal of a value of
/// order one, e.g. `-0.1234567890123456`); measured on the shipped cloth, see
/// [`projected_run_bytes`].
const NUMBER_BYTES: u64 = 17;

/// Output rows (frames) `run` writes for `steps` frames at every `every`-th step: step 0, every
/// multiple of `every` and the last step.
pub fn written_frames(steps: u64, every: u64) -> u64 {
    let every = every.max(1);
    steps / every + 1 + u64::from(steps % every != 0)
}

fn digits(n: u64) -> u64 {
    n.checked_ilog10().map_or(1, |d| d as u64 + 1)
}

/// Projected bytes of `trajectory.csv` and `energy.csv` of a run of `particles` particles over
/// `steps` frames writing every `every`-th: rows × bytes per row, a row being its step, time
/// and particle index then six numbers (trajectory) or seven (energy). Within about 10 % of
/// the files a cloth writes (7 % over for the shipped cloth's 1 s; tested on a 30×30 cloth in
/// `tests/cli/output_lock.rs`).
pub fn projected_run_bytes(particles: usize, steps: u64, every: u64) -> (u64, u64) {
    let frames = written_frames(steps, every);
    let lead = digits(steps) + 1 + NUMBER_BYTES + 1;
    let traj_row = lead + digits(particles.max(1) as u64 - 1) + 1 + 6 * NUMBER_BYTES + 6;
    // `injected` and `created` are mostly 0 (no impulse, no contact): one byte each.
    let energy_row = lead + 5 * NUMBER_BYTES + 2 + 7;
    (frames * particles as u64 * traj_row, frames * energy_row)
}

/// The smallest `--every` at or above `every` whose projected outputs stay within `limit`
/// bytes, if any does (the first and last rows are always written).
pub fn every_within(particles: usize, steps: u64, every: u64, limit: u64) -> Option<u64> {
    let total = |k: u64| {
        let (t, e) = projected_run_bytes(particles, steps, k);
        t + e
    };
    if total(steps.max(1)) > limit {
        return None;
    }
    // Every k below total(1) / limit is too large (rows(k) · k ≥ rows(1)): start there.
    let mut k = every.max(1).max(total(1) / limit.max(1));
    while total(k) > limit {
        k += 1;
    }
    Some(k)
}

/// Projected outputs above this many bytes draw a warning from `run` (100 MB).
pub const SIZE_WARNING_BYTES: u64 = 100_000_000;

/// A byte count in decimal units (`1.38 GB`, `412.00 kB`, `145.53 TB`).
pub fn human_bytes(b: u64) -> String {
    let units = [(1e12, "TB"), (1e9, "GB"), (1e6, "MB"), (1e3, "kB")];
    for (scale, unit) in units {
        if b as f64 >= scale {
            return format!("{:.2} {unit}", b as f64 / scale);
        }
    }
    format!("{b} B")
}

#[cfg(test)]
mod size_tests {
    use super::*;

    // Oracle: counting by hand. 10 steps at every 3 writes steps 0, 3, 6, 9 and the last (10);
    // at every 5 steps 0, 5, 10; at every 1 all eleven.
    #[test]
    fn written_frames_counts_the_first_the_multiples_and_the_last() {
        assert_eq!(written_frames(10, 3), 5);
        assert_eq!(written_frames(10, 5), 3);
        assert_eq!(written_frames(10, 1), 11);
        assert_eq!(written_frames(0, 4), 1);
    }

    // Oracle: the definition of the suggestion, checked by brute force: the suggested k is
    // within the limit and every smaller k at or above `every` is not.
    #[test]
    fn every_within_is_the_smallest_that_fits() {
        let (p, steps, limit) = (1024, 10_000, 100_000_000);
        let k = every_within(p, steps, 1, limit).unwrap();
        let total = |k| {
            let (t, e) = projected_run_bytes(p, steps, k);
            t + e
        };
        assert!(total(k) <= limit);
        assert!((1..k).all(|j| total(j) > limit), "k = {k}");
        assert_eq!(every_within(p, steps, 1, 1), None);
    }
}
