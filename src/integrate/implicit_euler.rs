//! Backward (implicit) Euler on the full nonlinear system, solved for the new velocity by
//! Newton's method with the analytic spring, damper and drag Jacobians (Baraff & Witkin,
//! "Large steps in cloth simulation", SIGGRAPH 1998, without their one-iteration shortcut).
//!
//! The step is the shared implicit core's stage itself ([`Newton`](super::Newton)): Newton stops at a root to
//! the root tolerance, early there at 1 % of the step's own error estimate (see
//! [`ImplicitSettings`](super::ImplicitSettings)); each Newton iteration solves
//! ((1 + μ) M − h ∂f/∂v − h² ∂f/∂x) Δv = −G(v') by block-Jacobi-preconditioned CG, with the
//! Levenberg–Marquardt shift μ = 0 unless compressed springs make the matrix indefinite, and
//! steps along Δv by an Armijo line search on the stage's incremental potential.
//! Order 1; A-stable and L-stable: on an undamped oscillator the amplitude shrinks by
//! 1/√(1 + (hω)²) per step, for every h.

use super::implicit::{Implicit, Rule, StageKind};

/// Backward Euler's rule: the stage itself, from the current state at the full step.
#[derive(Debug, Default)]
pub struct BackwardEuler;

/// Backward Euler with Newton + block-Jacobi-preconditioned CG.
pub type ImplicitEuler = Implicit<BackwardEuler>;

impl Rule for BackwardEuler {
    const NAME: &'static str = "implicit_euler";
    const STAGE: StageKind = StageKind::Full;
}
