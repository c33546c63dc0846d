//! BDF2, the two-step backward differentiation formula (Hairer & Wanner, *Solving ODEs II*,
//! §III.1 and §V.1), as used for cloth since Choi & Ko, "Stable but responsive cloth" (2002):
//!
//!   yₙ₊₁ − (4/3) yₙ + (1/3) yₙ₋₁ = (2h/3) F(yₙ₊₁).
//!
//! With the extrapolated base (x̂, v̂) = ((4xₙ − xₙ₋₁)/3, (4vₙ − vₙ₋₁)/3) this is a
//! backward-Euler stage of step 2h/3 from (x̂, v̂), solved by the shared implicit core
//! ([`Newton`]), stopping at a root to the root tolerance, early there at 0.01 % of its error
//! estimate.
//!
//! Starting step: BDF2 needs yₙ₋₁, so the first step, and the first after a reset (an impulse,
//! a contact, a new step size), is one backward-Euler step; its O(h²) local error is made
//! once, so the global order stays 2. Order 2, A-stable and L-stable (both roots of the
//! characteristic equation → 0 as hω → ∞); it damps an undamped oscillator slowly, by
//! O((hω)⁴) per step. Dissipated work is booked by the trapezoidal rule over each step
//! (backward Euler's h·P at the start).

use super::ensure_len;
use super::implicit::{Implicit, Rule};
use super::newton::{Newton, Stop};
use crate::error::Result;
use crate::model::{State, System, Vec3};

/// BDF2's rule: a stage of step 2h/3 from the extrapolated base, after a backward-Euler start;
/// it keeps the previous state and the dissipated power at the current one.
#[derive(Debug, Default)]
pub struct Bdf2Rule {
    x_prev: Vec<Vec3>,
    v_prev: Vec<Vec3>,
    x_base: Vec<Vec3>,
    v_base: Vec<Vec3>,
    /// Dissipated power at the current state (end of the last step).
    power: f64,
    /// Step of the last step; `None` when the history is void (start or reset).
    h_prev: Option<f64>,
}

/// BDF2 with a backward-Euler start, on the shared Newton + block-Jacobi-PCG core.
pub type Bdf2 = Implicit<Bdf2Rule>;

impl Rule for Bdf2Rule {
    const NAME: &'static str = "bdf2";
    const RECURRENCE_STEPS: usize = 2;
    fn reset(&mut self) {
        self.h_prev = None;
    }
    fn advance(
        &mut self,
        newton: &mut Newton,
        sys: &System,
        s: &mut State,
        h: f64,
    ) -> Result<(f64, u64)> {
        let n = s.len();
        for buf in [
            &mut self.x_prev,
            &mut self.v_prev,
            &mut self.x_base,
            &mut self.v_base,
        ] {
            ensure_len(buf, n);
        }
        let start = self.h_prev != Some(h);
        let (power, evals, dissipated);
        if start {
            (power, evals) = newton.solve(sys, &s.x, &s.v, h, Stop::SecondOrder, Self::NAME)?;
            dissipated = power * h;
        } else {
            for p in 0..n {
                // Fixed particles keep their state exactly ((4x − x)/3 need not round to x).
                (self.x_base[p], self.v_base[p]) = if sys.free[p] {
                    (
                        (s.x[p] * 4.0 - self.x_prev[p]) / 3.0,
                        (s.v[p] * 4.0 - self.v_prev[p]) / 3.0,
                    )
                } else {
                    (s.x[p], s.v[p])
                };
            }
            (power, evals) = newton.solve(
                sys,
                &self.x_base,
                &self.v_base,
                2.0 * h / 3.0,
                Stop::SecondOrder,
                Self::NAME,
            )?;
            dissipated = 0.5 * h * (self.power + power);
        }
        self.x_prev.copy_from_slice(&s.x);
        self.v_prev.copy_from_slice(&s.v);
        s.x.copy_from_slice(newton.x());
        s.v.copy_from_slice(newton.v());
        self.power = power;
        self.h_prev = Some(h);
        Ok((dissipated, evals))
    }
}
