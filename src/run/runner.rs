//! The run loop (argmin's Executor pattern): steppers only step; this owns everything else.

use super::cost::{CostModel, Work};
use super::energy::EnergyRecord;
use super::observer::Observer;
use super::scale::energy_scale;
use super::verdict::{Rule, Verdict, DEFAULT_BLOWUP_FACTOR};
use crate::error::{Error, Result};
use crate::integrate::Stepper;
use crate::model::{Impulse, State, System};
use serde::Serialize;
use std::time::Instant;

/// How long to run, with which frame step and substeps, and when to call a run unstable.
///
/// A run is `steps` frames of `dt`; observers see the state at the end of every frame.
/// Each frame is `substeps` equal steps of `dt / substeps` for a native method — bit for bit
/// the run at `dt / substeps` with every `substeps`-th state kept. A method that substeps
/// itself ([`Stepper::splits_frames`], Rapier) gets whole frames instead and splits them
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
    /// − injected) rises by more than this multiple of [`energy_scale`] is unstable and stops.
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

struct Loop<'a> {
    sys: &'a System,
    stepper: &'a mut dyn Stepper,
    work: Work,
    dissipated: f64,
    /// Energy the contact stage created (booked apart; it stays in the mechanical terms).
    created: f64,
    wall: f64,
    /// Positions and velocities before the step, kept only when the scene has a contact stage.
    x0: Vec<crate::model::Vec3>,
    v0: Vec<crate::model::Vec3>,
}

impl Loop<'_> {
    fn step(&mut self, s: &mut State, h: f64) -> Result<()> {
        let t0 = Instant::now();
        let newton_before = self.newton_counts();
        if self.sys.post_step.is_some() {
            self.x0.clone_from(&s.x);
            self.v0.clone_from(&s.v);
        }
        // A step that fails still did its work: the step and its Newton and linear iterations
        // (the implicit core's counters) are counted before the error goes up; its force
        // evaluations are in the stats it never returns, so the count leaves them out.
        let stepped = self.stepper.step(self.sys, s, h);
        let (newton, linear) = self.newton_counts();
        let w = &mut self.work;
        w.steps += 1;
        w.newton_iterations += newton.saturating_sub(newton_before.0);
        w.linear_iterations += linear.saturating_sub(newton_before.1);
        let stats = stepped?;
        w.force_evals += stats.force_evals;
        w.link_updates += stats.link_updates;
        w.engine_seconds += stats.engine_seconds;
        // Contact stage (obstacles only): resolve contacts after the accepted step, before the
        // energy account; what it removes joins `dissipated`, and a changed state resets the
        // stepper's history. The stage books losses and gains apart: energy it created stays
        // in the mechanical terms, where the verdict sees it as a gain, and is listed in `created`.
        if let Some(c) = self
            .sys
            .post_step
            .as_ref()
            .filter(|_| !self.stepper.handles_contacts())
        {
            let cs = c.apply(self.sys, &self.x0, &self.v0, s, h);
            self.work.contact_passes += 1;
            self.dissipated += cs.dissipated;
            self.created += cs.created;
            if cs.changed {
                self.stepper.reset();
            }
        }
        self.wall += t0.elapsed().as_secs_f64();
        self.dissipated += stats.dissipated;
        Ok(())
    }

    /// The implicit core's Newton and linear iteration counters so far (0 without one).
    fn newton_counts(&self) -> (u64, u64) {
        self.stepper
            .newton()
            .map_or((0, 0), |n| (n.newton_iterations, n.cg_iterations))
    }
}

/// Runs `stepper` on `sys` from `s0` for `plan`, feeding `obs` once per frame. A numerical
/// blow-up is a [`Status::Unstable`] outcome (its step is the frame, its time the substep's
/// end), not an error; errors are only the observers' (I/O).
///
/// Impulses take effect when the scene's [`crate::model::Events`] says, relative to the
/// frames of `plan.dt`; `steps_done` counts frames, and the cost counts every substep.
// One function because the frame loop owns the stepper, the contact stage, impulses, energy accounts and the verdict together; each is a call, the loop is their order.
pub fn run(
    sys: &System,
    stepper: &mut dyn Stepper,
    s0: State,
    plan: &RunPlan,
    obs: &mut dyn Observer,
) -> Result<RunOutcome> {
    let scale = energy_scale(sys, &s0, plan.duration());
    let mut s = s0;
    let mut prev = s.clone();
    let mut injected = 0.0;
    let initial = EnergyRecord::new(sys.state_energy(&s), 0.0, 0.0);
    let mut last = initial;
    obs.observe(0, &s, &initial)?;
    stepper.reset();
    let n = if stepper.splits_frames() {
        1
    } else {
        plan.substeps.max(1)
    };
    // The step of a substep, computed as a caller running at dt / n would: bit-identical.
    let h = if n == 1 { plan.dt } else { plan.dt / n as f64 };
    let impulses: Vec<Impulse> = sys
        .impulses
        .iter()
        .map(|im| Impulse {
            time: sys.events.applied_at(im.time, plan.dt),
            ..*im
        })
        .collect();
    let mut lp = Loop {
        sys,
        stepper,
        work: Work::default(),
        dissipated: 0.0,
        created: 0.0,
        wall: 0.0,
        x0: Vec::new(),
        v0: Vec::new(),
    };
    let eps = 1e-9 * h;
    let mut next_imp = 0;
    let mut status = Status::Ok;
    let mut verdict = Verdict::new(initial.total, scale, plan.blowup_factor);
    let mut done = 0;
    for frame in 0..plan.steps {
        prev.clone_from(&s);
        let mut rec = last;
        // `keep`: the frame is written; `stop`: no frame follows it.
        let (mut keep, mut stop) = (true, false);
        for m in frame * n..(frame + 1) * n {
            let t_end = (m + 1) as f64 * h;
            let imp_at_start = next_imp;
            let mut failure = None;
            while next_imp < impulses.len() && impulses[next_imp].time < t_end - eps {
                let im = impulses[next_imp];
                if im.time > s.t + eps {
                    let hi = im.time - s.t;
                    if let Err(e) = lp.step(&mut s, hi) {
                        failure = Some(e);
                        break;
                    }
                }
                let p = im.particle;
                let before = s.v[p].norm_squared();
                s.v[p] += im.delta_v;
                injected += 0.5 * sys.mass[p] * (s.v[p].norm_squared() - before);
                lp.stepper.reset();
                next_imp += 1;
            }
            let split = next_imp > imp_at_start;
            if failure.is_none() && t_end - s.t > eps {
                // An unsplit step is exactly `h`: t_end − t would differ from it by round-off
                // and make history-keeping methods (position Verlet) restart.
                let hs = if split { t_end - s.t } else { h };
                if let Err(e) = lp.step(&mut s, hs) {
                    failure = Some(e);
                }
            }
            s.t = t_end;
            rec = EnergyRecord::new(sys.state_energy(&s), lp.dissipated, injected)
                .with_created(lp.created);
            let fired = match failure {
                // A step that failed (an implicit solve that did not converge) left no state
                // worth writing: it ends the run like a divergence.
                Some(Error::Step(why)) => Some((Rule::Diverged, verdict.failed_step(&last, &why))),
                Some(other) => return Err(other),
                None => verdict.step(&s, &rec).map(|f| (f.rule, f.reason)),
            };
            if let Some((rule, reason)) = fired {
                if status.is_ok() {
                    status = Status::Unstable {
                        step: frame + 1,
                        time: t_end,
                        reason,
                    };
                }
                let fatal = matches!(rule, Rule::Diverged | Rule::Cap);
                if rule == Rule::Diverged || plan.stop_at_verdict {
                    keep = false;
                }
                stop |= fatal || plan.stop_at_verdict;
                if !keep {
                    break;
                }
            }
        }
        if !keep {
            std::mem::swap(&mut s, &mut prev);
            break;
        }
        last = rec;
        done = frame + 1;
        obs.observe(done, &s, &rec)?;
        if stop || obs.seen_enough() {
            break;
        }
    }
    obs.finish(done, &s, &last)?;
    Ok(RunOutcome {
        status,
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
