//! The linear-solve half of the shared implicit core: conjugate gradients on the Newton matrix
//! A = M − h ∂f/∂v − h² ∂f/∂x, preconditioned by its inverse 3×3 diagonal blocks (block
//! Jacobi), matrix-free, so one iteration costs one pass over particles and springs.
//!
//! A compressed spring makes the exact Jacobian indefinite; [`solve_clamped`] then redoes the
//! solve with more and more of the compressed springs' negative stiffness dropped (50 %,
//! 87.5 %, 100 %: the last is SPD). Large systems run the products and vector updates in
//! parallel over fixed chunks, and dot products sum fixed chunk partials in order, so results
//! are bit-identical for any thread count.

#[cfg(feature = "direct-solver")]
use super::direct::Factor;
use super::ImplicitSettings;
use crate::integrate::ensure_len;
use crate::model::parallel::{dot, each_particle, each_particle2};
use crate::model::{Jacobian, System, Vec3};
use nalgebra::Matrix3;

/// Fractions of compressed springs' indefinite stiffness dropped in successive attempts at
/// one linear solve (see [`Jacobian::clamp`]).
pub(super) const CLAMPS: [f64; 4] = [0.0, 0.5, 0.875, 1.0];

/// Scratch of the preconditioned CG iteration.
#[derive(Debug, Default)]
pub(super) struct Cg {
    diag_inv: Vec<Matrix3<f64>>,
    r: Vec<Vec3>,
    z: Vec<Vec3>,
    p: Vec<Vec3>,
    ap: Vec<Vec3>,
    /// Chunk sums of the dot products.
    parts: Vec<f64>,
}

/// The preconditioner of one CG solve.
pub(super) enum Precond<'a> {
    /// The inverse 3×3 diagonal blocks of the matrix itself.
    BlockJacobi,
    /// A sparse Cholesky factor of a nearby SPD matrix (the clamped Newton matrix, possibly
    /// of an earlier iterate or step).
    #[cfg(feature = "direct-solver")]
    Factor(&'a mut Factor),
    /// Never built: keeps the lifetime when the direct solver is not compiled in.
    #[cfg(not(feature = "direct-solver"))]
    #[allow(dead_code)]
    Unused(std::marker::PhantomData<&'a ()>),
}

/// How one CG solve ended (with its iteration count).
pub(super) enum CgOutcome {
    Converged(usize),
    NegativeCurvature(usize),
    NotConverged(usize),
}

impl Cg {
    /// Solves A x = b for the Newton matrix prepared in `jac` by CG preconditioned with
    /// `pre`, at most `max_it` iterations; x starts at zero. Stops at the relative tolerance
    /// [`ImplicitSettings::cg_tol`] or when the residual's Σ |rᵢ|²/mᵢ falls to `abs_tol2`
    /// (the inexact-Newton forcing; 0 for none).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve(
        &mut self,
        jac: &Jacobian,
        sys: &System,
        b: &[Vec3],
        x: &mut [Vec3],
        set: &ImplicitSettings,
        mut pre: Precond<'_>,
        max_it: usize,
        abs_tol2: f64,
    ) -> CgOutcome {
        let n = b.len();
        for buf in [&mut self.r, &mut self.z, &mut self.p, &mut self.ap] {
            ensure_len(buf, n);
        }
        if matches!(pre, Precond::BlockJacobi) {
            ensure_len(&mut self.diag_inv, n);
            jac.newton_diagonal(&sys.free, &mut self.diag_inv);
            each_particle(&mut self.diag_inv, |_, d| {
                *d = d.try_inverse().unwrap_or_else(Matrix3::identity)
            });
        }
        let free = &sys.free;
        each_particle2(x, &mut self.r, |i, xi, ri| {
            *xi = Vec3::zeros();
            *ri = if free[i] { b[i] } else { Vec3::zeros() };
        });
        self.precondition(&mut pre, free);
        self.p.copy_from_slice(&self.z);
        let mut rz = dot(&self.r, &self.z, &mut self.parts);
        let rz0 = rz;
        if rz0 == 0.0 {
            return CgOutcome::Converged(0);
        }
        for it in 0..max_it {
            jac.newton_matvec(free, &self.p, &mut self.ap);
            each_particle(&mut self.ap, |i, a| {
                if !free[i] {
                    *a = Vec3::zeros();
                }
            });
            let pap = dot(&self.p, &self.ap, &mut self.parts);
            if pap <= 0.0 || !pap.is_finite() {
                return CgOutcome::NegativeCurvature(it);
            }
            let alpha = rz / pap;
            let (p, ap) = (&self.p, &self.ap);
            each_particle2(x, &mut self.r, |i, xi, ri| {
                *xi += p[i] * alpha;
                *ri -= ap[i] * alpha;
            });
            if abs_tol2 > 0.0 {
                // `ap` is free until the next product: it holds M⁻¹ r for the forcing test.
                let (r, im) = (&self.r, &sys.inv_mass);
                each_particle(&mut self.ap, |i, a| *a = r[i] * im[i]);
                if dot(&self.r, &self.ap, &mut self.parts) <= abs_tol2 {
                    return CgOutcome::Converged(it + 1);
                }
            }
            self.precondition(&mut pre, free);
            let rz_new = dot(&self.r, &self.z, &mut self.parts);
            if rz_new <= set.cg_tol * set.cg_tol * rz0 {
                return CgOutcome::Converged(it + 1);
            }
            let beta = rz_new / rz;
            rz = rz_new;
            let z = &self.z;
            each_particle(&mut self.p, |i, pi| *pi = z[i] + *pi * beta);
        }
        CgOutcome::NotConverged(max_it)
    }

    /// z = P⁻¹ r.
    fn precondition(&mut self, pre: &mut Precond<'_>, free: &[bool]) {
        match pre {
            Precond::BlockJacobi => {
                let (r, d) = (&self.r, &self.diag_inv);
                each_particle(&mut self.z, |i, zi| *zi = d[i] * r[i]);
            }
            #[cfg(feature = "direct-solver")]
            Precond::Factor(f) => f.solve(free, &self.r, &mut self.z),
            #[cfg(not(feature = "direct-solver"))]
            Precond::Unused(_) => {
                let _ = free;
                unreachable!("no factor without the direct-solver feature")
            }
        }
    }
}

/// The Newton matrix could not be made positive definite even with every compressed spring's
/// negative stiffness dropped (a force term with an indefinite Jacobian of its own).
#[derive(Debug, Clone, Copy)]
pub(super) struct Indefinite;

/// Fills `jac` at (x, v), prepares A for step `h` and solves A dv = b: exact Jacobian first,
/// then more and more clamped (see [`CLAMPS`]) while CG meets non-positive curvature.
/// `rhs(jac, b)` writes the right-hand side for the Jacobian as filled (it may depend on it).
/// A solve that runs out of CG iterations leaves its partial solution (the caller's residual
/// check decides). Returns the CG iterations spent.
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_clamped(
    cg: &mut Cg,
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
    let mut spent = 0u64;
    for (attempt, &clamp) in CLAMPS.iter().enumerate() {
        jac.clamp = clamp;
        sys.jacobian(x, v, jac);
        jac.prepare_newton(&sys.mass, &sys.free, h);
        rhs(jac, b);
        match cg.solve(
            jac,
            sys,
            b,
            dv,
            set,
            Precond::BlockJacobi,
            set.max_cg,
            abs_tol2,
        ) {
            CgOutcome::Converged(it) => return Ok(spent + it as u64),
            CgOutcome::NotConverged(it) => return Ok(spent + it as u64),
            CgOutcome::NegativeCurvature(it) if attempt + 1 < CLAMPS.len() => spent += it as u64,
            CgOutcome::NegativeCurvature(_) => break,
        }
    }
    Err(Indefinite)
}
