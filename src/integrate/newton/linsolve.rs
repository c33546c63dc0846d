//! The linear solve of one Newton iteration, A Δv = b with A = M − h ∂f/∂v − h² ∂f/∂x, by the
//! configured [`LinearSolver`], to the inexact-Newton tolerance the Newton loop sets.
//!
//! [`LinearSolver::BlockJacobiCg`] (the default) is matrix-free CG preconditioned by the
//! inverse 3×3 diagonal blocks; CG runs on the exact matrix with the stage's
//! Levenberg–Marquardt shift, raised where it meets non-positive curvature ([`solve_shifted`]).
//! [`LinearSolver::BlockIc0Cg`] is the same solve preconditioned by a
//! block incomplete Cholesky factor IC(0) of the *clamped* (SPD) Newton matrix at the current
//! iterate, refactored at every Newton iteration on a pattern kept per topology (`ic0.rs`).
//! [`LinearSolver::Cholesky`] is a modified Newton with a Krylov correction: a sparse
//! Cholesky factor (faer, AMD ordering) of the clamped Newton matrix preconditions CG on the
//! exact one; the factor is kept across Newton iterations and steps while CG converges within
//! [`ImplicitSettings::refactor_after`] iterations, else refactored at the current iterate.
//! Where the exact matrix is indefinite (CG meets non-positive curvature), the step is the
//! projected-Newton direction, the clamped system solved directly with a fresh factor
//! (Teran, Sifakis, Irving & Fedkiw, SCA 2005).
//!
//! The choice. The cloth's Newton matrix is well conditioned whatever its size (the mass
//! term bounds the smallest eigenvalue, and h²k/m does not change with n), so block-Jacobi CG
//! needs ≈ 32-46 iterations per Newton iteration on 32², 100² and 316² alike; IC(0) cuts that
//! about fourfold, to 8-11, at the price of two sequential triangular solves per iteration
//! and a factorisation per Newton iteration. Over the first 10 frames from rest
//! (`springlab bench-ratios --no-rapier --rounds 5 --implicit-sizes 32,100
//! --implicit-solver S`, 2-core machine, two runs per solver alternated), the cost of a step
//! in symplectic steps of the same cloth timed in the same run (the minimum over the rounds),
//! IC(0) against block Jacobi:
//!
//! | method | 32² | 100² |
//! |---|---|---|
//! | implicit_euler | 88.3, 88.4 / 114.3, 123.8 | 118.7, 123.6 / 143.5, 149.8 |
//! | implicit_midpoint | 92.4, 95.6 / 114.9, 121.8 | 107.6, 110.4 / 120.4, 124.9 |
//! | bdf2 | 107.9, 107.9 / 144.1, 147.6 | 126.3, 132.2 / 160.4, 157.0 |
//! | linear_implicit_euler | 54.7, 55.7 / 79.8, 81.5 | 65.5, 66.5 / 98.2, 101.7 |
//!
//! From rest IC(0) takes 11-34 % less time; on the 316² cloth, where block Jacobi's products
//! run on two threads and IC(0) runs on one, the two are level (implicit Euler's 10 frames:
//! IC(0) takes 0.94 of block Jacobi's wall time and 0.61 of its processor time), and over
//! the 100² cloth's 3 s, where most Newton iterations are shifted, they are level too
//! (implicit Euler: 102.9 against 100.6 ms per step; `--implicit-steps 180 --rounds 1`).
//! Block Jacobi stays the default: IC(0) gains from rest only, and a default changes every
//! implicit run's iterates. The modelled cost (`run/cost.rs`) prices IC(0)'s factorisations
//! and substitutions apart, so either solver's runs are priced within the model's usual
//! distance of the clock.
//!
//! Neither completes the 316² cloth's 3 s at 1/60 (`springlab bench-ratios --no-rapier
//! --implicit-methods implicit_euler --implicit-sizes 316 --implicit-steps 180 --rounds 1`):
//! with the shifted Newton block Jacobi stops at frame 64 and IC(0) at frame 66, stages
//! crawling along a fold's valley under the default cap of 50 Newton iterations; the step is
//! then reported as failed, never accepted off its root. The sparse Cholesky lost everywhere:
//! on 100² (30 000 unknowns, 3.3 M nonzeros in L) one numeric factorisation took ≈ 35 ms and
//! one triangular solve pair ≈ 7 ms, 277 ms per step against block Jacobi's 41 ms in the same
//! run; on 32², 9.5 against 6.0 ms. Block-Jacobi CG already needs about
//! the same iterations per Newton iteration whatever the mesh size, so a multilevel method
//! can only lower the constant; the one-level and two-level preconditioners measured against
//! the cost target (`docs/performance.md`) lower it less than they add per iteration.

use super::cg::{solve_clamped, solve_shifted, Cg, CgStop, Indefinite};
#[cfg(feature = "direct-solver")]
use super::cg::{CgOutcome, Precond};
#[cfg(feature = "direct-solver")]
use super::direct::Factor;
use super::ic0::Ic0;
use super::settings::{ImplicitSettings, LinearSolver};
use crate::model::{Jacobian, System, Vec3};

/// What a solve does where the exact matrix is indefinite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Indefiniteness {
    /// Raise the Levenberg–Marquardt shift `jac.shift` (a Newton direction, `shift.rs`).
    Shift,
    /// Drop compressed springs' negative stiffness (the linearly implicit method's matrix).
    Clamp,
}

/// One system A Δv = b of the Newton matrix: the iterate (x, v) at which the Jacobian is
/// taken, the step h, the solver settings and the inexact-Newton stop. Every layer of the
/// solve (the solver choice, the factored, shifted and clamped solves) reads all of them.
#[derive(Clone, Copy)]
pub(super) struct LinearProblem<'a> {
    /// The system whose Newton matrix it is.
    pub(super) sys: &'a System,
    /// Positions at which the Jacobian is taken.
    pub(super) x: &'a [Vec3],
    /// Velocities at which the Jacobian is taken.
    pub(super) v: &'a [Vec3],
    /// The stage's step (β).
    pub(super) h: f64,
    /// Solver choice, iteration caps and CG tolerance.
    pub(super) set: &'a ImplicitSettings,
    /// CG may stop once Σ |rᵢ|²/mᵢ of its residual is below it (0: never).
    pub(super) abs_tol2: f64,
}

impl LinearProblem<'_> {
    /// CG's stop on this problem with at most `max_it` iterations.
    pub(super) fn cg_stop(&self, max_it: usize) -> CgStop {
        CgStop {
            max_it,
            rel_tol: self.set.cg_tol,
            abs_tol2: self.abs_tol2,
        }
    }
}

/// Scratch and state of the linear solves: CG vectors and the reusable factors.
#[derive(Debug, Default)]
pub(super) struct LinearSolve {
    cg: Cg,
    /// [`LinearSolver::BlockIc0Cg`]'s factor (its pattern kept across iterations and steps).
    ic0: Ic0,
    #[cfg(feature = "direct-solver")]
    factor: Factor,
    /// Step the factor was built for (the matrix scales with it).
    #[cfg(feature = "direct-solver")]
    factor_h: f64,
    /// Numeric factorisations of the sparse Cholesky factor so far.
    pub(super) factorizations: u64,
}

impl LinearSolve {
    /// Numeric factorisations so far, IC(0)'s and the sparse Cholesky's.
    pub(super) fn factorizations(&self) -> u64 {
        self.factorizations + self.ic0.factorizations
    }
    /// Applications of a factored preconditioner so far.
    pub(super) fn factor_solves(&self) -> u64 {
        self.cg.factor_solves
    }

    /// Forgets the factor (the next solve refactors).
    pub(super) fn invalidate(&mut self) {
        #[cfg(feature = "direct-solver")]
        self.factor.invalidate();
    }

    /// Factors the clamped Newton matrix at `prob`'s (x, v).
    #[cfg(feature = "direct-solver")]
    fn refactor(&mut self, jac: &mut Jacobian, prob: &LinearProblem<'_>) -> Result<(), Indefinite> {
        prob.sys.newton_matrix(prob.x, prob.v, prob.h, 1.0, jac);
        self.factorizations += 1;
        self.factor_h = prob.h;
        self.factor
            .factor(jac, &prob.sys.free)
            .map_err(|_| Indefinite)
    }

    /// Solves A dv = b for the Newton matrix of `prob`; `rhs(jac, b)` writes the right-hand
    /// side for the Jacobian as filled (it may depend on it). A solve that runs out of
    /// iterations leaves its partial solution (the caller's residual check decides). Returns
    /// the linear iterations spent (CG iterations; a direct solve counts one). The
    /// block-Jacobi and IC(0) solvers solve the matrix shifted by `jac.shift` and raise the
    /// shift until it is positive definite (`shift.rs`); the Cholesky solver projects.
    pub(super) fn solve(
        &mut self,
        jac: &mut Jacobian,
        prob: &LinearProblem<'_>,
        rhs: impl FnMut(&Jacobian, &mut [Vec3]),
        b: &mut [Vec3],
        dv: &mut [Vec3],
        indefinite: Indefiniteness,
    ) -> Result<u64, Indefinite> {
        let set = prob.set;
        if matches!(
            set.solver,
            LinearSolver::BlockJacobiCg | LinearSolver::BlockIc0Cg
        ) {
            let ic0 = if set.solver == LinearSolver::BlockIc0Cg {
                Some(&mut self.ic0)
            } else {
                None
            };
            let solve = match indefinite {
                Indefiniteness::Shift => solve_shifted,
                Indefiniteness::Clamp => solve_clamped,
            };
            return solve(&mut self.cg, ic0, jac, prob, rhs, b, dv);
        }
        #[cfg(feature = "direct-solver")]
        return self.solve_factored(jac, prob, rhs, b, dv, indefinite);
        #[cfg(not(feature = "direct-solver"))]
        unreachable!("the CG solvers are the only ones without the direct-solver feature")
    }

    /// [`LinearSolver::Cholesky`]'s solve (module docs).
    #[cfg(feature = "direct-solver")]
    fn solve_factored(
        &mut self,
        jac: &mut Jacobian,
        prob: &LinearProblem<'_>,
        mut rhs: impl FnMut(&Jacobian, &mut [Vec3]),
        b: &mut [Vec3],
        dv: &mut [Vec3],
        indefinite: Indefiniteness,
    ) -> Result<u64, Indefinite> {
        let (sys, h, set) = (prob.sys, prob.h, prob.set);
        // The matrix-free shifted solve: the fallback
        // wherever no factor can be built.
        let fallback = match indefinite {
            Indefiniteness::Shift => solve_shifted,
            Indefiniteness::Clamp => solve_clamped,
        };
        macro_rules! clamped {
            () => {
                fallback(&mut self.cg, None, jac, prob, rhs, b, dv)
            };
        }
        let mut fresh = false;
        if !self.factor.is_factored() || self.factor_h != h {
            if self.refactor(jac, prob).is_err() {
                // Not SPD even clamped (a force term with an indefinite Jacobian of its own):
                // the matrix-free shifted solve.
                return clamped!();
            }
            fresh = true;
        }
        let mut spent = 0u64;
        loop {
            prob.sys.newton_matrix(prob.x, prob.v, prob.h, 0.0, jac);
            rhs(jac, b);
            let cap = if fresh {
                set.max_cg
            } else {
                set.refactor_after
            };
            let pre = Precond::Factor(&mut self.factor);
            match self.cg.solve(jac, sys, b, dv, pre, prob.cg_stop(cap)) {
                CgOutcome::Converged(it) => return Ok(spent + it as u64),
                CgOutcome::NotConverged(it) if !fresh => spent += it as u64,
                CgOutcome::NotConverged(it) => return Ok(spent + it as u64),
                CgOutcome::NegativeCurvature(it) => {
                    // Indefinite: the projected-Newton direction, the clamped system solved
                    // with a factor at this iterate.
                    spent += it as u64;
                    if !fresh {
                        if self.refactor(jac, prob).is_err() {
                            return clamped!();
                        }
                    } else {
                        prob.sys.newton_matrix(prob.x, prob.v, prob.h, 1.0, jac);
                    }
                    rhs(jac, b);
                    self.cg.factor_solves += 1;
                    self.factor.solve(&sys.free, b, dv);
                    return Ok(spent + 1);
                }
            }
            // The stale factor preconditions poorly: refactor here and solve again.
            if self.refactor(jac, prob).is_err() {
                return clamped!();
            }
            fresh = true;
        }
    }
}
