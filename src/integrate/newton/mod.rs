//! The implicit core shared by every implicit method: one backward-Euler stage
//!
//!   x' = x̂ + β v',  M (v' − v̂) = β f(x', v'),
//!
//! from a base state (x̂, v̂) with step β, solved for v' by Newton's method with the analytic
//! spring, damper and drag Jacobians, and a linearly implicit variant (one linear solve with
//! the Jacobian at the start). Backward Euler is the stage itself (x̂, v̂ = x, v; β = h);
//! implicit midpoint is the stage at β = h/2 followed by a linear extrapolation; BDF2 is the
//! stage from the extrapolated base (4yₙ − yₙ₋₁)/3 at β = 2h/3.
//!
//! The rule: a stage is accepted only at a root of its equation, the mass-weighted RMS of M⁻¹G at
//! most [`ImplicitSettings::root_tol`] (10⁻⁶) times the stage's velocity scale (the largest
//! component of v̂, v', β f/m or β g), or with max |M⁻¹G| at [`ImplicitSettings::newton_tol`]
//! (10⁻¹⁰) of it; otherwise the step fails ("did not converge", which the runner reports as
//! unstable). Newton stops at `newton_tol`, or, once at the root tolerance, when an update is below
//! the tolerance or the round-off floor, when the residual is a fraction of the stage's own error
//! estimate (1 % for first-order methods, 0.01 % for second-order ones, see
//! [`ImplicitSettings::kappa`]), or at the iteration cap. The error estimate alone is no stop: at
//! hω ≫ 1 it exceeds the error by about hω and would accept iterates far from the root (two free
//! particles of 1 and 2 kg at hω = 12 gained 45 % momentum). On a free system (`momentum.rs`) every
//! iterate's momentum balance is zeroed, and CG deflates the translations, so linear momentum is
//! kept to round-off at any tolerance. Newton backtracks when an update would raise the residual
//! (or, for a clamped direction, the stage's incremental potential). Where the clamped iteration
//! stalls (the residual has not halved in six iterations: near a root where the exact Jacobian is
//! indefinite, as past the 316² cloth's fold), the stage takes Steihaug–Toint trust-region steps on
//! the exact Jacobian (see `trust.rs`), which follow negative curvature instead of clamping it, and
//! goes back to clamped Newton where those stall in turn. The linear solves are inexact
//! (Eisenstat–Walker forcing, never tighter than half the error-based stop needs); the solver is
//! chosen by [`ImplicitSettings::solver`] (see `linsolve.rs` for the measured choice).

mod cg;
#[cfg(feature = "direct-solver")]
mod direct;
mod ic0;
mod linear;
mod linsolve;
mod momentum;
mod pattern;
mod potential;
mod settings;
mod translation;
mod trust;

use crate::error::{Error, Result};
use crate::integrate::ensure_len;
use crate::model::{Jacobian, System, Vec3};
use linsolve::LinearSolve;
use potential::{potential, PotentialScratch};
pub use settings::{ImplicitSettings, LinearSolver};

/// Which Newton stop an implicit method may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    /// Tolerance, small update, or `kappa` × the stage's first-order error estimate.
    FirstOrder,
    /// Tolerance, small update, or `kappa²` × the first-order estimate (second-order
    /// methods): their local error is about hω times the first-order estimate, so `kappa²`
    /// keeps the solver error below `kappa` of the method's own error wherever hω ≳ `kappa`
    /// (below that, a linear problem converges in the first iteration anyway).
    SecondOrder,
}

/// The shared Newton + preconditioned-CG solver of one backward-Euler stage, with its counters.
#[derive(Debug, Default)]
pub struct Newton {
    /// Solver settings.
    pub settings: ImplicitSettings,
    /// Total Newton iterations (linear solves) so far, for cost reports.
    pub newton_iterations: u64,
    /// Total linear iterations so far (CG iterations; a direct solve counts one), for cost
    /// reports.
    pub cg_iterations: u64,
    /// Stages that stopped on the truncation-error tolerance (`kappa`) before `newton_tol`.
    pub error_limited_steps: u64,
    /// Newton updates shortened by the line search.
    pub damped_updates: u64,
    /// Switches between clamped Newton and trust-region steps, each on a stall of the
    /// strategy running (see `trust::Stall`): how often a stage was hard.
    pub strategy_switches: u64,
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
    lin: LinearSolve,
    /// Σm when the system is translation invariant (every iterate's momentum balance is then
    /// zeroed, see `momentum.rs`), else 0.
    shift_mass: f64,
}

/// What one evaluation of the stage residual G(v') found.
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

/// A linear solve may stop once its residual's RMS is this fraction of the root tolerance
/// ([`ImplicitSettings::root_tol`]), not above: the next iterate must meet that tolerance in
/// max norm, which a residual at the tolerance itself in RMS would often miss.
const ROOT_FLOOR: f64 = 0.1;

/// Largest component magnitude over all particles (the max norm of a velocity or position field).
pub(crate) fn max_abs(v: &[Vec3]) -> f64 {
    v.iter().map(|c| c.amax()).fold(0.0, f64::max)
}

impl Newton {
    /// Positions x' of the last solved stage.
    pub(crate) fn x(&self) -> &[Vec3] {
        &self.xn
    }
    /// Velocities v' of the last solved stage.
    pub(crate) fn v(&self) -> &[Vec3] {
        &self.vn
    }
    /// Numeric factorisations of the Newton matrix so far (`LinearSolver::Cholesky`, a
    /// `direct-solver` build).
    pub fn factorizations(&self) -> u64 {
        self.lin.factorizations
    }
    /// Forgets solver state carried between steps (the reused factor), so that the next step
    /// gives the same bits as a fresh solver's.
    pub(crate) fn reset(&mut self) {
        self.lin.invalidate();
    }

    fn ensure(&mut self, n: usize) {
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
    }

    /// Sizes the scratch for `sys` and decides whether its iterates' momentum is balanced.
    fn prepare(&mut self, sys: &System) {
        self.ensure(sys.len());
        self.shift_mass = if translation::translation_invariant(sys) {
            sys.mass.iter().sum()
        } else {
            0.0
        };
    }

    /// The cached Jacobian when its topology still fits `sys`, else a fresh one.
    fn take_jacobian(&mut self, sys: &System) -> Jacobian {
        match self.jac.take() {
            Some(j) if j.diag_x.len() == sys.len() && j.pairs.len() == sys.springs.len() => j,
            _ => sys.new_jacobian(),
        }
    }

    /// Sets x' = x̂ + β v', evaluates the forces there and G(v') = M (v' − v̂) − β f(x', v')
    /// into `self.r`; the max norm counts only what is above the force evaluation's own
    /// rounding floor at each particle.
    fn residual(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
        v_scale0: f64,
    ) -> Residual {
        for p in 0..x0.len() {
            self.xn[p] = x0[p] + self.vn[p] * h;
        }
        let power = sys.forces(&self.xn, &self.vn, &mut self.f);
        if self.shift_mass > 0.0 {
            self.balance_momentum(sys, v0, h, self.shift_mass);
        }
        self.floor.iter_mut().for_each(|r| *r = 0.0);
        sys.springs.add_rounding_scale(&self.xn, &mut self.floor);
        let (mut max, mut merit) = (0.0f64, 0.0f64);
        // Gravity's kick β|g| is part of the scale: a body resting on a contact has no net force.
        let kick = sys.gravity.map_or(0.0, |g| g.amax() * h);
        let mut scale = v_scale0.max(max_abs(&self.vn)).max(kick);
        for p in 0..x0.len() {
            if sys.free[p] {
                self.r[p] = (self.vn[p] - v0[p]) * sys.mass[p] - self.f[p] * h;
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

    /// Backtracking on an interior Newton step `self.dv` from `self.vbase`: a folding cloth
    /// makes the Jacobian a poor model, and a full update can raise the residual; halve it
    /// until GᵀM⁻¹G falls, or the stage's incremental potential does (the Newton direction is a
    /// descent direction for it, not for the residual); after `max_halvings` the last trial is
    /// taken. Updates `res` to the accepted iterate's; returns (α, force evaluations).
    fn backtrack(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
        v_scale0: f64,
        res: &mut Residual,
    ) -> (f64, u64) {
        let mut evals = 0;
        let mut alpha = 1.0;
        let mut phi_base = f64::NAN; // the base's potential, computed only if needed
        for halving in 0..=self.settings.max_halvings {
            let trial = self.trial(sys, x0, v0, h, v_scale0, alpha);
            evals += 1;
            let mut done = trial.merit <= res.merit
                || !trial.merit.is_finite()
                || halving == self.settings.max_halvings;
            if !done {
                if phi_base.is_nan() {
                    phi_base = self.base_potential(sys, x0, v0, h);
                    evals += 1;
                }
                done = potential(sys, x0, v0, &self.vn, h, &mut self.pot) < phi_base;
                evals += 1; // each potential evaluates the dampers' power: a force pass
            }
            if done {
                if halving > 0 {
                    self.damped_updates += 1;
                }
                *res = trial;
                break;
            }
            alpha *= 0.5;
        }
        (alpha, evals)
    }

    /// A line-search trial: v' = `self.vbase` + t·`self.dv`, and the residual there.
    fn trial(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
        v_scale0: f64,
        t: f64,
    ) -> Residual {
        for p in 0..x0.len() {
            self.vn[p] = self.vbase[p] + self.dv[p] * t;
        }
        self.residual(sys, x0, v0, h, v_scale0)
    }

    /// The incremental potential at `self.vbase`, freezing the damping directions there.
    fn base_potential(&mut self, sys: &System, x0: &[Vec3], v0: &[Vec3], h: f64) -> f64 {
        for p in 0..x0.len() {
            self.pot.x_frozen[p] = x0[p] + self.vbase[p] * h;
        }
        potential(sys, x0, v0, &self.vbase, h, &mut self.pot)
    }

    /// One trust-region step along `self.dv` from `self.vbase` (N&W Alg. 4.1, with Nocedal &
    /// Yuan's backtracking on rejection, "Combining trust region and line search", 1998): the
    /// trial τs, τ = 1, ¼, ¹⁄₁₆, …, is taken at the first τ whose ratio ρ of the incremental
    /// potential's actual to the model's predicted decrease reaches [`trust::ETA`], or whose
    /// residual merit falls (near convergence Φ's differences sink into its round-off, the
    /// residual's do not). `model` = m(s), `gs` = Gᵀs (so sᵀAs = 2(m(s) − Gᵀs)). Updates the
    /// radius and `res`; returns the force evaluations and whether a step was taken (if not,
    /// the base is restored with its residual in `self.r`, `res`).
    #[allow(clippy::too_many_arguments)]
    fn trust_region_step(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
        v_scale0: f64,
        res: &mut Residual,
        model: f64,
        gs: f64,
        radius: &mut f64,
        step_norm: f64,
    ) -> (u64, bool) {
        let phi_base = self.base_potential(sys, x0, v0, h);
        let mut evals = 1;
        let s_as = 2.0 * (model - gs);
        let on_boundary = step_norm >= *radius * (1.0 - 1e-12);
        let mut tau = 1.0;
        for _ in 0..=self.settings.max_halvings {
            let trial = self.trial(sys, x0, v0, h, v_scale0, tau);
            let phi = potential(sys, x0, v0, &self.vn, h, &mut self.pot);
            evals += 2;
            let pred = tau * gs + 0.5 * tau * tau * s_as;
            let rho = if pred < 0.0 {
                (phi - phi_base) / pred
            } else {
                f64::NEG_INFINITY
            };
            let finite = trial.merit.is_finite() && phi.is_finite();
            let accept = finite && (rho >= trust::ETA || trial.merit <= res.merit);
            if accept {
                // A step taken on the residual alone keeps the radius (no evidence either way).
                let rho = if rho < trust::ETA { 0.25 } else { rho };
                *radius = if tau < 1.0 {
                    tau * step_norm
                } else {
                    trust::update_radius(*radius, step_norm, rho, on_boundary)
                };
                if tau < 1.0 {
                    self.damped_updates += 1;
                }
                *res = trial;
                return (evals, true);
            }
            tau *= 0.25;
        }
        *radius = tau * step_norm;
        self.vn.copy_from_slice(&self.vbase);
        *res = self.residual(sys, x0, v0, h, v_scale0);
        (evals + 1, false)
    }

    /// Solves the backward-Euler stage from (x̂, v̂) = (`x0`, `v0`) with step `h` (β above);
    /// the result is in [`Newton::x`], [`Newton::v`]. Returns the dissipated power at the
    /// solution and the force evaluations made. `who` names the method in errors.
    // One function because the iteration's state (iterate, residual, strategy, forcing, stop tests) is shared by every branch of the loop; its parts (line search, trust region, stops) live in their own modules.
    pub(crate) fn solve(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
        stop: Stop,
        who: &'static str,
    ) -> Result<(f64, u64)> {
        let n = x0.len();
        self.prepare(sys);
        // Start: the first-order methods at v̂; the second-order ones at the linearly implicit
        // solution (Jacobian at the base), exact for linear forces, so that at hω ≫ 1 Newton
        // stays on the base's side of a spring's anchor instead of jumping to a root where
        // |d| folds the force law (found on the anchored spring at hω = 31.6).
        let mut evals = 0u64;
        let guessed = stop == Stop::SecondOrder && {
            evals += 1;
            self.linearized(sys, x0, v0, h).is_ok()
        };
        if !guessed {
            self.vn.copy_from_slice(v0);
        }
        let mut jac = self.take_jacobian(sys);
        let v_scale0 = max_abs(v0);
        // Errors are built only on failure: a step must not allocate.
        // Err(true): non-finite residual; Err(false): no convergence.
        let mut result: std::result::Result<f64, bool> = Err(false);
        // Round-off floor: positions carry ε|x| absolute error, i.e. ε|x|/h in velocity.
        let x_floor = 16.0 * f64::EPSILON * max_abs(x0) / h;
        let mut small_update = false;
        let free_mass: f64 = (0..n).filter(|&p| sys.free[p]).map(|p| sys.mass[p]).sum();
        let free_mass = if free_mass > 0.0 { free_mass } else { 1.0 };
        let kappa = match stop {
            Stop::FirstOrder => self.settings.kappa,
            Stop::SecondOrder => self.settings.kappa * self.settings.kappa,
        };
        let mut res = self.residual(sys, x0, v0, h, v_scale0);
        let mut prev_merit = f64::INFINITY;
        // Trust radius (P-norm) of the Steihaug–Toint solves. The stage starts with clamped
        // Newton and backtracking (fast while far from the solution). Where that stalls, the
        // clamped iteration may be circling a point where the exact Jacobian is indefinite:
        // the stage then runs Steihaug–Toint trust-region steps on the exact Jacobian,
        // starting from the last linear step's size; where those stall in turn (radii far
        // below the distance to the root), it goes back to clamped Newton (see `trust::Stall`).
        let mut radius = f64::INFINITY;
        let mut trust_mode = false;
        let mut stall = trust::Stall::new();
        evals += 1;
        if guessed {
            // Keep the linearly implicit start only where it beats v̂: on a folding cloth the
            // start-of-step linearisation can be far off.
            self.vbase.copy_from_slice(&self.vn);
            self.vn.copy_from_slice(v0);
            let at_base = self.residual(sys, x0, v0, h, v_scale0);
            evals += 1;
            if at_base.merit <= res.merit || !res.merit.is_finite() {
                res = at_base;
                for p in 0..n {
                    self.vpred[p] = self.vn[p] - self.r[p] * sys.inv_mass[p];
                }
            } else {
                self.vn.copy_from_slice(&self.vbase);
                res = self.residual(sys, x0, v0, h, v_scale0);
                evals += 1;
            }
        } else {
            // The explicit predictor v0 + h M⁻¹ f(x0 + h v0, v0) is first order, so ½|v' − v_pred|
            // estimates backward Euler's local error in velocity at no extra force evaluation.
            // (From v' rather than v̂: the same predictor where the momentum shift moved v'.)
            for p in 0..n {
                self.vpred[p] = self.vn[p] - self.r[p] * sys.inv_mass[p];
            }
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
            let root = res_rms <= self.settings.root_tol * res.scale || tight;
            let loose = iter > 0 && kappa > 0.0 && res_rms <= kappa * lte;
            // The cheap stops only where the stage meets the root tolerance (module docs).
            if tight || (root && (small_update || loose || iter == self.settings.max_newton)) {
                if loose && !tight && !small_update {
                    self.error_limited_steps += 1;
                }
                result = Ok(res.power);
                break;
            }
            if iter == self.settings.max_newton {
                break;
            }
            if stall.stalled(res.merit) {
                self.strategy_switches += 1;
                trust_mode = !trust_mode;
                radius = if trust_mode {
                    self.lin.trust_step().1.max(f64::MIN_POSITIVE)
                } else {
                    f64::INFINITY
                };
            }
            self.newton_iterations += 1;
            for p in 0..n {
                self.r[p] = -self.r[p];
            }
            // Inexact Newton (Dembo, Eisenstat & Steihaug, SIAM J. Numer. Anal. 19, 1982): the
            // linear residual need only fall to η |G| with Eisenstat & Walker's forcing
            // η = min(η_max, 0.9 (|G|/|G_prev|)²) (SIAM J. Sci. Comput. 17, 1996, choice 2),
            // and never below half the error-based stop's target, which it would oversolve.
            let eta = if prev_merit.is_finite() {
                (0.9 * res.merit / prev_merit).min(self.settings.forcing)
            } else {
                self.settings.forcing
            };
            prev_merit = res.merit;
            // The error-based floor, never above a tenth of the root tolerance (in RMS), which
            // the next iterate must meet in max norm.
            let target2 = if kappa > 0.0 {
                (0.5 * kappa * lte)
                    .min(ROOT_FLOOR * self.settings.root_tol * res.scale)
                    .powi(2)
                    * free_mass
            } else {
                0.0
            };
            let abs_tol2 = target2.max(eta * eta * res.merit);
            let mut rhs = std::mem::take(&mut self.r);
            let solved = self.lin.solve(
                &mut jac,
                sys,
                &self.xn,
                &self.vn,
                h,
                &self.settings,
                |_, _| {},
                &mut rhs,
                &mut self.dv,
                abs_tol2,
                trust_mode.then_some(radius),
            );
            self.r = rhs;
            match solved {
                Ok(it) => self.cg_iterations += it,
                Err(_) => {
                    self.jac = Some(jac);
                    return Err(Error::Step(format!(
                        "{who}: Newton matrix is not positive definite even after clamping"
                    )));
                }
            }
            let (model, step_norm, used_radius) = self.lin.trust_step();
            self.vbase.copy_from_slice(&self.vn);
            let alpha = if trust_mode {
                radius = used_radius;
                // Gᵀs: the right-hand side holds −G.
                let gs: f64 = -(0..n).map(|p| self.r[p].dot(&self.dv[p])).sum::<f64>();
                let (e, taken) = self.trust_region_step(
                    sys,
                    x0,
                    v0,
                    h,
                    v_scale0,
                    &mut res,
                    model,
                    gs,
                    &mut radius,
                    step_norm,
                );
                evals += e;
                if !taken {
                    small_update = false;
                    continue;
                }
                1.0
            } else {
                let (alpha, e) = self.backtrack(sys, x0, v0, h, v_scale0, &mut res);
                evals += e;
                alpha
            };
            // Converged when the update is below the tolerance or the round-off floor.
            small_update = alpha * max_abs(&self.dv)
                <= self.settings.newton_tol * v_scale0.max(max_abs(&self.vn)) + x_floor;
        }
        self.jac = Some(jac);
        let power = result.map_err(|non_finite| {
            Error::Step(if non_finite {
                format!("{who}: non-finite residual in Newton iteration")
            } else {
                format!(
                    "{who}: Newton did not converge in {} iterations",
                    self.settings.max_newton
                )
            })
        })?;
        Ok((power, evals))
    }
}
