//! Backward (implicit) Euler on the full nonlinear system, solved for the new velocity by
//! Newton's method with the analytic spring, damper and drag Jacobians (Baraff & Witkin,
//! "Large steps in cloth simulation", SIGGRAPH 1998, without their one-iteration shortcut).
//!
//! Each Newton iteration solves (M - h ∂f/∂v - h² ∂f/∂x) Δv = -G(v') with conjugate gradients,
//! preconditioned by the inverse 3×3 diagonal blocks (block Jacobi), matrix-free: cost per CG
//! iteration is linear in particles + springs. If CG meets non-positive curvature (a compressed
//! spring makes the exact Jacobian indefinite) the iteration is redone with the definite
//! (transverse-clamped) Jacobian, which still converges to the same root.
//! Order 1; A-stable and L-stable: on an undamped oscillator the amplitude shrinks by
//! 1/√(1 + (hω)²) per step, for every h.

use super::{ensure_len, Integrator, StepStats};
use crate::error::{Error, Result};
use crate::model::{Jacobian, State, System, Vec3};
use nalgebra::Matrix3;

/// Settings and counters of the implicit solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplicitSettings {
    /// Newton iterations before giving up.
    pub max_newton: usize,
    /// Newton stops when max |M⁻¹ G| ≤ `newton_tol` × the velocity scale, or when an update
    /// is below `newton_tol` × |v| plus the round-off floor 16ε·max|x|/h.
    pub newton_tol: f64,
    /// Newton also stops when the residual is below `stall_tol` × the velocity scale and fell
    /// by less than 10 % in the last iteration (counted in `stalled_steps`).
    pub stall_tol: f64,
    /// CG stops at this relative residual (preconditioned norm).
    pub cg_tol: f64,
    /// CG iterations before giving up on one linear solve.
    pub max_cg: usize,
}

impl Default for ImplicitSettings {
    fn default() -> Self {
        ImplicitSettings {
            max_newton: 50,
            newton_tol: 1e-10,
            stall_tol: 1e-5,
            cg_tol: 1e-8,
            max_cg: 2000,
        }
    }
}

/// Backward Euler with Newton + block-Jacobi-preconditioned CG.
#[derive(Debug, Default)]
pub struct ImplicitEuler {
    /// Solver settings.
    pub settings: ImplicitSettings,
    /// Total Newton iterations so far (for cost reports).
    pub newton_iterations: u64,
    /// Total CG iterations so far (for cost reports).
    pub cg_iterations: u64,
    /// Steps accepted on Newton stagnation below `stall_tol` rather than full convergence.
    pub stalled_steps: u64,
    jac: Option<Jacobian>,
    f: Vec<Vec3>,
    xn: Vec<Vec3>,
    vn: Vec<Vec3>,
    r: Vec<Vec3>,
    dv: Vec<Vec3>,
    floor: Vec<f64>,
    cg: Cg,
}

/// Rounding floor of the Newton residual, as a multiple of ε·h/m·Σ k(|x_i| + |x_j| + l0): a
/// residual below it is the rounding error of the force evaluation itself and cannot shrink.
const ROUNDING_FLOOR: f64 = 8.0 * f64::EPSILON;

#[derive(Debug, Default)]
struct Cg {
    diag_inv: Vec<Matrix3<f64>>,
    r: Vec<Vec3>,
    z: Vec<Vec3>,
    p: Vec<Vec3>,
    ap: Vec<Vec3>,
}

enum CgOutcome {
    Converged(usize),
    NegativeCurvature,
    NotConverged,
}

impl Cg {
    /// Solves A x = b for the Newton matrix of `jac`; x starts at zero.
    fn solve(
        &mut self,
        jac: &Jacobian,
        sys: &System,
        b: &[Vec3],
        x: &mut [Vec3],
        set: &ImplicitSettings,
    ) -> CgOutcome {
        let n = b.len();
        for buf in [&mut self.r, &mut self.z, &mut self.p, &mut self.ap] {
            ensure_len(buf, n);
        }
        ensure_len(&mut self.diag_inv, n);
        jac.newton_diagonal(&sys.free, &mut self.diag_inv);
        for d in self.diag_inv.iter_mut() {
            *d = d.try_inverse().unwrap_or_else(Matrix3::identity);
        }
        for i in 0..n {
            x[i] = Vec3::zeros();
            self.r[i] = if sys.free[i] { b[i] } else { Vec3::zeros() };
            self.z[i] = self.diag_inv[i] * self.r[i];
            self.p[i] = self.z[i];
        }
        let mut rz: f64 = self.r.iter().zip(&self.z).map(|(a, b)| a.dot(b)).sum();
        let rz0 = rz;
        if rz0 == 0.0 {
            return CgOutcome::Converged(0);
        }
        for it in 0..set.max_cg {
            jac.newton_matvec(&sys.free, &self.p, &mut self.ap);
            for i in 0..n {
                if !sys.free[i] {
                    self.ap[i] = Vec3::zeros();
                }
            }
            let pap: f64 = self.p.iter().zip(&self.ap).map(|(a, b)| a.dot(b)).sum();
            if pap <= 0.0 || !pap.is_finite() {
                return CgOutcome::NegativeCurvature;
            }
            let alpha = rz / pap;
            for i in 0..n {
                x[i] += self.p[i] * alpha;
                self.r[i] -= self.ap[i] * alpha;
                self.z[i] = self.diag_inv[i] * self.r[i];
            }
            let rz_new: f64 = self.r.iter().zip(&self.z).map(|(a, b)| a.dot(b)).sum();
            if rz_new <= set.cg_tol * set.cg_tol * rz0 {
                return CgOutcome::Converged(it + 1);
            }
            let beta = rz_new / rz;
            rz = rz_new;
            for i in 0..n {
                self.p[i] = self.z[i] + self.p[i] * beta;
            }
        }
        CgOutcome::NotConverged
    }
}

fn max_abs(v: &[Vec3]) -> f64 {
    v.iter().map(|c| c.amax()).fold(0.0, f64::max)
}

impl Integrator for ImplicitEuler {
    fn name(&self) -> &str {
        "implicit_euler"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        for buf in [
            &mut self.f,
            &mut self.xn,
            &mut self.vn,
            &mut self.r,
            &mut self.dv,
        ] {
            ensure_len(buf, n);
        }
        ensure_len(&mut self.floor, n);
        let mut jac = match self.jac.take() {
            Some(j) if j.diag_x.len() == n && j.pairs.len() == sys.springs.len() => j,
            _ => sys.new_jacobian(),
        };
        self.vn.copy_from_slice(&s.v);
        let mut evals = 0u64;
        let v_scale0 = max_abs(&s.v);
        // Errors are built only on failure: a step must not allocate.
        let mut result: std::result::Result<f64, bool> = Err(false); // Err(true): non-finite
                                                                     // Round-off floor: positions carry ε|x| absolute error, i.e. ε|x|/h in velocity.
        let x_floor = 16.0 * f64::EPSILON * max_abs(&s.x) / h;
        let mut small_update = false;
        let mut prev_res = f64::INFINITY;
        for iter in 0..=self.settings.max_newton {
            for p in 0..n {
                self.xn[p] = s.x[p] + self.vn[p] * h;
            }
            let power = sys.forces(&self.xn, &self.vn, &mut self.f);
            evals += 1;
            self.floor.iter_mut().for_each(|r| *r = 0.0);
            sys.springs.add_rounding_scale(&self.xn, &mut self.floor);
            // G(v') = M (v' - v) - h f(x + h v', v'); scaled residual M⁻¹G has units of velocity,
            // counted only above the rounding floor of the force evaluation at that particle.
            let mut res = 0.0f64;
            let mut scale = v_scale0.max(max_abs(&self.vn));
            for p in 0..n {
                if sys.free[p] {
                    self.r[p] = (self.vn[p] - s.v[p]) * sys.mass[p] - self.f[p] * h;
                    let noise = ROUNDING_FLOOR * h * sys.inv_mass[p] * self.floor[p];
                    res = res.max((self.r[p] * sys.inv_mass[p]).amax() - noise);
                    scale = scale.max((self.f[p] * (h * sys.inv_mass[p])).amax());
                } else {
                    self.r[p] = Vec3::zeros();
                }
            }
            if !res.is_finite() {
                result = Err(true);
                break;
            }
            // Stagnation below `stall_tol` (a residual far under backward Euler's own O(h)
            // error, typically where a folding cloth makes the clamped Hessian a poor model):
            // accept, and count it so the cost report can say so.
            let stalled = res <= self.settings.stall_tol * scale && res > 0.9 * prev_res;
            if stalled {
                self.stalled_steps += 1;
            }
            prev_res = res;
            if res <= self.settings.newton_tol * scale || scale == 0.0 || small_update || stalled {
                result = Ok(power);
                break;
            }
            if iter == self.settings.max_newton {
                break;
            }
            self.newton_iterations += 1;
            for p in 0..n {
                self.r[p] = -self.r[p];
            }
            let mut definite = false;
            loop {
                jac.definite = definite;
                sys.jacobian(&self.xn, &self.vn, &mut jac);
                jac.prepare_newton(&sys.mass, &sys.free, h);
                match self
                    .cg
                    .solve(&jac, sys, &self.r, &mut self.dv, &self.settings)
                {
                    CgOutcome::Converged(it) => {
                        self.cg_iterations += it as u64;
                        break;
                    }
                    CgOutcome::NegativeCurvature if !definite => definite = true,
                    CgOutcome::NotConverged => {
                        self.cg_iterations += self.settings.max_cg as u64;
                        break; // use the partial solve: Newton's residual check decides
                    }
                    CgOutcome::NegativeCurvature => {
                        return Err(Error::Step("implicit_euler: Newton matrix is not positive definite even after clamping".into()));
                    }
                }
            }
            for p in 0..n {
                self.vn[p] += self.dv[p];
            }
            // Converged when the update is below the tolerance or the round-off floor; one more
            // force evaluation at the final iterate follows (for the dissipated power).
            small_update = max_abs(&self.dv)
                <= self.settings.newton_tol * v_scale0.max(max_abs(&self.vn)) + x_floor;
        }
        self.jac = Some(jac);
        let power = result.map_err(|non_finite| {
            Error::Step(if non_finite {
                "implicit_euler: non-finite residual in Newton iteration".into()
            } else {
                format!(
                    "implicit_euler: Newton did not converge in {} iterations",
                    self.settings.max_newton
                )
            })
        })?;
        s.v.copy_from_slice(&self.vn);
        s.x.copy_from_slice(&self.xn);
        s.t += h;
        Ok(StepStats {
            force_evals: evals,
            dissipated: power * h,
        })
    }
}
