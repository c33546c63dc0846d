//! The `[run]` and `[expect]` tables: the step, the length, the methods, events, tolerance
//! and frame rate a scene asks for, and the expectations a CI run checks.

use super::checker::{Checker, MAX_STEPS};
use super::file::ScenarioFile;
use super::{Expect, RunSettings};
use crate::error::{num, Result};

pub(super) fn validate_run(ck: &Checker, raw: &ScenarioFile) -> Result<RunSettings> {
    let Some(r) = &raw.run else {
        return Ok(RunSettings {
            dt: None,
            steps: None,
            duration: None,
            methods: Vec::new(),
            events: Default::default(),
            tolerance: None,
            hz: None,
        });
    };
    let dt = match r.dt {
        Some(dt) => Some(ck.positive("run.dt", dt)?),
        None => None,
    };
    let steps = match r.steps {
        Some(s) if s < 1 || s as u64 > MAX_STEPS => {
            return Err(ck.err(
                "run.steps",
                format!("must be between 1 and {MAX_STEPS}, got {s}"),
            ))
        }
        Some(s) => Some(s as u64),
        None => None,
    };
    let duration = match r.duration {
        Some(d) => Some(ck.positive("run.duration", d)?),
        None => None,
    };
    match (steps, duration) {
        (Some(_), Some(_)) => {
            return Err(ck.err(
                "run",
                "give exactly one of `steps` and `duration`, not both",
            ))
        }
        (None, None) => return Err(ck.err("run", "give exactly one of `steps` and `duration`")),
        _ => {}
    }
    if let (Some(dt), Some(d)) = (dt, duration) {
        if dt > d * (1.0 + 1e-12) {
            return Err(ck.err(
                "run.dt",
                format!("{} s is longer than run.duration = {} s: one step would end the run at {} s, after its duration; give a step ≤ the duration", num(dt), num(d), num(dt)),
            ));
        }
        if d / dt > MAX_STEPS as f64 {
            return Err(ck.err(
                "run.duration",
                format!("duration / dt = {:.3e} steps exceeds {MAX_STEPS}", d / dt),
            ));
        }
    }
    let methods = r.methods.clone().unwrap_or_default();
    for (k, name) in methods.iter().enumerate() {
        if crate::method::Registry::builtin().find(name).is_none() {
            return Err(ck.err(
                format!("run.methods[{k}]"),
                format!(
                    "unknown method '{name}'; known: {}",
                    crate::method::Registry::builtin().names().join(", ")
                ),
            ));
        }
    }
    let events = match &r.events {
        Some(e) => crate::model::Events::parse(e).map_err(|why| ck.err("run.events", why))?,
        None => Default::default(),
    };
    let tolerance = match r.tolerance {
        Some(t) => Some(ck.positive("run.tolerance", t)?),
        None => None,
    };
    let hz = match r.hz {
        Some(h) => Some(ck.positive("run.hz", h)?),
        None => None,
    };
    Ok(RunSettings {
        dt,
        steps,
        duration,
        methods,
        events,
        tolerance,
        hz,
    })
}

/// Checks `[expect]`: a registered method, exactly one positive finite `hz` or `dt`, a frame
/// no longer than the run (`run`'s duration, when the scene gives one) and frames × substeps
/// within the step limit, `substeps` ≥ 1, and positive finite limits.
pub(super) fn validate_expect(
    ck: &Checker,
    raw: &ScenarioFile,
    run: &RunSettings,
) -> Result<Option<Expect>> {
    let Some(e) = &raw.expect else {
        return Ok(None);
    };
    let registry = crate::method::Registry::builtin();
    if registry.find(&e.method).is_none() {
        return Err(ck.err(
            "expect.method",
            format!(
                "unknown method '{}'; known: {}",
                e.method,
                registry.names().join(", ")
            ),
        ));
    }
    let frame_dt = match (e.hz, e.dt) {
        (Some(_), Some(_)) => {
            return Err(ck.err("expect", "give exactly one of `hz` and `dt`, not both"))
        }
        (None, None) => return Err(ck.err("expect", "give exactly one of `hz` and `dt`")),
        (Some(hz), None) => 1.0 / ck.positive("expect.hz", hz)?,
        (None, Some(dt)) => ck.positive("expect.dt", dt)?,
    };
    let substeps = match e.substeps {
        None => 1,
        Some(n) if (1..=MAX_STEPS as i64).contains(&n) => n as u64,
        Some(n) => {
            return Err(ck.err(
                "expect.substeps",
                format!("must be between 1 and {MAX_STEPS}, got {n}"),
            ))
        }
    };
    let (field, given) = match e.hz {
        Some(hz) if frame_dt.is_finite() => (
            "expect.hz",
            format!("{} Hz (a frame of {} s)", num(hz), num(frame_dt)),
        ),
        Some(hz) => (
            "expect.hz",
            format!("{} Hz (a frame of 1/{} s)", num(hz), num(hz)),
        ),
        None => ("expect.dt", format!("a frame of {} s", num(frame_dt))),
    };
    expect_frames_fit(ck, run, (field, &given), frame_dt, substeps)?;
    let limit = |field: &str, v: Option<f64>| -> Result<Option<f64>> {
        v.map(|x| ck.positive(&format!("expect.{field}"), x))
            .transpose()
    };
    Ok(Some(Expect {
        method: e.method.clone(),
        frame_dt,
        substeps,
        stable: e.stable,
        max_position_error: limit("max_position_error", e.max_position_error)?,
        max_strain: limit("max_strain", e.max_strain)?,
        max_energy_drift_rate: limit("max_energy_drift_rate", e.max_energy_drift_rate)?,
    }))
}

/// Refuses an `[expect]` frame of `frame_dt` s (given by a field, as written) that the scene's run could
/// not hold: longer than its duration (one frame would end after it), or so short that its
/// frames × `substeps` pass the step limit. A run without a duration in seconds (steps with
/// no step) is left to the command that gives it one.
fn expect_frames_fit(
    ck: &Checker,
    run: &RunSettings,
    (field, given): (&str, &str),
    frame_dt: f64,
    substeps: u64,
) -> Result<()> {
    let Some(duration) = run.length() else {
        return Ok(());
    };
    if frame_dt > duration * (1.0 + 1e-12) {
        return Err(ck.err(
            field,
            format!(
                "{given} is longer than the run's duration of {} s: one frame would end after the run; give a frame ≤ the duration",
                num(duration)
            ),
        ));
    }
    let frames = (duration / frame_dt).round();
    if frames > MAX_STEPS as f64 {
        return Err(ck.err(
            field,
            format!(
                "{given} over the run's {} s is {} frames, above the limit of {} steps",
                num(duration),
                num(frames),
                num(MAX_STEPS as f64)
            ),
        ));
    }
    match super::timing::substeps_past_limit(frames, substeps) {
        Some(why) => Err(ck.err("expect.substeps", why)),
        None => Ok(()),
    }
}
