//! The linear solve of one Newton iteration, A Δv = b with A = M − h ∂f/∂v − h² ∂f/∂x, by the
//! configured [`LinearSolver`], to the inexact-Newton tolerance the Newton loop sets.
//!
//! [`LinearSolver::BlockJacobiCg`] (the default) is matrix-free CG with the inverse 3×3
//! diagonal blocks as preconditioner ([`solve_clamped`]). [`LinearSolver::BlockIc0Cg`] is
//! the same solve (exact matrix first, clamped on non-positive curvature, Steihaug–Toint in
//! the trust region) preconditioned instead by a block incomplete Cholesky factor IC(0) of the
//! *clamped* (SPD) Newton matrix at the current iterate, refactored at every Newton iteration
//! on a pattern kept per topology (`ic0.rs`). [`LinearSolver::Cholesky`] is a
//! modified Newton with a Krylov correction: a sparse Cholesky factor (faer, AMD ordering) of
//! the *clamped* (SPD) Newton matrix preconditions CG on the *exact* one; the factor is kept
//! across Newton iterations and steps while CG converges within
//! [`ImplicitSettings::refactor_after`] iterations, else refactored at the current iterate.
//! Where the exact matrix is indefinite (CG meets non-positive curvature), the step is the
//! projected-Newton direction, the clamped system solved directly with a fresh factor
//! (Teran, Sifakis, Irving & Fedkiw, SCA 2005).
//!
//! Why block Jacobi is the default, measured with `springlab bench-ratios --rounds 3
//! --no-rapier` (implicit Euler, cloth at 1/60 s, 10 steps from rest, 2 shared cores):
//! the cloth's Newton matrix is well conditioned whatever its size (the mass term bounds
//! the smallest eigenvalue, and k, m per particle do not change with n), so block-Jacobi CG
//! needs ≈ 23-27 iterations per Newton iteration at the inexact-Newton tolerance on 32², 100²
//! and 316² alike, each about one force evaluation's cost (100²: 41 ms per step). On 100²
//! (30 000 unknowns, 3.3 M nonzeros in L) one numeric factorisation took ≈ 35 ms and one
//! triangular solve pair ≈ 7 ms, so even at ≈ 6 preconditioned iterations per Newton
//! iteration and a factor every other step the Cholesky solve cost 277 ms per step; on 32²
//! 9.5 ms against 6.0 ms. A factorisation's cost grows faster than n² while CG's does not.
//!
//! Block IC(0) cuts the iterations about fourfold, to 5.5-6.1 per Newton iteration on 32²,
//! 100² and 316² (block Jacobi: 22.9-26.6 in the same runs), but each iteration adds two
//! sequential block triangular solves (≈ two products' work, on one core) where block Jacobi
//! multiplies by a block diagonal in parallel, and each Newton iteration fills the Jacobian a
//! second time (clamped) and factors it; the residuals and line searches cost the same either
//! way. One run each: implicit Euler 1.6 / 29 / 765 ms per step on 32² / 100² / 316² against
//! 2.8 / 41 / 1073 ms; but 16 interleaved pairs of 100² runs on the shared machine put the
//! two within noise of each other (medians 36 and 34-36 ms, pairwise ratio median 1.01, spread
//! 0.75-1.33), short of the clear (> 10 %) gain that would justify a new default. It wins
//! where one solve needs many iterations: linearly implicit Euler (one solve per step, 145
//! block-Jacobi iterations) ran 22-33 ms against 36-55 ms at 100², and so does 316², where
//! 3 interleaved pairs gave implicit Euler 565-773 ms against 1061-1184 ms per step and
//! linearly implicit Euler 473-687 ms against 1170-1407 ms. Algebraic multigrid was not built: its gain is an iteration count
//! independent of the mesh size, which block-Jacobi CG already has here (the mass term bounds
//! the smallest eigenvalue: h²k/m does not change with n), so AMG could only lower the
//! constant, as IC(0) does, and IC(0)'s fourfold lower constant did not pay at 100².

use super::cg::{solve_clamped, Cg, Indefinite};
#[cfg(feature = "direct-solver")]
use super::cg::{CgOutcome, Precond};
#[cfg(feature = "direct-solver")]
use super::direct::Factor;
use super::ic0::Ic0;
use super::ImplicitSettings;
use crate::model::{Jacobian, System, Vec3};

/// Which linear solver the implicit core uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolver {
    /// Matrix-free CG preconditioned by the inverse 3×3 diagonal blocks, clamping compressed
    /// springs in steps on non-positive curvature: the measured fastest (module docs).
    #[default]
    BlockJacobiCg,
    /// CG preconditioned by a block incomplete Cholesky factor IC(0) of the clamped Newton
    /// matrix, refactored at every Newton iteration; clamps on non-positive curvature as
    /// [`LinearSolver::BlockJacobiCg`] does (module docs).
    BlockIc0Cg,
    /// CG preconditioned by a reused sparse Cholesky factor of the clamped Newton matrix;
    /// projected Newton (the clamped system, solved directly) where the exact matrix is
    /// indefinite. Built with the `direct-solver` feature only.
    #[cfg(feature = "direct-solver")]
    Cholesky,
}

impl LinearSolver {
    /// Every solver compiled in, the default first.
    pub const ALL: &'static [LinearSolver] = &[
        LinearSolver::BlockJacobiCg,
        LinearSolver::BlockIc0Cg,
        #[cfg(feature = "direct-solver")]
        LinearSolver::Cholesky,
    ];

    /// The name bench reports print and `--implicit-solver` takes.
    pub fn name(self) -> &'static str {
        match self {
            LinearSolver::BlockJacobiCg => "block_jacobi_cg",
            LinearSolver::BlockIc0Cg => "block_ic0_cg",
            #[cfg(feature = "direct-solver")]
            LinearSolver::Cholesky => "cholesky_pcg",
        }
    }

    /// The solver called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|s| s.name() == name)
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
    /// Numeric factorisations so far.
    pub(super) factorizations: u64,
}

impl LinearSolve {
    /// Forgets the factor (the next solve refactors).
    pub(super) fn invalidate(&mut self) {
        #[cfg(feature = "direct-solver")]
        self.factor.invalidate();
    }

    /// The last trust-region solve's (model value m(s), ‖s‖_P, radius used), see [`Cg::solve`].
    pub(super) fn trust_step(&self) -> (f64, f64, f64) {
        (self.cg.model, self.cg.step_norm, self.cg.radius)
    }

    /// Fills `jac` at (x, v) with the given clamp and prepares the Newton matrix for step h.
    #[cfg(feature = "direct-solver")]
    fn fill(jac: &mut Jacobian, sys: &System, x: &[Vec3], v: &[Vec3], h: f64, clamp: f64) {
        jac.clamp = clamp;
        sys.jacobian(x, v, jac);
        jac.prepare_newton(&sys.mass, &sys.free, h);
    }

    /// Factors the clamped Newton matrix at (x, v).
    #[cfg(feature = "direct-solver")]
    fn refactor(
        &mut self,
        jac: &mut Jacobian,
        sys: &System,
        x: &[Vec3],
        v: &[Vec3],
        h: f64,
    ) -> Result<(), Indefinite> {
        Self::fill(jac, sys, x, v, h, 1.0);
        self.factorizations += 1;
        self.factor_h = h;
        self.factor.factor(jac, &sys.free).map_err(|_| Indefinite)
    }

    /// Solves A dv = b for the Newton matrix at (x, v) with step `h`; `rhs(jac, b)` writes the
    /// right-hand side for the Jacobian as filled (it may depend on it). A solve that runs out
    /// of iterations leaves its partial solution (the caller's residual check decides).
    /// Returns the linear iterations spent (CG iterations; a direct solve counts one).
    /// `abs_tol2`: CG may stop once Σ |rᵢ|²/mᵢ of its residual is below it (0: never).
    /// `radius`: Some(Δ) for a trust-region (Steihaug–Toint) step of the block-Jacobi or IC(0)
    /// solver, whose model value and P-norm [`LinearSolve::trust_step`] then reports; the
    /// Cholesky solver ignores it.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve(
        &mut self,
        jac: &mut Jacobian,
        sys: &System,
        x: &[Vec3],
        v: &[Vec3],
        h: f64,
        set: &ImplicitSettings,
        rhs: impl FnMut(&Jacobian, &mut [Vec3]),
        b: &mut [Vec3],
        dv: &mut [Vec3],
        abs_tol2: f64,
        radius: Option<f64>,
    ) -> Result<u64, Indefinite> {
        if matches!(
            set.solver,
            LinearSolver::BlockJacobiCg | LinearSolver::BlockIc0Cg
        ) {
            let ic0 = if set.solver == LinearSolver::BlockIc0Cg {
                self.factorizations += 1;
                Some(&mut self.ic0)
            } else {
                None
            };
            return solve_clamped(
                &mut self.cg,
                ic0,
                jac,
                sys,
                x,
                v,
                h,
                set,
                rhs,
                b,
                dv,
                abs_tol2,
                radius,
            );
        }
        #[cfg(feature = "direct-solver")]
        return self.solve_factored(jac, sys, x, v, h, set, rhs, b, dv, abs_tol2);
        #[cfg(not(feature = "direct-solver"))]
        unreachable!("the CG solvers are the only ones without the direct-solver feature")
    }

    /// [`LinearSolver::Cholesky`]'s solve (module docs).
    #[cfg(feature = "direct-solver")]
    #[allow(clippy::too_many_arguments)]
    fn solve_factored(
        &mut self,
        jac: &mut Jacobian,
        sys: &System,
        x: &[Vec3],
        v: &[Vec3],
        h: f64,
        set: &ImplicitSettings,
        mut rhs: impl FnMut(&Jacobian, &mut [Vec3]),
        b: &mut [Vec3],
        dv: &mut [Vec3],
        abs_tol2: f64,
    ) -> Result<u64, Indefinite> {
        // The matrix-free solve, which clamps what it can and reports the rest: the fallback
        // wherever no factor can be built.
        macro_rules! clamped {
            () => {
                solve_clamped(
                    &mut self.cg,
                    None,
                    jac,
                    sys,
                    x,
                    v,
                    h,
                    set,
                    rhs,
                    b,
                    dv,
                    abs_tol2,
                    None,
                )
            };
        }
        let mut fresh = false;
        if !self.factor.is_factored() || self.factor_h != h {
            if self.refactor(jac, sys, x, v, h).is_err() {
                // Not SPD even clamped (a force term with an indefinite Jacobian of its own):
                // the matrix-free solve, which clamps what it can and reports the rest.
                return clamped!();
            }
            fresh = true;
        }
        let mut spent = 0u64;
        loop {
            Self::fill(jac, sys, x, v, h, 0.0);
            rhs(jac, b);
            let cap = if fresh {
                set.max_cg
            } else {
                set.refactor_after
            };
            let pre = Precond::Factor(&mut self.factor);
            match self
                .cg
                .solve(jac, sys, b, dv, set, pre, cap, abs_tol2, None)
            {
                // No trust radius is given here, so CG never stops on a boundary.
                CgOutcome::Converged(it) | CgOutcome::Boundary(it) => return Ok(spent + it as u64),
                CgOutcome::NotConverged(it) if !fresh => spent += it as u64,
                CgOutcome::NotConverged(it) => return Ok(spent + it as u64),
                CgOutcome::NegativeCurvature(it) => {
                    // Indefinite: the projected-Newton direction, the clamped system solved
                    // with a factor at this iterate.
                    spent += it as u64;
                    if !fresh {
                        if self.refactor(jac, sys, x, v, h).is_err() {
                            return clamped!();
                        }
                    } else {
                        Self::fill(jac, sys, x, v, h, 1.0);
                    }
                    rhs(jac, b);
                    self.factor.solve(&sys.free, b, dv);
                    return Ok(spent + 1);
                }
            }
            // The stale factor preconditions poorly: refactor here and solve again.
            if self.refactor(jac, sys, x, v, h).is_err() {
                return clamped!();
            }
            fresh = true;
        }
    }
}
