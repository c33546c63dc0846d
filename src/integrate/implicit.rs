//! The one stepper shell of every method built on the shared implicit core ([`Newton`]): a
//! [`Rule`] says how a step is made of backward-Euler stages (which base, which step, which
//! stop, and what follows the stage), and [`Implicit`] does the rest every such method shares
//! (its name, the core's settings and counters, reset, the step's bookkeeping).

use super::newton::Newton;
use super::{StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System};

/// How an implicit method makes a step of the shared core's stages.
pub trait Rule: std::fmt::Debug + Default + Send {
    /// The method's name: what [`Stepper::name`] reports and what the solver's errors say.
    const NAME: &'static str;
    /// k of a k-step method ([`Stepper::recurrence_steps`]).
    const RECURRENCE_STEPS: usize = 1;
    /// Advances `s` by `h` (all but the time) with `newton`: the work dissipated (J) and the
    /// force evaluations made.
    fn advance(
        &mut self,
        newton: &mut Newton,
        sys: &System,
        s: &mut State,
        h: f64,
    ) -> Result<(f64, u64)>;
    /// Forgets any history the rule keeps (the state was changed from outside).
    fn reset(&mut self) {}
}

/// An implicit method: its rule on the shared Newton + preconditioned-CG core.
#[derive(Debug, Default)]
pub struct Implicit<R> {
    /// The solver, its settings and its iteration counters.
    pub newton: Newton,
    rule: R,
}

impl<R: Rule> Stepper for Implicit<R> {
    fn name(&self) -> &str {
        R::NAME
    }
    fn newton(&self) -> Option<&Newton> {
        Some(&self.newton)
    }
    fn newton_mut(&mut self) -> Option<&mut Newton> {
        Some(&mut self.newton)
    }
    fn reset(&mut self) {
        self.rule.reset();
        self.newton.reset();
    }
    fn recurrence_steps(&self) -> usize {
        R::RECURRENCE_STEPS
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let (dissipated, evals) = self.rule.advance(&mut self.newton, sys, s, h)?;
        s.t += h;
        Ok(StepStats {
            force_evals: evals,
            dissipated,
            ..StepStats::default()
        })
    }
}
