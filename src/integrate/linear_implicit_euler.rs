//! Linearly implicit Euler (Baraff & Witkin, "Large steps in cloth simulation", SIGGRAPH
//! 1998): backward Euler with the forces linearised at the start of the step, so one linear
//! solve per step and no Newton iteration — the classic cloth method.
//!
//! (M − h ∂f/∂v − h² ∂f/∂x) Δv = h (f₀ + h ∂f/∂x v₀), v' = v₀ + Δv, x' = x₀ + h v', with the
//! Jacobian at (x₀, v₀), solved by the shared core's block-Jacobi CG ([`Newton`]), clamping
//! compressed springs' negative stiffness when CG meets non-positive curvature (any matrix
//! keeps this W-method first order). On linear forces it is backward Euler exactly, so it is
//! A- and L-stable (amplitude × 1/√(1 + (hω)²) per step on an undamped oscillator). Dissipated
//! work is booked as backward Euler's, h·P(x', v') (one more force evaluation).

use super::newton::Newton;
use super::{StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System};

/// The method's name: what [`Stepper::name`] reports and what the solver's errors say.
const NAME: &str = "linear_implicit_euler";

/// Baraff–Witkin linearly implicit Euler on the shared block-Jacobi-PCG core.
#[derive(Debug, Default)]
pub struct LinearImplicitEuler {
    /// The solver, its settings and its counters (one "Newton iteration" per step).
    pub newton: Newton,
}

impl Stepper for LinearImplicitEuler {
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
        let (power, evals) = self.newton.solve_linearized(sys, &s.x, &s.v, h, NAME)?;
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
