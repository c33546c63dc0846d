//! The linearly implicit stage (Baraff & Witkin, "Large steps in cloth simulation", SIGGRAPH
//! 1998, eq. 18): backward Euler with the forces linearised at the start of the step,
//!
//!   (M − h ∂f/∂v − h² ∂f/∂x) Δv = h (f₀ + h ∂f/∂x v₀),  v' = v₀ + Δv,  x' = x₀ + h v',
//!
//! one linear solve per step on the same matrix, CG and clamping as the Newton stage. On a
//! translation-invariant system the solution is shifted to keep linear momentum exactly
//! (`momentum.rs`).

use super::linsolve::{Indefiniteness, LinearProblem};
use super::Newton;
use crate::error::{Error, Result};
use crate::model::{System, Vec3};

impl Newton {
    /// Writes the linearly implicit solution from (`x0`, `v0`) with step `h` into
    /// [`Newton::x`], [`Newton::v`] (one force evaluation, one Jacobian, one linear solve).
    /// `Err(())` when no clamping makes the matrix positive definite.
    pub(super) fn linearized(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
    ) -> std::result::Result<(), ()> {
        let n = x0.len();
        self.prepare(sys);
        let mut jac = self.take_jacobian(sys);
        sys.forces(x0, v0, &mut self.f);
        let (f0, kv, free) = (&self.f, &mut self.vpred, &sys.free);
        let rhs = |jac: &crate::model::Jacobian, b: &mut [Vec3]| {
            jac.position_matvec(free, v0, kv);
            for p in 0..n {
                b[p] = (f0[p] + kv[p] * h) * h;
            }
        };
        self.newton_iterations += 1;
        let prob = LinearProblem {
            sys,
            x: x0,
            v: v0,
            h,
            set: &self.settings,
            abs_tol2: 0.0,
        };
        let solved = self.lin.solve(
            &mut jac,
            &prob,
            rhs,
            &mut self.r,
            &mut self.dv,
            Indefiniteness::Clamp,
        );
        self.jac = Some(jac);
        self.cg_iterations += solved.map_err(|_| ())?;
        if self.shift_mass > 0.0 {
            // A free system: A c = M c for a uniform c, so this shift zeroes the momentum
            // balance Σ(b − A Δv) that an inexact solve leaves (see `momentum.rs`).
            let mut unbalanced = Vec3::zeros();
            for p in 0..n {
                unbalanced += self.r[p] - self.dv[p] * sys.mass[p];
            }
            let c = unbalanced / self.shift_mass;
            self.dv.iter_mut().for_each(|d| *d += c);
        }
        for p in 0..n {
            self.vn[p] = if sys.free[p] {
                v0[p] + self.dv[p]
            } else {
                v0[p]
            };
            self.xn[p] = x0[p] + self.vn[p] * h;
            // The explicit Euler predictor, for the Newton stage's error estimate.
            self.vpred[p] = v0[p] + self.f[p] * (h * sys.inv_mass[p]);
        }
        Ok(())
    }

    /// One linearly implicit Euler step from (`x0`, `v0`) with step `h`; the result is in
    /// [`Newton::x`], [`Newton::v`]. Returns the dissipated power at the new state (for the
    /// energy account, as backward Euler books it) and the force evaluations made (2: the
    /// linearisation point and the new state).
    pub(crate) fn solve_linearized(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
        who: &'static str,
    ) -> Result<(f64, u64)> {
        self.linearized(sys, x0, v0, h).map_err(|_| {
            Error::Step(format!(
                "{who}: the linear system is not positive definite even after clamping"
            ))
        })?;
        let power = sys.forces(&self.xn, &self.vn, &mut self.f);
        if !power.is_finite() || self.vn.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(Error::Step(format!(
                "{who}: non-finite solution of the linear system"
            )));
        }
        Ok((power, 2))
    }
}
