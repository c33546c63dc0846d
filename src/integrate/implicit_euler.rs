//! Backward (implicit) Euler on the full nonlinear system, solved for the new velocity by
//! Newton's method with the analytic spring, damper and drag Jacobians (Baraff & Witkin,
//! "Large steps in cloth simulation", SIGGRAPH 1998, without their one-iteration shortcut).
//!
//! Newton stops at 1 % of the step's own error estimate (see [`ImplicitSettings::kappa`]) and
//! backtracks when an update would raise the residual (or, for the clamped direction, the
//! step's incremental potential).
//!
//! Each Newton iteration solves (M - h ∂f/∂v - h² ∂f/∂x) Δv = -G(v') with conjugate gradients,
//! preconditioned by the inverse 3×3 diagonal blocks (block Jacobi), matrix-free: cost per CG
//! iteration is linear in particles + springs. If CG meets non-positive curvature (a compressed
//! spring makes the exact Jacobian indefinite) the solve is redone with more and more of the
//! compressed springs' negative stiffness dropped (50 %, 87.5 %, 100 %: the last is SPD),
//! which still converges to the same root. Large systems run the products and vector updates
//! in parallel over fixed chunks (bit-identical for any thread count).
//! Order 1; A-stable and L-stable: on an undamped oscillator the amplitude shrinks by
//! 1/√(1 + (hω)²) per step, for every h.

use super::{ensure_len, Integrator, StepStats};
use crate::error::{Error, Result};
use crate::model::parallel::{dot, each_particle, each_particle2, each_particle3};
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
    /// Newton also stops when |M⁻¹ G| ≤ `kappa` × the step's truncation-error estimate
    /// ½ |v' − v_pred| (v_pred: the first-order explicit predictor), both in the mass-weighted
    /// RMS norm √(Σ m |·|² / Σ m), so the solver error stays `kappa` times below the method's
    /// own error (Hairer & Wanner, Solving ODEs II, §IV.8, stop Newton at κ ∈ [0.01, 0.1] of
    /// the error tolerance, in an RMS norm; we take 1 % of the error itself).
    pub kappa: f64,
    /// CG stops at this relative residual (preconditioned norm).
    pub cg_tol: f64,
    /// CG iterations before giving up on one linear solve.
    pub max_cg: usize,
    /// Halvings of a Newton update tried when it would raise the residual (line search on
    /// GᵀM⁻¹G); the last trial is taken if none lowers it.
    pub max_halvings: usize,
}

impl Default for ImplicitSettings {
    fn default() -> Self {
        ImplicitSettings {
            max_newton: 50,
            newton_tol: 1e-10,
            kappa: 1e-2,
            cg_tol: 1e-8,
            max_cg: 2000,
            max_halvings: 4,
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
    /// Steps that stopped on the truncation-error tolerance (`kappa`) before `newton_tol`.
    pub error_limited_steps: u64,
    /// Newton updates shortened by the line search.
    pub damped_updates: u64,
    jac: Option<Jacobian>,
    f: Vec<Vec3>,
    xn: Vec<Vec3>,
    vn: Vec<Vec3>,
    vbase: Vec<Vec3>,
    vpred: Vec<Vec3>,
    pot: PotentialScratch,
    r: Vec<Vec3>,
    dv: Vec<Vec3>,
    floor: Vec<f64>,
    cg: Cg,
}

/// What one evaluation of the backward-Euler residual G(v') found.
#[derive(Debug, Clone, Copy)]
struct Residual {
    /// max |M⁻¹G| above the rounding floor (velocity units).
    max: f64,
    /// GᵀM⁻¹G, the line-search merit.
    merit: f64,
    /// Velocity scale for relative tolerances.
    scale: f64,
    /// Dissipated power at the iterate.
    power: f64,
}

/// Rounding floor of the Newton residual, as a multiple of ε·h/m·Σ k(|x_i| + |x_j| + l0): a
/// residual below it is the rounding error of the force evaluation itself and cannot shrink.
const ROUNDING_FLOOR: f64 = 8.0 * f64::EPSILON;

/// Fractions of compressed springs' indefinite stiffness dropped in successive attempts at
/// one Newton solve (see [`Jacobian::clamp`]).
const CLAMPS: [f64; 4] = [0.0, 0.5, 0.875, 1.0];

#[derive(Debug, Default)]
struct Cg {
    diag_inv: Vec<Matrix3<f64>>,
    r: Vec<Vec3>,
    z: Vec<Vec3>,
    p: Vec<Vec3>,
    ap: Vec<Vec3>,
    /// Chunk sums of the dot products.
    parts: Vec<f64>,
}

enum CgOutcome {
    Converged(usize),
    NegativeCurvature(usize),
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
        each_particle(&mut self.diag_inv, |_, d| {
            *d = d.try_inverse().unwrap_or_else(Matrix3::identity)
        });
        let free = &sys.free;
        each_particle2(x, &mut self.r, |i, xi, ri| {
            *xi = Vec3::zeros();
            *ri = if free[i] { b[i] } else { Vec3::zeros() };
        });
        let (r, d) = (&self.r, &self.diag_inv);
        each_particle2(&mut self.z, &mut self.p, |i, zi, pi| {
            *zi = d[i] * r[i];
            *pi = *zi;
        });
        let mut rz = dot(&self.r, &self.z, &mut self.parts);
        let rz0 = rz;
        if rz0 == 0.0 {
            return CgOutcome::Converged(0);
        }
        for it in 0..set.max_cg {
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
            let (p, ap, d) = (&self.p, &self.ap, &self.diag_inv);
            each_particle3(x, &mut self.r, &mut self.z, |i, xi, ri, zi| {
                *xi += p[i] * alpha;
                *ri -= ap[i] * alpha;
                *zi = d[i] * *ri;
            });
            let rz_new = dot(&self.r, &self.z, &mut self.parts);
            if rz_new <= set.cg_tol * set.cg_tol * rz0 {
                return CgOutcome::Converged(it + 1);
            }
            let beta = rz_new / rz;
            rz = rz_new;
            let z = &self.z;
            each_particle(&mut self.p, |i, pi| *pi = z[i] + *pi * beta);
        }
        CgOutcome::NotConverged
    }
}

impl ImplicitEuler {
    /// Sets x' = x + h v', evaluates the forces there and G(v') = M (v' − v) − h f(x', v')
    /// into `self.r`; the max norm counts only what is above the force evaluation's own
    /// rounding floor at each particle.
    fn residual(&mut self, sys: &System, s: &State, h: f64, v_scale0: f64) -> Residual {
        for p in 0..s.len() {
            self.xn[p] = s.x[p] + self.vn[p] * h;
        }
        let power = sys.forces(&self.xn, &self.vn, &mut self.f);
        self.floor.iter_mut().for_each(|r| *r = 0.0);
        sys.springs.add_rounding_scale(&self.xn, &mut self.floor);
        let (mut max, mut merit) = (0.0f64, 0.0f64);
        let mut scale = v_scale0.max(max_abs(&self.vn));
        for p in 0..s.len() {
            if sys.free[p] {
                self.r[p] = (self.vn[p] - s.v[p]) * sys.mass[p] - self.f[p] * h;
                let noise = ROUNDING_FLOOR * h * sys.inv_mass[p] * self.floor[p];
                max = max.max((self.r[p] * sys.inv_mass[p]).amax() - noise);
                merit += self.r[p].norm_squared() * sys.inv_mass[p];
                scale = scale.max((self.f[p] * (h * sys.inv_mass[p])).amax());
            } else {
                self.r[p] = Vec3::zeros();
            }
        }
        Residual {
            max,
            merit,
            scale,
            power,
        }
    }
}

/// Scratch for [`potential`].
#[derive(Debug, Default)]
struct PotentialScratch {
    /// x + h v' at the trial.
    x_new: Vec<Vec3>,
    /// Positions at which the damping directions are frozen (the line search's base).
    x_frozen: Vec<Vec3>,
    /// Force output of the dissipated-power evaluation (unused).
    f: Vec<Vec3>,
}

/// The step's incremental potential Φ(v') = ½ Σ m|v' − v|² + U(x + h v') + ½ h P(x_k, v'),
/// with the dissipated power P, a quadratic form in v' for springlab's linear dampers,
/// evaluated with damping directions frozen at the line search's base x_k: its v'-gradient
/// at the base is exactly the residual G, so a clamped Newton direction descends on it.
fn potential(sys: &System, s: &State, v: &[Vec3], h: f64, w: &mut PotentialScratch) -> f64 {
    let mut kin = 0.0;
    for p in 0..s.len() {
        w.x_new[p] = s.x[p] + v[p] * h;
        if sys.free[p] {
            kin += 0.5 * sys.mass[p] * (v[p] - s.v[p]).norm_squared();
        }
    }
    let e = sys.energy(&w.x_new, v);
    let power = sys.forces(&w.x_frozen, v, &mut w.f);
    kin + e.gravity + e.elastic + 0.5 * h * power
}

fn max_abs(v: &[Vec3]) -> f64 {
    v.iter().map(|c| c.amax()).fold(0.0, f64::max)
}

impl Integrator for ImplicitEuler {
    fn name(&self) -> &str {
        "implicit_euler"
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        for buf in [
            &mut self.f,
            &mut self.xn,
            &mut self.vn,
            &mut self.vbase,
            &mut self.vpred,
            &mut self.pot.x_new,
            &mut self.pot.x_frozen,
            &mut self.pot.f,
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
        let v_scale0 = max_abs(&s.v);
        // Errors are built only on failure: a step must not allocate.
        // Err(true): non-finite residual; Err(false): no convergence.
        let mut result: std::result::Result<f64, bool> = Err(false);
        // Round-off floor: positions carry ε|x| absolute error, i.e. ε|x|/h in velocity.
        let x_floor = 16.0 * f64::EPSILON * max_abs(&s.x) / h;
        let mut small_update = false;
        let free_mass: f64 = (0..n).filter(|&p| sys.free[p]).map(|p| sys.mass[p]).sum();
        let free_mass = if free_mass > 0.0 { free_mass } else { 1.0 };
        let mut res = self.residual(sys, s, h, v_scale0);
        let mut evals = 1u64;
        // The explicit predictor v0 + h M⁻¹ f(x0 + h v0, v0) is first order, so ½|v' − v_pred|
        // estimates backward Euler's local error in velocity at no extra force evaluation.
        for p in 0..n {
            self.vpred[p] = s.v[p] - self.r[p] * sys.inv_mass[p];
        }
        for iter in 0..=self.settings.max_newton {
            if !res.max.is_finite() || !res.merit.is_finite() {
                result = Err(true);
                break;
            }
            let tight = res.max <= self.settings.newton_tol * res.scale || res.scale == 0.0;
            // Mass-weighted RMS norms (velocity units) for the error-based stop: a max norm
            // would let a few particles at a pinned corner decide for the whole cloth.
            let mut lte2 = 0.0;
            for p in 0..n {
                if sys.free[p] {
                    lte2 += sys.mass[p] * (self.vn[p] - self.vpred[p]).norm_squared();
                }
            }
            let lte = 0.5 * (lte2 / free_mass).sqrt();
            let res_rms = (res.merit / free_mass).sqrt();
            let loose = iter > 0 && res_rms <= self.settings.kappa * lte;
            if tight || small_update || loose {
                if loose && !tight && !small_update {
                    self.error_limited_steps += 1;
                }
                result = Ok(res.power);
                break;
            }
            if iter == self.settings.max_newton {
                break;
            }
            self.newton_iterations += 1;
            for p in 0..n {
                self.r[p] = -self.r[p];
            }
            // Exact Jacobian first; on negative curvature drop more and more of the compressed
            // springs' indefinite stiffness (CLAMPS), ending with the SPD clamped matrix.
            let mut attempt = 0;
            loop {
                jac.clamp = CLAMPS[attempt];
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
                    CgOutcome::NegativeCurvature(it) if attempt + 1 < CLAMPS.len() => {
                        self.cg_iterations += it as u64;
                        attempt += 1;
                    }
                    CgOutcome::NotConverged => {
                        self.cg_iterations += self.settings.max_cg as u64;
                        break; // use the partial solve: Newton's residual check decides
                    }
                    CgOutcome::NegativeCurvature(_) => {
                        return Err(Error::Step("implicit_euler: Newton matrix is not positive definite even after clamping".into()));
                    }
                }
            }
            // Backtracking: a folding cloth makes the (clamped) Jacobian a poor model, and a
            // full update can raise the residual; halve it until GᵀM⁻¹G falls.
            self.vbase.copy_from_slice(&self.vn);
            let mut alpha = 1.0;
            let mut phi_base = f64::NAN; // the base's potential, computed only if needed
            for halving in 0..=self.settings.max_halvings {
                for p in 0..n {
                    self.vn[p] = self.vbase[p] + self.dv[p] * alpha;
                }
                let trial = self.residual(sys, s, h, v_scale0);
                evals += 1;
                let mut done = trial.merit <= res.merit
                    || !trial.merit.is_finite()
                    || halving == self.settings.max_halvings;
                if !done {
                    // The residual rose: accept the update anyway if it lowers the step's
                    // incremental potential (the clamped Newton direction is a descent
                    // direction for it, not for the residual).
                    if phi_base.is_nan() {
                        for p in 0..n {
                            self.pot.x_frozen[p] = s.x[p] + self.vbase[p] * h;
                        }
                        phi_base = potential(sys, s, &self.vbase, h, &mut self.pot);
                        evals += 1;
                    }
                    done = potential(sys, s, &self.vn, h, &mut self.pot) < phi_base;
                    evals += 1; // each potential evaluates the dampers' power: a force pass
                }
                if done {
                    if halving > 0 {
                        self.damped_updates += 1;
                    }
                    res = trial;
                    break;
                }
                alpha *= 0.5;
            }
            // Converged when the update is below the tolerance or the round-off floor.
            small_update = alpha * max_abs(&self.dv)
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
