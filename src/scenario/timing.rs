//! The one place a scene's step, duration and command-line overrides are resolved: every
//! command and the study call [`Timing::resolve`], so they agree on what "the scene's step"
//! and "the scene's duration" are, and fail the same way when one is missing.

use super::Scenario;
use crate::error::{Error, Result};

/// A resolved step and length of run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Step (s).
    pub dt: f64,
    /// Whole steps covering the duration (≥ 1).
    pub steps: u64,
    /// Simulated time (s) as asked (`steps · dt` up to the rounding of a whole step count).
    pub duration: f64,
}

fn positive(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::option(
            flag,
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

impl Timing {
    /// The step: `dt` (a `--dt` override) or the scene's `[run].dt`.
    pub fn step(scene: &Scenario, dt: Option<f64>) -> Result<f64> {
        match dt.or(scene.run.dt) {
            Some(v) => positive("--dt", v),
            None => Err(Error::option(
                "--dt",
                format!(
                    "{}: no step: give --dt or set [run].dt",
                    scene.source.display()
                ),
            )),
        }
    }

    /// The duration: `duration` (a `--duration` override), else `[run].duration`, else
    /// `[run].steps` × `[run].dt`.
    pub fn duration(scene: &Scenario, duration: Option<f64>) -> Result<f64> {
        Self::length("--duration", scene, duration)
    }

    /// The horizon of a measurement (`advise --horizon`): resolved like [`Timing::duration`],
    /// with errors naming `--horizon`.
    pub fn horizon(scene: &Scenario, horizon: Option<f64>) -> Result<f64> {
        Self::length("--horizon", scene, horizon)
    }

    fn length(flag: &str, scene: &Scenario, duration: Option<f64>) -> Result<f64> {
        let from_steps = scene.run.steps.zip(scene.run.dt).map(|(n, d)| n as f64 * d);
        match duration.or(scene.run.duration).or(from_steps) {
            Some(v) => positive(flag, v),
            None => Err(Error::option(
                flag,
                format!(
                    "{}: no duration: give {flag} or set [run].duration or [run].steps",
                    scene.source.display()
                ),
            )),
        }
    }

    /// Step and duration with their overrides, and the whole number of steps between them.
    pub fn resolve(scene: &Scenario, dt: Option<f64>, duration: Option<f64>) -> Result<Self> {
        let dt = Self::step(scene, dt)?;
        let duration = Self::duration(scene, duration)?;
        let steps = ((duration / dt).round() as u64).max(1);
        if steps > super::MAX_STEPS {
            return Err(Error::option(
                "--dt",
                format!(
                    "{dt} s over {duration} s is {steps} steps, above the limit of {}",
                    super::MAX_STEPS
                ),
            ));
        }
        Ok(Timing {
            dt,
            steps,
            duration,
        })
    }
}
