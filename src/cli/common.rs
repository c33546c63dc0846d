//! Flags shared by several subcommands and their validation into library values.

use anyhow::{bail, Result};
use springlab::integrate::IntegratorOptions;
use springlab::run::RunPlan;
use springlab::scenario::{Scenario, Timing};
use std::path::PathBuf;

/// Step and length flags; each overrides the scenario's `[run]` table.
#[derive(Debug, Clone, clap::Args)]
pub struct StepArgs {
    /// Time step in seconds (overrides [run].dt).
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    /// Number of steps (overrides [run].steps / duration).
    #[arg(long, conflicts_with = "duration")]
    pub steps: Option<u64>,
    /// Simulated time in seconds (overrides [run].steps / duration).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    #[command(flatten)]
    pub blowup: super::measure_common::BlowupArg,
    /// Constraint projection sweeps per step for verlet_constraints.
    #[arg(long, default_value_t = 20)]
    pub iterations: usize,
    /// Solver substeps per frame for Rapier backends.
    #[arg(long, default_value_t = 4)]
    pub substeps: usize,
    #[command(flatten)]
    pub xpbd: super::xpbd_args::XpbdArgs,
}

impl StepArgs {
    /// The run plan: flags first, then the scenario's `[run]`, else an error saying what to add.
    pub fn plan(&self, scene: &Scenario) -> Result<RunPlan> {
        let dt = match self.dt.or(scene.run.dt) {
            Some(dt) => dt,
            None => bail!(
                "{}: no time step: give --dt or set [run].dt",
                scene.source.display()
            ),
        };
        if !(dt.is_finite() && dt > 0.0) {
            bail!("--dt: must be a finite number > 0, got {dt}");
        }
        if let Some(d) = self.duration {
            if !(d.is_finite() && d > 0.0) {
                bail!("--duration: must be a finite number > 0, got {d}");
            }
        }
        if self.steps == Some(0) {
            bail!("--steps: must be at least 1");
        }
        let blowup_factor = self.blowup.value()?;
        if self.iterations == 0 {
            bail!("--iterations: must be at least 1");
        }
        if self.substeps == 0 {
            bail!("--substeps: must be at least 1");
        }
        self.xpbd.values()?;
        let mut plan = if let Some(n) = self.steps {
            RunPlan::new(dt, n)
        } else if let Some(d) = self.duration.or(scene.run.duration) {
            Timing::step_fits(scene, dt, self.dt.is_some(), d)?;
            RunPlan::for_duration(dt, d)
        } else if let Some(n) = scene.run.steps {
            RunPlan::new(dt, n)
        } else {
            bail!("{}: no run length: give --steps or --duration, or set [run].steps or [run].duration", scene.source.display());
        };
        if plan.steps > springlab::scenario::MAX_STEPS {
            bail!(
                "run length: {} steps exceeds the limit of {}",
                plan.steps,
                springlab::scenario::MAX_STEPS
            );
        }
        Timing::check_impulses(scene, plan.duration())?;
        plan.blowup_factor = blowup_factor;
        Ok(plan)
    }

    /// Integrator options from the flags.
    pub fn options(&self) -> IntegratorOptions {
        IntegratorOptions {
            constraint_iterations: self.iterations,
            substeps: self.substeps,
            xpbd_substeps: self.xpbd.xpbd_substeps,
            xpbd_iterations: self.xpbd.xpbd_iterations,
        }
    }
}

/// Loads a scenario, adding nothing to the library's error (it already names the file).
pub fn load(path: &PathBuf) -> Result<Scenario> {
    Ok(Scenario::from_file(path)?)
}
