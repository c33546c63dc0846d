//! One run's stepping, frame by frame: each step with its work counted and the contact stage
//! after it, the impulses that split steps, and every substep's state judged by the verdict.

use super::cost::Work;
use super::runner::{RunPlan, Status};
use super::verdict::{Rule, Verdict};
use super::EnergyRecord;
use crate::error::{Error, Result};
use crate::integrate::Stepper;
use crate::method::MethodInfo;
use crate::model::{Impulse, State, System};
use std::time::Instant;

/// The state of a run between frames: the stepper and the work it did, the energy accounts
/// beside the state, the impulses still due, and the verdict with the status it gave.
pub(super) struct Loop<'a> {
    sys: &'a System,
    stepper: &'a mut dyn Stepper,
    /// The method resolves obstacle contacts itself (its `MethodInfo::contacts` fact).
    own_contacts: bool,
    /// The work counted so far.
    pub(super) work: Work,
    dissipated: f64,
    /// Energy the contact stage created (booked apart; it stays in the mechanical terms).
    created: f64,
    /// Kinetic energy the impulses injected.
    injected: f64,
    /// Wall time spent inside the stepper's steps (s).
    pub(super) wall: f64,
    /// Positions and velocities before the step, kept only when the scene has a contact stage.
    x0: Vec<crate::model::Vec3>,
    v0: Vec<crate::model::Vec3>,
    /// The scene's impulses at the times they take effect, and the index of the next one.
    impulses: Vec<Impulse>,
    next_imp: usize,
    /// The substep, the substeps per frame, and the tolerance of time comparisons.
    h: f64,
    n: u64,
    eps: f64,
    verdict: Verdict,
    /// How the run stands: the first unstable verdict, once one fired.
    pub(super) status: Status,
    stop_at_verdict: bool,
}

/// How a frame ended: the energy account at its end, whether it is written (`keep`), and
/// whether no frame follows it (`stop`).
pub(super) struct FrameEnd {
    /// The energy account after the frame's last substep.
    pub(super) rec: EnergyRecord,
    /// The frame's state is written.
    pub(super) keep: bool,
    /// The run ends after this frame.
    pub(super) stop: bool,
}

impl<'a> Loop<'a> {
    /// The loop running `stepper` on `sys` for `plan`, judged by `verdict`; `facts` (the
    /// method's registered facts) say whether it splits frames and resolves contacts itself.
    pub(super) fn new(
        sys: &'a System,
        stepper: &'a mut dyn Stepper,
        facts: &MethodInfo,
        plan: &RunPlan,
        verdict: Verdict,
    ) -> Self {
        let own_contacts = facts.contacts;
        let n = if facts.splits_frames {
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
        Loop {
            sys,
            stepper,
            own_contacts,
            work: Work::default(),
            dissipated: 0.0,
            created: 0.0,
            injected: 0.0,
            wall: 0.0,
            x0: Vec::new(),
            v0: Vec::new(),
            impulses,
            next_imp: 0,
            h,
            n,
            eps: 1e-9 * h,
            verdict,
            status: Status::Ok,
            stop_at_verdict: plan.stop_at_verdict,
        }
    }

    /// Advances `s` through the frame `frame`, its substeps judged one by one; `last` is the
    /// account of the last frame written. Errors are only those that are not a failed step.
    pub(super) fn frame(
        &mut self,
        s: &mut State,
        frame: u64,
        last: &EnergyRecord,
    ) -> Result<FrameEnd> {
        let mut end = FrameEnd {
            rec: *last,
            keep: true,
            stop: false,
        };
        for m in frame * self.n..(frame + 1) * self.n {
            let t_end = (m + 1) as f64 * self.h;
            let failure = self.substep(s, t_end).err();
            s.t = t_end;
            end.rec = EnergyRecord::new(self.sys.state_energy(s), self.dissipated, self.injected)
                .with_created(self.created);
            let fired = match failure {
                // A step that failed (an implicit solve that did not converge) left no state
                // worth writing: it ends the run like a divergence.
                Some(Error::Step(why)) => {
                    Some((Rule::Diverged, self.verdict.failed_step(last, &why)))
                }
                Some(other) => return Err(other),
                None => self.verdict.step(s, &end.rec).map(|f| (f.rule, f.reason)),
            };
            if let Some((rule, reason)) = fired {
                if self.status.is_ok() {
                    self.status = Status::Unstable {
                        step: frame + 1,
                        time: t_end,
                        reason,
                    };
                }
                let fatal = matches!(rule, Rule::Diverged | Rule::Cap);
                if rule == Rule::Diverged || self.stop_at_verdict {
                    end.keep = false;
                }
                end.stop |= fatal || self.stop_at_verdict;
                if !end.keep {
                    break;
                }
            }
        }
        Ok(end)
    }

    /// Advances `s` to `t_end`: the impulses due before it, each applied at its time with a
    /// step up to it, then the rest of the substep.
    fn substep(&mut self, s: &mut State, t_end: f64) -> Result<()> {
        let imp_at_start = self.next_imp;
        while self.next_imp < self.impulses.len()
            && self.impulses[self.next_imp].time < t_end - self.eps
        {
            let im = self.impulses[self.next_imp];
            if im.time > s.t + self.eps {
                let hi = im.time - s.t;
                self.step(s, hi)?;
            }
            let p = im.particle;
            let before = s.v[p].norm_squared();
            s.v[p] += im.delta_v;
            self.injected += 0.5 * self.sys.mass[p] * (s.v[p].norm_squared() - before);
            self.stepper.reset();
            self.next_imp += 1;
        }
        let split = self.next_imp > imp_at_start;
        if t_end - s.t > self.eps {
            // An unsplit step is exactly `h`: t_end − t would differ from it by round-off
            // and make history-keeping methods (position Verlet) restart.
            let hs = if split { t_end - s.t } else { self.h };
            self.step(s, hs)?;
        }
        Ok(())
    }

    /// One step of `h` from `s` with its work counted, then the contact stage.
    fn step(&mut self, s: &mut State, h: f64) -> Result<()> {
        let t0 = Instant::now();
        let before = self.stepper.solver_work();
        if self.sys.post_step.is_some() {
            self.x0.clone_from(&s.x);
            self.v0.clone_from(&s.v);
        }
        // A step that fails still did its work: the step and its Newton and linear iterations,
        // factorisations and substitutions (the implicit core's counters) are counted before
        // the error goes up; its force evaluations are in the stats it never returns, so the
        // count leaves them out.
        let stepped = self.stepper.step(self.sys, s, h);
        let after = self.stepper.solver_work();
        let w = &mut self.work;
        w.steps += 1;
        w.newton_iterations += after
            .newton_iterations
            .saturating_sub(before.newton_iterations);
        w.linear_iterations += after
            .linear_iterations
            .saturating_sub(before.linear_iterations);
        w.factorizations += after.factorizations.saturating_sub(before.factorizations);
        w.factor_solves += after.factor_solves.saturating_sub(before.factor_solves);
        w.patch_iterations += after
            .patch_iterations
            .saturating_sub(before.patch_iterations);
        let stats = stepped?;
        w.force_evals += stats.force_evals;
        w.link_updates += stats.link_updates;
        w.engine_seconds += stats.engine_seconds;
        // Contact stage (obstacles only): resolve contacts after the accepted step, before the
        // energy account; what it removes joins `dissipated`, and a changed state resets the
        // stepper's history. The stage books losses and gains apart: energy it created stays
        // in the mechanical terms, where the verdict sees it as a gain, and is listed in `created`.
        if let Some(c) = self.sys.post_step.as_ref().filter(|_| !self.own_contacts) {
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
}
