//! BDF2, the two-step backward differentiation formula (Hairer & Wanner, *Solving ODEs II*,
//! §III.1 and §V.1), as used for cloth since Choi & Ko, "Stable but responsive cloth" (2002):
//!
//!   yₙ₊₁ − (4/3) yₙ + (1/3) yₙ₋₁ = (2h/3) F(yₙ₊₁).
//!
//! With the extrapolated base (x̂, v̂) = ((4xₙ − xₙ₋₁)/3, (4vₙ − vₙ₋₁)/3) this is a
//! backward-Euler stage of step 2h/3 from (x̂, v̂), solved by the shared implicit core
//! ([`Newton`](super::Newton)), stopping at a root to the root tolerance, early there at 0.01 % of its error
//! estimate.
//!
//! Starting step: BDF2 needs yₙ₋₁, so the first step, and the first after a reset (an impulse,
//! a contact, a new step size), is one backward-Euler step; its O(h²) local error is made
//! once, so the global order stays 2. Order 2, A-stable and L-stable (both roots of the
//! characteristic equation → 0 as hω → ∞); it damps an undamped oscillator slowly, by
//! O((hω)⁴) per step. Dissipated work is booked by the trapezoidal rule over each step
//! (backward Euler's h·P at the start).

use super::implicit::{Implicit, Rule, StageKind};

/// BDF2's rule: a stage of step 2h/3 from the extrapolated base, after a backward-Euler start.
#[derive(Debug, Default)]
pub struct Bdf2Rule;

/// BDF2 with a backward-Euler start, on the shared Newton + block-Jacobi-PCG core.
pub type Bdf2 = Implicit<Bdf2Rule>;

impl Rule for Bdf2Rule {
    const NAME: &'static str = "bdf2";
    const STAGE: StageKind = StageKind::Bdf2;
}
