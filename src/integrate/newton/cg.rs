//! The linear-solve half of the shared implicit core: conjugate gradients on the Newton matrix
//! A = M − h ∂f/∂v − h² ∂f/∂x, matrix-free (one product is one pass over particles and
//! springs), preconditioned by a block IC(0) factor of the clamped matrix (`ic0.rs`) or by
//! A's inverse 3×3 diagonal blocks (block Jacobi).
//!
//! A compressed spring can make the exact matrix indefinite; [`solve_shifted`] then redoes the
//! solve with the mass term raised past the curvature CG met (the Levenberg–Marquardt shift,
//! `shift.rs`), until the matrix is positive definite; [`solve_clamped`], the linearly
//! implicit method's solve, drops more and more of the compressed springs' negative stiffness
//! instead (50 %, 87.5 %, 100 %: the last is SPD). Large systems run the products and vector updates in
//! parallel over fixed chunks, and dot products sum fixed chunk partials in order, so results
//! are bit-identical for any thread count.

#[cfg(feature = "direct-solver")]
use super::direct::Factor;
use super::ic0::Ic0;
use super::linsolve::LinearProblem;
use super::shift::{raised, MAX_SHIFTS};
use super::translation::translation_invariant;
use crate::integrate::ensure_len;
use crate::model::parallel::{
    dot, each_particle, each_particle2, each_particle2_sum, each_particle3_sum2, each_particle_sum,
};
use crate::model::{Jacobian, System, Vec3};
use nalgebra::Matrix3;

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
    /// Applications of a factored preconditioner (IC(0) or a Cholesky factor) so far.
    pub(super) factor_solves: u64,
    /// The mass-relative curvature pᵀAp / pᵀMp of the direction on which the last solve met
    /// non-positive curvature (−∞ where the product was not finite).
    pub(super) curvature: f64,
}

/// The preconditioner of one CG solve.
pub(super) enum Precond<'a> {
    /// The inverse 3×3 diagonal blocks of the matrix itself.
    BlockJacobi,
    /// A sparse Cholesky factor of a nearby SPD matrix (the clamped Newton matrix, possibly
    /// of an earlier iterate or step).
    #[cfg(feature = "direct-solver")]
    Factor(&'a mut Factor),
    /// A block incomplete Cholesky factor IC(0) of a nearby SPD matrix (the clamped Newton
    /// matrix at the same iterate).
    Ic0(&'a Ic0),
}

/// When one CG solve stops: the iteration cap, the relative tolerance on the preconditioned
/// residual rᵀz, and the absolute one on Σ |rᵢ|²/mᵢ (the inexact-Newton forcing; 0 for none).
/// Each caller sets the three together, from the settings and the Newton loop's forcing.
#[derive(Debug, Clone, Copy)]
pub(super) struct CgStop {
    /// Most iterations.
    pub(super) max_it: usize,
    /// Stop once rᵀz ≤ `rel_tol`² × its start value.
    pub(super) rel_tol: f64,
    /// Stop once Σ |rᵢ|²/mᵢ ≤ `abs_tol2` (0: never).
    pub(super) abs_tol2: f64,
}

/// How one CG solve ended (with its iteration count).
pub(super) enum CgOutcome {
    Converged(usize),
    NegativeCurvature(usize),
    NotConverged(usize),
}

impl Cg {
    /// Solves A x = b for the Newton matrix prepared in `jac` by CG preconditioned with
    /// `pre`, at most `stop.max_it` iterations; x starts at zero, or on a translation-invariant
    /// system at its exact translation part (see [`Cg::deflate`]). Stops at the relative
    /// tolerance `stop.rel_tol` or when the residual's Σ |rᵢ|²/mᵢ falls to `stop.abs_tol2`;
    /// on non-positive curvature it stops with [`CgOutcome::NegativeCurvature`], the
    /// curvature met in [`Cg::curvature`].
    pub(super) fn solve(
        &mut self,
        jac: &Jacobian,
        sys: &System,
        b: &[Vec3],
        x: &mut [Vec3],
        mut pre: Precond<'_>,
        stop: CgStop,
    ) -> CgOutcome {
        let CgStop {
            max_it,
            rel_tol,
            abs_tol2,
        } = stop;
        let n = b.len();
        for buf in [&mut self.r, &mut self.z, &mut self.p, &mut self.ap] {
            ensure_len(buf, n);
        }
        if matches!(pre, Precond::BlockJacobi) {
            ensure_len(&mut self.diag_inv, n);
            jac.newton_diagonal(&sys.free, &mut self.diag_inv);
            let mass = &sys.mass;
            each_particle(&mut self.diag_inv, |i, d| {
                *d = spd_block_inverse(d, mass[i])
            });
        }
        let free = &sys.free;
        each_particle2(x, &mut self.r, |i, xi, ri| {
            *xi = Vec3::zeros();
            *ri = if free[i] { b[i] } else { Vec3::zeros() };
        });
        // Deflation of the translations.
        let deflate = translation_invariant(sys).then(|| sys.mass.iter().sum::<f64>());
        if let Some(total) = deflate {
            // x₀ = Z (ZᵀAZ)⁻¹ Zᵀb: the uniform c = Σb / Σm, since A Z = M Z.
            let c = self.r.iter().sum::<Vec3>() / total;
            let mass = &sys.mass;
            each_particle2(x, &mut self.r, |i, xi, ri| {
                *xi = c;
                *ri -= c * mass[i];
            });
        }
        let mut rz = self.precondition_dot(&mut pre, free, deflate, &sys.mass);
        self.p.copy_from_slice(&self.z);
        let rz0 = rz;
        if rz0 == 0.0 {
            return CgOutcome::Converged(0);
        }
        // The last iteration's β: its p = z + βp is applied in the next product's pass.
        let mut beta = None;
        for it in 0..max_it {
            let z = &self.z;
            jac.newton_matvec_updated(free, &mut self.p, &mut self.ap, |i, pi| {
                if let Some(beta) = beta {
                    *pi = z[i] + *pi * beta;
                }
            });
            // Fixed rows dropped and pᵀAp in one pass.
            let p = &self.p;
            let pap = each_particle_sum(&mut self.ap, &mut self.parts, |i, a| {
                if !free[i] {
                    *a = Vec3::zeros();
                }
                p[i].dot(a)
            });
            if !pap.is_finite() || pap <= 0.0 {
                let (p, mass) = (&self.p, &sys.mass);
                let pmp: f64 = (0..n)
                    .filter(|&i| free[i])
                    .map(|i| mass[i] * p[i].norm_squared())
                    .sum();
                self.curvature = if pap.is_finite() && pmp > 0.0 {
                    pap / pmp
                } else {
                    f64::NEG_INFINITY
                };
                return CgOutcome::NegativeCurvature(it);
            }
            let alpha = rz / pap;
            let (p, ap, im) = (&self.p, &self.ap, &sys.inv_mass);
            let rz_new = if pointwise(&pre, deflate) {
                // The update, the forcing test's Σ |rᵢ|²/mᵢ, block Jacobi and rᵀz in one pass.
                let d = &self.diag_inv;
                let (rmr, rz_new) = each_particle3_sum2(
                    x,
                    &mut self.r,
                    &mut self.z,
                    &mut self.parts,
                    |i, xi, ri, zi| {
                        *xi += p[i] * alpha;
                        *ri -= ap[i] * alpha;
                        *zi = d[i] * *ri;
                        (ri.dot(&(*ri * im[i])), ri.dot(zi))
                    },
                );
                if abs_tol2 > 0.0 && rmr <= abs_tol2 {
                    return CgOutcome::Converged(it + 1);
                }
                rz_new
            } else {
                // The update and the forcing test's Σ |rᵢ|²/mᵢ in one pass.
                let rmr = each_particle2_sum(x, &mut self.r, &mut self.parts, |i, xi, ri| {
                    *xi += p[i] * alpha;
                    *ri -= ap[i] * alpha;
                    ri.dot(&(*ri * im[i]))
                });
                if abs_tol2 > 0.0 && rmr <= abs_tol2 {
                    return CgOutcome::Converged(it + 1);
                }
                self.precondition_dot(&mut pre, free, deflate, &sys.mass)
            };
            if rz_new <= rel_tol * rel_tol * rz0 {
                return CgOutcome::Converged(it + 1);
            }
            beta = Some(rz_new / rz);
            rz = rz_new;
        }
        CgOutcome::NotConverged(max_it)
    }

    /// Deflated CG (Nicolaides, SIAM J. Numer. Anal. 24, 1987; Saad, Yeung, Erhel &
    /// Guyomarc'h, SIAM J. Sci. Comput. 21, 2000, Alg. 2.1) with the rigid translations Z as
    /// the deflation space, on a translation-invariant system (`momentum.rs`), where A Z = M Z:
    /// z −= Z (ZᵀAZ)⁻¹ ZᵀA z, i.e. minus its mass-weighted mean, so that every search direction
    /// is A-orthogonal to the translations and the residual keeps Σ r = 0 (the start solves the
    /// translation part exactly). Block Jacobi sees the translations as P⁻¹A-eigenvalues near
    /// m/(m + h²k), tiny at hω ≫ 1, and would leave them (the momentum balance) for last.
    /// `total`: Σm, `None` for no deflation.
    fn deflate(&mut self, total: Option<f64>, mass: &[f64]) {
        if let Some(total) = total {
            let mean = (0..self.z.len()).map(|i| self.z[i] * mass[i]).sum::<Vec3>() / total;
            each_particle(&mut self.z, |_, zi| *zi -= mean);
        }
    }

    /// z = P⁻¹ r, deflated (`total`: Σm, or `None`), and returns rᵀz; block Jacobi without
    /// deflation in one pass.
    fn precondition_dot(
        &mut self,
        pre: &mut Precond<'_>,
        free: &[bool],
        total: Option<f64>,
        mass: &[f64],
    ) -> f64 {
        if pointwise(pre, total) {
            let (r, d) = (&self.r, &self.diag_inv);
            return each_particle_sum(&mut self.z, &mut self.parts, |i, zi| {
                *zi = d[i] * r[i];
                r[i].dot(zi)
            });
        }
        self.precondition(pre, free);
        self.deflate(total, mass);
        dot(&self.r, &self.z, &mut self.parts)
    }

    /// z = P⁻¹ r.
    fn precondition(&mut self, pre: &mut Precond<'_>, free: &[bool]) {
        match pre {
            Precond::BlockJacobi => {
                let (r, d) = (&self.r, &self.diag_inv);
                each_particle(&mut self.z, |i, zi| *zi = d[i] * r[i]);
            }
            #[cfg(feature = "direct-solver")]
            Precond::Factor(f) => {
                self.factor_solves += 1;
                f.solve(free, &self.r, &mut self.z)
            }
            Precond::Ic0(f) => {
                self.factor_solves += 1;
                f.solve(free, &self.r, &mut self.z)
            }
        }
    }
}

/// Whether preconditioning acts particle by particle, so that it can share a pass with the
/// update before it: block Jacobi without deflation (`total`: Σm, or `None`).
fn pointwise(pre: &Precond<'_>, total: Option<f64>) -> bool {
    total.is_none() && matches!(pre, Precond::BlockJacobi)
}

/// The inverse of a diagonal block `d` of the Newton matrix, made SPD for preconditioning: a
/// block whose eigenvalues all exceed half the particle's mass `m` is inverted as is; one
/// that does not (compressed springs' negative stiffness) has its eigenvalues raised to `m`,
/// the mass term's own floor, before inverting. A near-singular block would otherwise give
/// a preconditioner that is not positive definite, on which CG has no convergence theory.
fn spd_block_inverse(d: &Matrix3<f64>, m: f64) -> Matrix3<f64> {
    if (d - Matrix3::identity() * (0.5 * m)).cholesky().is_some() {
        return d.try_inverse().unwrap_or_else(Matrix3::identity);
    }
    let e = ((d + d.transpose()) * 0.5).symmetric_eigen();
    let inv = e.eigenvalues.map(|l| {
        let l = l.max(m);
        if l > 0.0 {
            1.0 / l
        } else {
            1.0
        }
    });
    e.eigenvectors * Matrix3::from_diagonal(&inv) * e.eigenvectors.transpose()
}

/// Fractions of compressed springs' indefinite stiffness dropped in successive attempts at
/// one linearly implicit solve (see [`Jacobian::clamp`]).
pub(super) const CLAMPS: [f64; 4] = [0.0, 0.5, 0.875, 1.0];

/// Factors by block IC(0) the fully clamped (SPD) Newton matrix at `prob`'s (x, v), with
/// `jac`'s shift: the preconditioner of the attempts that follow. Leaves `jac` filled clamped.
fn factor_clamped(f: &mut Ic0, jac: &mut Jacobian, prob: &LinearProblem<'_>) {
    let LinearProblem { sys, x, v, h, .. } = *prob;
    sys.newton_matrix(x, v, h, 1.0, jac);
    f.factor(jac, &sys.free);
}

/// The preconditioner of an attempt: the IC(0) factor if there is one, else block Jacobi.
fn precond(ic0: Option<&Ic0>) -> Precond<'_> {
    match ic0 {
        Some(f) => Precond::Ic0(f),
        None => Precond::BlockJacobi,
    }
}

/// The Newton matrix could not be made positive definite even with every compressed spring's
/// negative stiffness dropped (a force term with an indefinite Jacobian of its own).
#[derive(Debug, Clone, Copy)]
pub(super) struct Indefinite;

/// Fills `jac` at `prob`'s (x, v), prepares A for its step h and solves A dv = b: exact
/// Jacobian first, then more and more clamped (see [`CLAMPS`]) while CG meets non-positive
/// curvature. `rhs(jac, b)` writes the right-hand side for the Jacobian as filled (it may
/// depend on it). A solve that runs out of CG iterations leaves its partial solution (the
/// caller's residual check decides). Returns the CG iterations spent. The linearly implicit
/// method's solve: its matrix is the method, and dropping compressed springs' transverse
/// stiffness is Baraff & Witkin's practice (Choi & Ko, SIGGRAPH 2002, §5). With `ic0` =
/// Some(factor), the clamped (SPD) matrix at (x, v) is factored by block IC(0) first, and
/// that factor preconditions every attempt instead of block Jacobi.
pub(super) fn solve_clamped(
    cg: &mut Cg,
    mut ic0: Option<&mut Ic0>,
    jac: &mut Jacobian,
    prob: &LinearProblem<'_>,
    mut rhs: impl FnMut(&Jacobian, &mut [Vec3]),
    b: &mut [Vec3],
    dv: &mut [Vec3],
) -> Result<u64, Indefinite> {
    let LinearProblem { sys, x, v, h, .. } = *prob;
    let mut spent = 0u64;
    jac.shift = 0.0;
    if let Some(f) = ic0.as_deref_mut() {
        factor_clamped(f, jac, prob);
    }
    for (attempt, &clamp) in CLAMPS.iter().enumerate() {
        sys.newton_matrix(x, v, h, clamp, jac);
        rhs(jac, b);
        let pre = precond(ic0.as_deref());
        match cg.solve(jac, sys, b, dv, pre, prob.cg_stop(prob.set.max_cg)) {
            CgOutcome::Converged(it) | CgOutcome::NotConverged(it) => return Ok(spent + it as u64),
            CgOutcome::NegativeCurvature(it) if attempt + 1 < CLAMPS.len() => spent += it as u64,
            CgOutcome::NegativeCurvature(_) => break,
        }
    }
    Err(Indefinite)
}

/// Fills `jac` at `prob`'s (x, v) and solves A dv = b for the Newton matrix A at its step h
/// with the Levenberg–Marquardt shift `jac.shift` (`shift.rs`), raising the shift past the
/// curvature CG meets until A is positive definite; the shift used stays in `jac.shift`.
/// `rhs(jac, b)` writes the right-hand side for the Jacobian as filled (it may depend on it).
/// A solve that runs out of CG iterations leaves its partial solution (the caller's residual
/// check decides). Returns the CG iterations spent. With `ic0` = Some(factor), the clamped
/// (SPD) matrix at (x, v), with the same shift, is factored by block IC(0) first, and that
/// factor preconditions every attempt instead of block Jacobi.
pub(super) fn solve_shifted(
    cg: &mut Cg,
    mut ic0: Option<&mut Ic0>,
    jac: &mut Jacobian,
    prob: &LinearProblem<'_>,
    mut rhs: impl FnMut(&Jacobian, &mut [Vec3]),
    b: &mut [Vec3],
    dv: &mut [Vec3],
) -> Result<u64, Indefinite> {
    let LinearProblem { sys, x, v, h, .. } = *prob;
    let mut spent = 0u64;
    for attempt in 0..MAX_SHIFTS {
        if let Some(f) = ic0.as_deref_mut() {
            factor_clamped(f, jac, prob);
        }
        // The exact Jacobian (the shift enters only the prepared mass blocks).
        if attempt == 0 || ic0.is_some() {
            jac.clamp = 0.0;
            sys.jacobian(x, v, jac);
        }
        jac.prepare_newton(&sys.mass, &sys.free, h);
        rhs(jac, b);
        let pre = precond(ic0.as_deref());
        match cg.solve(jac, sys, b, dv, pre, prob.cg_stop(prob.set.max_cg)) {
            CgOutcome::Converged(it) | CgOutcome::NotConverged(it) => return Ok(spent + it as u64),
            CgOutcome::NegativeCurvature(it) => {
                spent += it as u64;
                if !cg.curvature.is_finite() {
                    break;
                }
                jac.shift = raised(jac.shift, cg.curvature);
            }
        }
    }
    Err(Indefinite)
}

#[cfg(test)]
pub(super) mod tests {
    //! Oracles: the Newton matrix assembled densely, column by column, from the matrix-free
    //! product CG uses; nalgebra's dense Cholesky solve and eigenvalues of it; the quadratic
    //! model −bᵀs + ½ sᵀAs evaluated directly; the P-norm from the preconditioner's blocks.
    use super::*;
    use crate::integrate::newton::settings::ImplicitSettings;
    use nalgebra::{DMatrix, DVector};

    /// A crumpled 5×5 cloth (compressed springs), its Newton matrix at step `h` with `clamp`,
    /// the dense matrix on the free coordinates and those coordinates.
    pub(in crate::integrate::newton) fn crumpled(
        h: f64,
        clamp: f64,
    ) -> (System, Jacobian, DMatrix<f64>, Vec<usize>) {
        let sys = crumpled_scene().build();
        let x = crumpled_state();
        let mut jac = sys.new_jacobian();
        sys.newton_matrix(&x, &vec![Vec3::zeros(); x.len()], h, clamp, &mut jac);
        let dofs: Vec<usize> = (0..3 * sys.len()).filter(|&d| sys.free[d / 3]).collect();
        let dense = dense_newton(&jac, &sys.free, &dofs);
        (sys, jac, dense, dofs)
    }

    /// The crumpled cloth's positions: the 5×5 cloth's initial state squeezed to 60 % along
    /// x and rumpled by ±10 cm along z.
    fn crumpled_state() -> Vec<Vec3> {
        let mut x = crumpled_scene().initial_state().x;
        for (p, x) in x.iter_mut().enumerate() {
            x[2] += 0.05 * ((p * 7 % 5) as f64 - 2.0);
            x[0] *= 0.6;
        }
        x
    }

    fn crumpled_scene() -> crate::scenario::Scenario {
        crate::scenario::Scenario::from_toml_str(
            "[world]\ngravity=[0.0,-9.81,0.0]\n[[cloth]]\norigin=[0.0,0.0,0.0]\nsize=[1.0,1.0]\n\
             count=[5,5]\nmass=0.001\nstiffness=200.0\ndamping=0.002\nfix=[\"top_left\",\"top_right\"]\n",
            "cloth.toml",
        )
        .unwrap()
    }

    /// The Newton matrix prepared in `jac` on the coordinates `dofs`, assembled densely column
    /// by column from the matrix-free product CG uses.
    pub(in crate::integrate::newton) fn dense_newton(
        jac: &Jacobian,
        free: &[bool],
        dofs: &[usize],
    ) -> DMatrix<f64> {
        let n = free.len();
        let mut dense = DMatrix::zeros(dofs.len(), dofs.len());
        let (mut e, mut col) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
        for (j, &dj) in dofs.iter().enumerate() {
            e.iter_mut().for_each(|v| *v = Vec3::zeros());
            e[dj / 3][dj % 3] = 1.0;
            jac.newton_matvec(free, &e, &mut col);
            for (i, &di) in dofs.iter().enumerate() {
                dense[(i, j)] = col[di / 3][di % 3];
            }
        }
        dense
    }

    fn rhs(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|p| Vec3::new((p as f64).sin(), (p as f64 * 0.7).cos(), 0.3))
            .map(|v| v * 1e-3)
            .collect()
    }

    /// The field `v` on the coordinates `dofs`, as one vector.
    pub(in crate::integrate::newton) fn flat(v: &[Vec3], dofs: &[usize]) -> DVector<f64> {
        DVector::from_iterator(dofs.len(), dofs.iter().map(|&d| v[d / 3][d % 3]))
    }

    fn set() -> ImplicitSettings {
        ImplicitSettings {
            cg_tol: 1e-14,
            ..ImplicitSettings::default()
        }
    }

    /// Positive definite matrix (compressed springs clamped): CG's solution is the dense
    /// Cholesky solve's.
    #[test]
    fn cg_on_a_positive_definite_matrix_is_the_dense_solve() {
        let (sys, jac, dense, dofs) = crumpled(1.0 / 60.0, 1.0);
        let b = rhs(sys.len());
        let want = dense
            .cholesky()
            .expect("clamped matrix is SPD")
            .solve(&flat(&b, &dofs));
        let mut x = vec![Vec3::zeros(); b.len()];
        let stop = CgStop {
            max_it: 500,
            rel_tol: set().cg_tol,
            abs_tol2: 0.0,
        };
        let out = Cg::default().solve(&jac, &sys, &b, &mut x, Precond::BlockJacobi, stop);
        assert!(matches!(out, CgOutcome::Converged(_)));
        assert!((flat(&x, &dofs) - &want).amax() <= 1e-9 * want.amax());
    }

    /// Indefinite matrix (the exact Jacobian of compressed springs at a long step): the
    /// curvature CG reports is a Rayleigh quotient pᵀAp/pᵀMp, so it lies between the lowest
    /// and highest eigenvalues of M⁻¹A (computed densely); the shifted solve ends on a shift
    /// that makes A + μM positive definite, and its step is the dense solve of that matrix.
    #[test]
    fn an_indefinite_matrix_is_shifted_until_positive_definite() {
        let h = 0.2;
        let (sys, _, dense, dofs) = crumpled(h, 0.0);
        let mass =
            nalgebra::DVector::from_iterator(dofs.len(), dofs.iter().map(|&d| sys.mass[d / 3]));
        let inv_sqrt_m = mass.map(|m| 1.0 / m.sqrt());
        let scaled = DMatrix::from_fn(dofs.len(), dofs.len(), |i, j| {
            dense[(i, j)] * inv_sqrt_m[i] * inv_sqrt_m[j]
        });
        let eig = scaled.symmetric_eigen().eigenvalues;
        assert!(
            eig.min() < 0.0,
            "the test needs an indefinite matrix: {}",
            eig.min()
        );
        let b = rhs(sys.len());
        let mut jac = sys.new_jacobian();
        let mut cg = Cg::default();
        let mut x = vec![Vec3::zeros(); b.len()];
        let state = crumpled_state();
        let mut bb = b.clone();
        let v = vec![Vec3::zeros(); b.len()];
        let prob = LinearProblem {
            sys: &sys,
            x: &state,
            v: &v,
            h,
            set: &set(),
            abs_tol2: 0.0,
        };
        solve_shifted(&mut cg, None, &mut jac, &prob, |_, _| {}, &mut bb, &mut x)
            .expect("a shift makes it positive definite");
        assert!(cg.curvature <= 0.0 && cg.curvature >= eig.min() - 1e-9 * eig.amax());
        let mu = jac.shift;
        assert!(
            mu > -eig.min(),
            "shift {mu} must pass the lowest curvature {}",
            eig.min()
        );
        let shifted = &dense + DMatrix::from_diagonal(&(mass * mu));
        let want = shifted
            .cholesky()
            .expect("the shifted matrix is SPD")
            .solve(&flat(&b, &dofs));
        assert!((flat(&x, &dofs) - &want).amax() <= 1e-8 * want.amax());
    }
}
