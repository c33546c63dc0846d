//! The linear-solve half of the shared implicit core: conjugate gradients on the Newton matrix
//! A = M − h ∂f/∂v − h² ∂f/∂x, matrix-free (one product is one pass over particles and
//! springs), preconditioned by a block IC(0) factor of the clamped matrix (`ic0.rs`) or by
//! A's inverse 3×3 diagonal blocks (block Jacobi).
//!
//! A compressed spring makes the exact Jacobian indefinite; [`solve_clamped`] then redoes the
//! solve with more and more of the compressed springs' negative stiffness dropped (50 %,
//! 87.5 %, 100 %: the last is SPD). Large systems run the products and vector updates in
//! parallel over fixed chunks, and dot products sum fixed chunk partials in order, so results
//! are bit-identical for any thread count.

#[cfg(feature = "direct-solver")]
use super::direct::Factor;
use super::ic0::Ic0;
use super::settings::ImplicitSettings;
use super::translation::translation_invariant;
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
    /// The quadratic model's value m(s) = −bᵀs + ½ sᵀAs at the returned step (its predicted
    /// change of the incremental potential).
    pub(super) model: f64,
    /// The returned step's P-norm √(sᵀPs).
    pub(super) step_norm: f64,
    /// Trust-region solves: the radius used (set to max(‖s‖_P, √(bᵀP⁻¹b)) on the first
    /// negative curvature of a solve called with an infinite radius).
    pub(super) radius: f64,
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

/// How one CG solve ended (with its iteration count).
pub(super) enum CgOutcome {
    Converged(usize),
    NegativeCurvature(usize),
    NotConverged(usize),
    /// Trust-region solves: the step stopped on the boundary, along negative curvature or
    /// because the next iterate would leave the region (Steihaug–Toint).
    Boundary(usize),
}

impl Cg {
    /// Solves A x = b for the Newton matrix prepared in `jac` by CG preconditioned with
    /// `pre`, at most `max_it` iterations; x starts at zero, or on a translation-invariant
    /// system at its exact translation part (see [`Cg::deflate`]; [`Cg::model`] and
    /// [`Cg::step_norm`] then leave that part out). Stops at the relative tolerance
    /// [`ImplicitSettings::cg_tol`] or when the residual's Σ |rᵢ|²/mᵢ falls to `abs_tol2`
    /// (the inexact-Newton forcing; 0 for none).
    ///
    /// With `radius` = Some(Δ) it is Steihaug–Toint truncated CG (Nocedal & Wright Alg. 7.2)
    /// in the preconditioner's norm: on non-positive curvature, or when an iterate would leave
    /// ‖s‖_P ≤ Δ, it steps to the boundary and returns [`CgOutcome::Boundary`]; the model value
    /// and ‖s‖_P are left in [`Cg::model`], [`Cg::step_norm`]. The P-norms follow the
    /// recurrences of Conn, Gould & Toint (Trust-Region Methods, §7.5.1), with no extra vectors.
    // One function because CG's vectors, the clamping of compressed springs and the deflation of translations act within one iteration.
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
        radius: Option<f64>,
    ) -> CgOutcome {
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
        // Deflation of the translations (not in the trust region, whose norms assume x₀ = 0).
        let deflate =
            (radius.is_none() && translation_invariant(sys)).then(|| sys.mass.iter().sum::<f64>());
        if let Some(total) = deflate {
            // x₀ = Z (ZᵀAZ)⁻¹ Zᵀb: the uniform c = Σb / Σm, since A Z = M Z.
            let c = self.r.iter().sum::<Vec3>() / total;
            let mass = &sys.mass;
            each_particle2(x, &mut self.r, |i, xi, ri| {
                *xi = c;
                *ri -= c * mass[i];
            });
        }
        self.precondition(&mut pre, free);
        self.deflate(deflate, &sys.mass);
        self.p.copy_from_slice(&self.z);
        let mut rz = dot(&self.r, &self.z, &mut self.parts);
        let rz0 = rz;
        // ‖x‖²_P, xᵀPp, ‖p‖²_P, and the model value m(x), all zero-started.
        let (mut xx, mut xp, mut pp, mut model) = (0.0, 0.0, rz0, 0.0);
        self.model = 0.0;
        self.step_norm = 0.0;
        self.radius = radius.unwrap_or(f64::INFINITY);
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
            if !pap.is_finite() || (pap <= 0.0 && radius.is_none()) {
                return CgOutcome::NegativeCurvature(it);
            }
            let mut alpha = rz / pap;
            let xx_next = xx + 2.0 * alpha * xp + alpha * alpha * pp;
            if radius.is_some() && (pap <= 0.0 || xx_next >= self.radius * self.radius) {
                if self.radius == f64::INFINITY {
                    self.radius = xx.sqrt().max(rz0.sqrt());
                }
                alpha = super::trust::to_boundary(xx, xp, pp, self.radius);
                let p = &self.p;
                each_particle(x, |i, xi| *xi += p[i] * alpha);
                self.model = model - alpha * rz + 0.5 * alpha * alpha * pap;
                self.step_norm = self.radius;
                return CgOutcome::Boundary(it + 1);
            }
            xx = xx_next;
            model -= 0.5 * alpha * rz;
            self.model = model;
            self.step_norm = xx.sqrt();
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
            self.deflate(deflate, &sys.mass);
            let rz_new = dot(&self.r, &self.z, &mut self.parts);
            if rz_new <= set.cg_tol * set.cg_tol * rz0 {
                return CgOutcome::Converged(it + 1);
            }
            let beta = rz_new / rz;
            xp = beta * (xp + alpha * pp);
            pp = rz_new + beta * beta * pp;
            rz = rz_new;
            let z = &self.z;
            each_particle(&mut self.p, |i, pi| *pi = z[i] + *pi * beta);
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

    /// z = P⁻¹ r.
    fn precondition(&mut self, pre: &mut Precond<'_>, free: &[bool]) {
        match pre {
            Precond::BlockJacobi => {
                let (r, d) = (&self.r, &self.diag_inv);
                each_particle(&mut self.z, |i, zi| *zi = d[i] * r[i]);
            }
            #[cfg(feature = "direct-solver")]
            Precond::Factor(f) => f.solve(free, &self.r, &mut self.z),
            Precond::Ic0(f) => f.solve(free, &self.r, &mut self.z),
        }
    }
}

/// The inverse of a diagonal block `d` of the Newton matrix, made SPD for preconditioning: a
/// block whose eigenvalues all exceed half the particle's mass `m` is inverted as is; one
/// that does not (compressed springs' negative stiffness) has its eigenvalues raised to `m`,
/// the mass term's own floor, before inverting. A near-singular block would otherwise give
/// steps huge in max norm yet small in the preconditioner's norm, which the trust region
/// measures.
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

/// The Newton matrix could not be made positive definite even with every compressed spring's
/// negative stiffness dropped (a force term with an indefinite Jacobian of its own).
#[derive(Debug, Clone, Copy)]
pub(super) struct Indefinite;

/// Fills `jac` at (x, v), prepares A for step `h` and solves A dv = b: exact Jacobian first,
/// then more and more clamped (see [`CLAMPS`]) while CG meets non-positive curvature.
/// `rhs(jac, b)` writes the right-hand side for the Jacobian as filled (it may depend on it).
/// A solve that runs out of CG iterations leaves its partial solution (the caller's residual
/// check decides). Returns the CG iterations spent. With `radius` = Some(Δ) the exact
/// Jacobian is solved by Steihaug–Toint CG (see [`Cg::solve`]) and nothing is clamped.
/// With `ic0` = Some(factor), the clamped (SPD) matrix at (x, v) is factored by block IC(0)
/// first, and that factor preconditions every attempt instead of block Jacobi.
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_clamped(
    cg: &mut Cg,
    mut ic0: Option<&mut Ic0>,
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
    radius: Option<f64>,
) -> Result<u64, Indefinite> {
    let mut spent = 0u64;
    let clamps = if radius.is_some() {
        &CLAMPS[..1]
    } else {
        &CLAMPS[..]
    };
    if let Some(f) = ic0.as_deref_mut() {
        jac.clamp = 1.0;
        sys.jacobian(x, v, jac);
        jac.prepare_newton(&sys.mass, &sys.free, h);
        f.factor(jac, &sys.free);
    }
    for (attempt, &clamp) in clamps.iter().enumerate() {
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
            match ic0.as_deref() {
                Some(f) => Precond::Ic0(f),
                None => Precond::BlockJacobi,
            },
            set.max_cg,
            abs_tol2,
            radius,
        ) {
            CgOutcome::Converged(it) | CgOutcome::Boundary(it) => return Ok(spent + it as u64),
            CgOutcome::NotConverged(it) => return Ok(spent + it as u64),
            CgOutcome::NegativeCurvature(it) if attempt + 1 < clamps.len() => spent += it as u64,
            CgOutcome::NegativeCurvature(_) => break,
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
    use nalgebra::{DMatrix, DVector};

    /// A crumpled 5×5 cloth (compressed springs), its Newton matrix at step `h` with `clamp`,
    /// the dense matrix on the free coordinates and those coordinates.
    pub(in crate::integrate::newton) fn crumpled(
        h: f64,
        clamp: f64,
    ) -> (System, Jacobian, DMatrix<f64>, Vec<usize>) {
        let scene = crate::scenario::Scenario::from_toml_str(
            "[world]\ngravity=[0.0,-9.81,0.0]\n[[cloth]]\norigin=[0.0,0.0,0.0]\nsize=[1.0,1.0]\n\
             count=[5,5]\nmass=0.001\nstiffness=200.0\ndamping=0.002\nfix=[\"top_left\",\"top_right\"]\n",
            "cloth.toml",
        )
        .unwrap();
        let sys = scene.build();
        let mut s = scene.initial_state();
        for (p, x) in s.x.iter_mut().enumerate() {
            x[2] += 0.05 * ((p * 7 % 5) as f64 - 2.0);
            x[0] *= 0.6;
        }
        let mut jac = sys.new_jacobian();
        jac.clamp = clamp;
        sys.jacobian(&s.x, &s.v, &mut jac);
        jac.prepare_newton(&sys.mass, &sys.free, h);
        let dofs: Vec<usize> = (0..3 * sys.len()).filter(|&d| sys.free[d / 3]).collect();
        let dense = dense_newton(&jac, &sys.free, &dofs);
        (sys, jac, dense, dofs)
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

    fn solve(sys: &System, jac: &Jacobian, b: &[Vec3], radius: f64) -> (Cg, CgOutcome, Vec<Vec3>) {
        let set = ImplicitSettings {
            cg_tol: 1e-14,
            ..ImplicitSettings::default()
        };
        let mut cg = Cg::default();
        let mut x = vec![Vec3::zeros(); b.len()];
        let out = cg.solve(
            jac,
            sys,
            b,
            &mut x,
            &set,
            Precond::BlockJacobi,
            500,
            0.0,
            Some(radius),
        );
        (cg, out, x)
    }

    /// Positive definite model, radius far away: Steihaug's step is the Newton step.
    #[test]
    fn steihaug_inside_the_radius_is_the_newton_step() {
        let (sys, jac, dense, dofs) = crumpled(1.0 / 60.0, 1.0);
        let b = rhs(sys.len());
        let bd = flat(&b, &dofs);
        let want = dense
            .clone()
            .cholesky()
            .expect("clamped matrix is SPD")
            .solve(&bd);
        let (cg, out, x) = solve(&sys, &jac, &b, 1e30);
        assert!(matches!(out, CgOutcome::Converged(_)));
        let s = flat(&x, &dofs);
        assert!((&s - &want).amax() <= 1e-9 * want.amax());
        let m = -bd.dot(&s) + 0.5 * s.dot(&(&dense * &s));
        assert!(
            (cg.model - m).abs() <= 1e-9 * m.abs(),
            "{} vs {m}",
            cg.model
        );
    }

    /// Indefinite model (exact Jacobian of compressed springs at a long step): the step stops
    /// on the boundary, ‖s‖_P = Δ, and the model value reported is the model's.
    #[test]
    fn steihaug_on_negative_curvature_stops_on_the_boundary() {
        let (sys, jac, dense, dofs) = crumpled(0.2, 0.0);
        let lowest = dense.clone().symmetric_eigen().eigenvalues.min();
        assert!(
            lowest < 0.0,
            "the test needs an indefinite matrix: {lowest}"
        );
        let b = rhs(sys.len());
        let bd = flat(&b, &dofs);
        // Far beyond the Newton-step scale (|b|/m ≈ 1 m/s): only following the negative
        // curvature reaches it.
        let radius = 1e3;
        let (cg, out, x) = solve(&sys, &jac, &b, radius);
        assert!(matches!(out, CgOutcome::Boundary(_)));
        let pnorm2: f64 = (0..sys.len())
            .filter(|&p| sys.free[p])
            .map(|p| {
                let blk = cg.diag_inv[p].try_inverse().unwrap();
                x[p].dot(&(blk * x[p]))
            })
            .sum();
        assert!(
            (pnorm2.sqrt() - radius).abs() <= 1e-9 * radius,
            "{}",
            pnorm2.sqrt()
        );
        let s = flat(&x, &dofs);
        let m = -bd.dot(&s) + 0.5 * s.dot(&(&dense * &s));
        assert!(
            (cg.model - m).abs() <= 1e-9 * m.abs(),
            "{} vs {m}",
            cg.model
        );
        assert!(m < 0.0, "the boundary step must lower the model: {m}");
    }
}
