//! The implicit midpoint rule, y' = y + h F((y + y')/2), on the full nonlinear system.
//!
//! Written in the midpoint velocity u = (v + v')/2 it is a backward-Euler stage of step h/2,
//! x_½ = x + (h/2) u, M (u − v) = (h/2) f(x_½, u), followed by the extrapolation x' = 2x_½ − x,
//! v' = 2u − v; so it runs the shared implicit core ([`Newton`](super::Newton)) at h/2, started from the
//! linearly implicit solution and stopped, once at the root tolerance, at 0.01 % of the
//! stage's first-order error estimate (a second-order method's error is about hω times smaller
//! than that estimate).
//! Order 2, symplectic and A-stable: the one-step map on an undamped oscillator is the Cayley
//! transform, a rotation, so a linear spring's energy (a quadratic invariant) is kept to solver
//! tolerance at every h (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §IV.2).
//! Dissipated work is booked by the midpoint rule, h·P(x_½, u).

use super::implicit::{Implicit, Rule, StageKind};

/// The midpoint rule: a stage at half the step, then the extrapolation to the step's end.
#[derive(Debug, Default)]
pub struct Midpoint;

/// Implicit midpoint with the shared Newton + block-Jacobi-preconditioned CG core.
pub type ImplicitMidpoint = Implicit<Midpoint>;

impl Rule for Midpoint {
    const NAME: &'static str = "implicit_midpoint";
    const STAGE: StageKind = StageKind::Midpoint;
}
