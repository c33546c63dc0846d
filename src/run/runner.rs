//! The run loop (argmin's Executor pattern): steppers only step; this owns everything else.

use super::cost::{CostModel, Work};
use super::energy::EnergyRecord;
use super::frame_loop::Loop;
use super::observer::Observer;
use super::verdict::{Verdict, DEFAULT_BLOWUP_FACTOR};
use crate::error::Result;
use crate::integrate::Stepper;
use crate::method::{Instance, MethodInfo};
use crate::model::{State, System};
use serde::Serialize;

/// How long to run, with which frame step and substeps, and when to call a run unstable.
///
/// A run is `steps` frames of `dt`; observers see the state at the end of every frame.
/// Each frame is `substeps` equal steps of `dt / substeps` for a native method — bit for bit
/// the run at `dt / substeps` with every `substeps`-th state kept. A method that substeps
/// itself (its fact [`MethodInfo::splits_frames`], Rapier) gets whole frames instead and splits them
/// with its own setting ([`crate::method::MethodOptions::substeps`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunPlan {
    /// Frame (output) step in s (impulses inside a step split it; the output grid stays
    /// uniform).
    pub dt: f64,
    /// Number of frames.
    pub steps: u64,
    /// Equal substeps per frame for native methods (≥ 1; 1: one step per frame).
    pub substeps: u64,
    /// The hard cap of [`super::verdict`]: a run whose energy balance (mechanical + dissipated
    /// − injected) rises by more than this multiple of [`super::energy_scale`] is unstable and
    /// stops.
    pub blowup_factor: f64,
    /// Stop at the first unstable verdict (what measuring commands want: an unstable run has
    /// no accuracy to measure), or compute on until the state diverges or passes the cap (what
    /// `run` wants: every computed step is written, the one the verdict fired on included).
    pub stop_at_verdict: bool,
}

impl RunPlan {
    /// A plan of `steps` frames of `dt`, one step per frame, with the default blow-up factor.
    pub fn new(dt: f64, steps: u64) -> Self {
        RunPlan {
            dt,
            steps,
            substeps: 1,
            blowup_factor: DEFAULT_BLOWUP_FACTOR,
            stop_at_verdict: true,
        }
    }
    /// A plan covering `duration` (rounded to the nearest whole number of steps, at least 1).
    pub fn for_duration(dt: f64, duration: f64) -> Self {
        Self::new(dt, crate::model::whole_steps(duration, dt))
    }
    /// The same plan with `n` substeps per frame (at least 1).
    pub fn with_substeps(self, n: u64) -> Self {
        RunPlan {
            substeps: n.max(1),
            ..self
        }
    }
    /// Simulated time covered.
    pub fn duration(&self) -> f64 {
        self.dt * self.steps as f64
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Status {
    /// Every step finished with a finite state and bounded energy.
    Ok,
    /// The run grew without bound (or its step failed): at which frame and time the verdict
    /// first fired, and which measure tripped.
    Unstable {
        /// Frame in which the verdict first fired.
        step: u64,
        /// Its time (s).
        time: f64,
        /// Which measure tripped, in words.
        reason: String,
    },
}

/// A run's status as documents spell it (`ok` or `unstable`): what a finished run is compared
/// by, as a value rather than a string.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunStatus {
    /// Every step finished with a finite state and bounded energy.
    Ok,
    /// The run grew without bound, or its step failed.
    Unstable,
}

impl RunStatus {
    /// True for [`RunStatus::Ok`].
    pub fn is_ok(self) -> bool {
        self == RunStatus::Ok
    }
    /// `ok` or `unstable`.
    pub fn label(self) -> &'static str {
        match self {
            RunStatus::Ok => "ok",
            RunStatus::Unstable => "unstable",
        }
    }
    /// The status whose [`RunStatus::label`] is `label` (how documents spell it).
    pub fn from_label(label: &str) -> Option<Self> {
        [RunStatus::Ok, RunStatus::Unstable]
            .into_iter()
            .find(|s| s.label() == label)
    }
}

impl std::fmt::Display for RunStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.label())
    }
}

impl std::fmt::Display for Status {
    /// `ok`, or `UNSTABLE from step N (t = T s): reason`: how `run` and `bench-ratios` say it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Status::Ok => f.write_str("ok"),
            Status::Unstable { step, time, reason } => {
                write!(f, "UNSTABLE from step {step} (t = {time} s): {reason}")
            }
        }
    }
}

impl Status {
    /// The status without its details.
    pub fn kind(&self) -> RunStatus {
        match self {
            Status::Ok => RunStatus::Ok,
            Status::Unstable { .. } => RunStatus::Unstable,
        }
    }
    /// True for [`Status::Ok`].
    pub fn is_ok(&self) -> bool {
        matches!(self, Status::Ok)
    }
    /// `ok` or `unstable`: its [`RunStatus`]'s label.
    pub fn label(&self) -> &'static str {
        self.kind().label()
    }
}

/// What a run produced besides what its observers saw.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// How it ended.
    pub status: Status,
    /// Steps completed with an accepted state.
    pub steps_done: u64,
    /// Force evaluations made.
    pub force_evals: u64,
    /// Wall time spent inside the stepper's steps (s): measured, reported, never decides.
    pub wall_seconds: f64,
    /// The work the run counted.
    pub work: Work,
    /// Modelled cost of that work on this scene (s, [`CostModel`]): what decides.
    pub modelled_seconds: f64,
    /// Energy account at t = 0.
    pub initial_energy: EnergyRecord,
    /// Energy account of the last accepted state.
    pub final_energy: EnergyRecord,
    /// The last accepted state.
    pub final_state: State,
}

/// Runs the method `method` on `sys` from `s0` for `plan`, feeding `obs` once per frame. A numerical
/// blow-up is a [`Status::Unstable`] outcome (its step is the frame, its time the substep's
/// end), not an error; errors are only the observers' (I/O).
///
/// Impulses take effect when the scene's [`crate::model::Events`] says, relative to the
/// frames of `plan.dt`; `steps_done` counts frames, and the cost counts every substep.
pub fn run(
    sys: &System,
    method: &mut Instance,
    s0: State,
    plan: &RunPlan,
    obs: &mut dyn Observer,
) -> Result<RunOutcome> {
    run_with(sys, method.stepper.as_mut(), &method.info, s0, plan, obs)
}

/// [`run`] for a stepper made outside the registry (its settings chosen by hand), with its
/// method's registered facts `facts`, which say how it meets the runner.
pub fn run_with(
    sys: &System,
    stepper: &mut dyn Stepper,
    facts: &MethodInfo,
    s0: State,
    plan: &RunPlan,
    obs: &mut dyn Observer,
) -> Result<RunOutcome> {
    let (verdict, initial) = Verdict::for_run(sys, &s0, plan.duration(), plan.blowup_factor);
    let mut s = s0;
    let mut prev = s.clone();
    let mut last = initial;
    obs.observe(0, &s, &initial)?;
    stepper.reset();
    let mut lp = Loop::new(sys, stepper, facts, plan, verdict);
    let mut done = 0;
    for frame in 0..plan.steps {
        prev.clone_from(&s);
        let end = lp.frame(&mut s, frame, &last)?;
        if !end.keep {
            std::mem::swap(&mut s, &mut prev);
            break;
        }
        last = end.rec;
        done = frame + 1;
        obs.observe(done, &s, &end.rec)?;
        if end.stop || obs.seen_enough() {
            break;
        }
    }
    obs.finish(done, &s, &last)?;
    Ok(RunOutcome {
        status: lp.status,
        steps_done: done,
        force_evals: lp.work.force_evals,
        wall_seconds: lp.wall,
        modelled_seconds: CostModel::of(sys).seconds(&lp.work),
        work: lp.work,
        initial_energy: initial,
        final_energy: last,
        final_state: s,
    })
}
