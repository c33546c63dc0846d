//! The one place a scene's step, duration and command-line overrides are resolved: every
//! command and the study call [`Timing::resolve_asked`] (or [`Timing::resolve`], its form
//! for a step and a duration), so they agree on what "the scene's step"
//! and "the scene's duration" are, and fail the same way when one is missing.
//!
//! Nothing is clipped silently: a step longer than the duration is an error (a run never
//! goes past its duration), and so is an impulse the run would never apply (at or after its
//! end, [`Timing::check_impulses`]).

use super::Scenario;
use crate::error::{num, Error, Result};

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

/// What a command asked of the step and the run's length; each `None` takes the scene's
/// `[run]` value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Asked {
    /// The step (s), from `step_flag`.
    pub dt: Option<f64>,
    /// The flag that gives the step (`--dt`, or `--hz` when the step is 1/hz), named in errors.
    pub step_flag: &'static str,
    /// A whole number of steps (`--steps`), instead of a duration.
    pub steps: Option<u64>,
    /// The simulated time (s, `--duration`).
    pub duration: Option<f64>,
}

impl Default for Asked {
    fn default() -> Self {
        Asked {
            dt: None,
            step_flag: "--dt",
            steps: None,
            duration: None,
        }
    }
}

fn positive(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::option(
            flag,
            format!("must be a finite number > 0, got {}", num(v)),
        ))
    }
}

impl Timing {
    /// The step: `dt` (a `--dt` override) or the scene's `[run].dt`.
    pub fn step(scene: &Scenario, dt: Option<f64>) -> Result<f64> {
        Self::step_from(scene, dt, "--dt")
    }

    fn step_from(scene: &Scenario, dt: Option<f64>, flag: &str) -> Result<f64> {
        match dt.or(scene.run.dt) {
            Some(v) => positive(flag, v),
            None => Err(Error::option(
                flag,
                format!(
                    "{}: no step: give {flag} or set [run].dt",
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
        Self::length_with(flag, scene, duration, scene.run.dt)
    }

    /// The length as [`Timing::duration`] resolves it, `[run].steps` counted in `step` (the
    /// scene's own `[run].dt` when it has one, else the step the command was given).
    fn length_with(
        flag: &str,
        scene: &Scenario,
        duration: Option<f64>,
        step: Option<f64>,
    ) -> Result<f64> {
        let from_steps = scene
            .run
            .steps
            .zip(scene.run.dt.or(step))
            .map(|(n, d)| n as f64 * d);
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
    /// A step longer than the duration, or an impulse at or after the run's end, is an error.
    pub fn resolve(scene: &Scenario, dt: Option<f64>, duration: Option<f64>) -> Result<Self> {
        Self::resolve_asked(
            scene,
            &Asked {
                dt,
                duration,
                ..Asked::default()
            },
        )
    }

    /// Step and length as asked, for every command: the step from `asked.dt` or `[run].dt`;
    /// the length from `asked.steps` (whole steps), else `asked.duration`, else the scene's
    /// duration in seconds (`[run].duration`, or `[run].steps` × `[run].dt`, kept in seconds
    /// when the step is overridden). Errors name the flag or the field that gave the value.
    pub fn resolve_asked(scene: &Scenario, asked: &Asked) -> Result<Self> {
        let dt_flag = asked.dt.is_some().then_some(asked.step_flag);
        let dt = Self::step_from(scene, asked.dt, asked.step_flag)?;
        if let Some(d) = asked.duration {
            positive("--duration", d)?;
        }
        let (steps, duration) = match asked.steps {
            Some(0) => return Err(Error::option("--steps", "must be at least 1")),
            Some(n) if n > super::MAX_STEPS => {
                return Err(Error::option(
                    "--steps",
                    format!("{n} is above the limit of {}", super::MAX_STEPS),
                ))
            }
            Some(n) => (n, n as f64 * dt),
            None => {
                let duration = Self::length_with("--duration", scene, asked.duration, Some(dt))?;
                Self::step_fits(scene, dt, dt_flag, duration)?;
                let length_flag = Self::length_flag(dt_flag, asked.duration.is_some());
                (Self::steps_within(length_flag, dt, duration)?, duration)
            }
        };
        Self::check_impulses(scene, dt * steps as f64)?;
        Self::check_frame_impulses(scene, dt, dt * steps as f64)?;
        Ok(Timing {
            dt,
            steps,
            duration,
        })
    }

    /// The flag to blame for a run of too many steps: the step's flag when one gave the step
    /// (`step_flag`), else `--duration` when that flag gave the length, else the scene's
    /// `run.duration`.
    pub fn length_flag(step_flag: Option<&'static str>, duration_flag: bool) -> &'static str {
        match (step_flag, duration_flag) {
            (Some(f), _) => f,
            (None, true) => "--duration",
            (None, false) => "run.duration",
        }
    }

    /// The whole number of steps of `dt` s covering `duration` s (at least 1, rounded to the
    /// nearest), or an error naming `flag` when it is above [`super::MAX_STEPS`]; the error
    /// gives the real count even when it does not fit in an integer (or in an f64).
    pub fn steps_within(flag: &str, dt: f64, duration: f64) -> Result<u64> {
        let n = (duration / dt).round();
        if n <= super::MAX_STEPS as f64 {
            return Ok(crate::model::whole_steps(duration, dt));
        }
        let count = if n.is_finite() {
            num(n)
        } else {
            // Past f64's range (a subnormal step): the count from the logarithms.
            let l = duration.log10() - dt.log10();
            let (exp, mant) = (l.floor(), 10f64.powf(l - l.floor()));
            format!("{}e{exp}", num((mant * 1e3).round() / 1e3))
        };
        Err(Error::option(
            flag,
            format!(
                "{} s over {} s is {count} steps, above the limit of {}",
                num(dt),
                num(duration),
                num(super::MAX_STEPS as f64)
            ),
        ))
    }

    /// Refuses `frames` frames of `substeps` substeps each when together they pass the step
    /// limit, naming `flag` (`--substeps`): the run would take more steps than any run may.
    pub fn substeps_within(flag: &str, frames: u64, substeps: u64) -> Result<()> {
        match substeps_past_limit(frames as f64, substeps) {
            Some(why) => Err(Error::option(flag, why)),
            None => Ok(()),
        }
    }

    /// Refuses a step `dt` longer than the `duration` it must cover: the run would end after
    /// its duration. `flag`: the option that gave the step (`--dt`, `--hz`), `None` when it
    /// came from `[run].dt`.
    pub fn step_fits(scene: &Scenario, dt: f64, flag: Option<&str>, duration: f64) -> Result<()> {
        if dt <= duration * (1.0 + 1e-12) {
            return Ok(());
        }
        let (dt, duration) = (num(dt), num(duration));
        let msg = format!(
            "{dt} s is longer than the duration {duration} s: one step would end the run at {dt} s, after its duration; give a step ≤ the duration"
        );
        Err(match flag {
            Some(f) => Error::option(f, msg),
            None => Error::invalid(&scene.source, "run.dt", msg),
        })
    }

    /// Refuses impulses a run ending at `end` s would never apply: an impulse acts at the
    /// start of the step that contains its time, so one at or after the end changes nothing.
    /// The error names the impulse as written in the file (`impulse[k].time`).
    pub fn check_impulses(scene: &Scenario, end: f64) -> Result<()> {
        for (k, im) in scene.raw.impulse.iter().enumerate() {
            if let Some(why) = impulse_after_run(im.time, end) {
                return Err(Error::invalid(
                    &scene.source,
                    format!("impulse[{k}].time"),
                    why,
                ));
            }
        }
        Ok(())
    }

    /// With `[run] events = "frame"`, refuses an impulse that the frames of `frame` s would
    /// move to the run's end at `end` s or later, where it would never act (the error names
    /// the impulse and the frame it would move to). Exact events pass.
    pub fn check_frame_impulses(scene: &Scenario, frame: f64, end: f64) -> Result<()> {
        let eps = 1e-9 * end;
        let events = scene.run.events;
        for (k, im) in scene.raw.impulse.iter().enumerate() {
            let at = events.applied_at(im.time, frame);
            if at >= end - eps {
                return Err(Error::invalid(
                    &scene.source,
                    format!("impulse[{k}].time"),
                    format!(
                        "{} s moves to the frame boundary at {at} s with events = \"frame\" and {frame} s frames, at or after the end of the run at {end} s, so it would never act",
                        im.time
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Why an impulse at `time` s never acts in a run ending at `end` s, or `None` when it acts.
/// A time within a billionth of the run's length of its end is that end (the round-off of a
/// sum of steps), so the last instant an impulse may be given is `end` less that margin; the
/// message states this rule with the numbers. Scene loading and every command share it.
pub(crate) fn impulse_after_run(time: f64, end: f64) -> Option<String> {
    let margin = 1e-9 * end;
    if time < end - margin {
        return None;
    }
    let how = if time >= end {
        "at or after"
    } else {
        "within round-off (1e-9 of the run's length) of"
    };
    Some(format!(
        "{time} s is {how} the end of the run at {} s, so it would never act; give a time more than {} s before the end",
        num(end),
        num(margin)
    ))
}

/// Why `frames` frames of `substeps` substeps each pass the step limit, or `None` when they
/// fit: the one rule for a command's `--substeps` and a scene's `expect.substeps`.
pub(crate) fn substeps_past_limit(frames: f64, substeps: u64) -> Option<String> {
    let total = frames * substeps as f64;
    (total > super::MAX_STEPS as f64).then(|| {
        format!(
            "{substeps} substeps per frame over {} frames is {} steps, above the limit of {}",
            num(frames),
            num(total),
            num(super::MAX_STEPS as f64)
        )
    })
}
