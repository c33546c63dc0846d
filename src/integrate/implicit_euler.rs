//! Backward (implicit) Euler on the full nonlinear system, solved for the new velocity by
//! Newton's method with the analytic spring, damper and drag Jacobians (Baraff & Witkin,
//! "Large steps in cloth simulation", SIGGRAPH 1998, without their one-iteration shortcut).
//!
//! The step is the shared implicit core's stage itself ([`Newton`]): Newton stops at a root to
//! the root tolerance, early there at 1 % of the step's own error estimate (see
//! [`ImplicitSettings`](super::ImplicitSettings)); each Newton iteration solves
//! ((1 + μ) M − h ∂f/∂v − h² ∂f/∂x) Δv = −G(v') by block-Jacobi-preconditioned CG, with the
//! Levenberg–Marquardt shift μ = 0 unless compressed springs make the matrix indefinite, and
//! steps along Δv by an Armijo line search on the stage's incremental potential.
//! Order 1; A-stable and L-stable: on an undamped oscillator the amplitude shrinks by
//! 1/√(1 + (hω)²) per step, for every h.

use super::newton::{Newton, Stop};
use super::{StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System};

/// The method's name: what [`Stepper::name`] reports and what the solver's errors say.
const NAME: &str = "implicit_euler";

/// Backward Euler with Newton + block-Jacobi-preconditioned CG.
#[derive(Debug, Default)]
pub struct ImplicitEuler {
    /// The solver, its settings and its iteration counters.
    pub newton: Newton,
}

impl Stepper for ImplicitEuler {
    fn name(&self) -> &str {
        NAME
    }
    fn newton(&self) -> Option<&Newton> {
        Some(&self.newton)
    }
    fn newton_mut(&mut self) -> Option<&mut Newton> {
        Some(&mut self.newton)
    }
    fn reset(&mut self) {
        self.newton.reset();
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let (power, evals) = self
            .newton
            .solve(sys, &s.x, &s.v, h, Stop::FirstOrder, NAME)?;
        s.v.copy_from_slice(self.newton.v());
        s.x.copy_from_slice(self.newton.x());
        s.t += h;
        Ok(StepStats {
            force_evals: evals,
            dissipated: power * h,
            ..StepStats::default()
        })
    }
}
