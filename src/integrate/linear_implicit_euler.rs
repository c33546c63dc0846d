//! Linearly implicit Euler (Baraff & Witkin, "Large steps in cloth simulation", SIGGRAPH
//! 1998): backward Euler with the forces linearised at the start of the step, so one linear
//! solve per step and no Newton iteration — the classic cloth method.
//!
//! (M − h ∂f/∂v − h² ∂f/∂x) Δv = h (f₀ + h ∂f/∂x v₀), v' = v₀ + Δv, x' = x₀ + h v', with the
//! Jacobian at (x₀, v₀), solved by the shared core's block-Jacobi CG ([`Newton`](super::Newton)), clamping
//! compressed springs' negative stiffness when CG meets non-positive curvature (any matrix
//! keeps this W-method first order). On linear forces it is backward Euler exactly, so it is
//! A- and L-stable (amplitude × 1/√(1 + (hω)²) per step on an undamped oscillator). Dissipated
//! work is booked as backward Euler's, h·P(x', v') (one more force evaluation).

use super::implicit::{Implicit, Rule, StageKind};

/// Baraff and Witkin's rule: one linear solve with the Jacobian at the start of the step.
#[derive(Debug, Default)]
pub struct LinearizedEuler;

/// Baraff–Witkin linearly implicit Euler on the shared block-Jacobi-PCG core (one "Newton
/// iteration" per step).
pub type LinearImplicitEuler = Implicit<LinearizedEuler>;

impl Rule for LinearizedEuler {
    const NAME: &'static str = "linear_implicit_euler";
    const STAGE: StageKind = StageKind::Linearized;
}
