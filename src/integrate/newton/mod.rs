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
//! (10⁻¹⁰) of it. A stage whose iteration runs out of iterations has the patch that holds its
//! residual (a knot of particles whose springs turn within the step) eliminated: the stage's
//! incremental potential over that patch, the rest held, minimised by trust-region Newton steps
//! on its dense Hessian, and the iteration resumed, knot after knot while the eliminations gain
//! (`patch.rs`); where that does not reach the root, it is solved again along its root path, the stages of steps β·k/16
//! each from the last roots (`continuation.rs`); where that path stops too, the step fails ("did not converge", which the runner reports as unstable),
//! saying where the iteration stopped and how far the path got, with the Newton matrix's lowest
//! eigenvalue at each (`curvature.rs`). Newton stops at `newton_tol`, or, once at the root
//! tolerance, when an update is below the tolerance or the round-off floor, when the residual
//! is a fraction of the stage's own error estimate (1 % for first-order methods, 0.01 % for
//! second-order ones, see [`ImplicitSettings::kappa`]), or at the iteration cap. The error estimate alone is no stop: at
//! hω ≫ 1 it exceeds the error by about hω and would accept iterates far from the root (two free
//! particles of 1 and 2 kg at hω = 12 gained 45 % momentum). On a free system (`momentum.rs`) every
//! iterate's momentum balance is zeroed, and CG deflates the translations, so linear momentum is
//! kept to round-off at any tolerance.
//!
//! Globalisation: for conservative forces the stage is the minimisation of its incremental
//! potential Φ(v') = ½ (v' − v̂)ᵀM(v' − v̂) + U(x̂ + β v') + β D(v') (`potential.rs`; the
//! dampers enter as their dissipation potential D with directions frozen at the iterate), whose
//! gradient is G. Every Newton direction solves the exact Newton matrix with a
//! Levenberg–Marquardt shift (1 + μ)M, μ = 0 until CG meets non-positive curvature and raised
//! past it then (`shift.rs`), so it is always a descent direction of Φ; the step along it is
//! Armijo's on Φ (`backtrack`), judged by the residual only where Φ's change sinks into its
//! round-off. Near a minimum whose Hessian is positive definite the shift falls to 0 and the
//! steps are Newton's own (quadratic convergence). The linear solves are inexact
//! (Eisenstat–Walker forcing, never tighter than half the error-based stop needs); the solver is
//! chosen by [`ImplicitSettings::solver`] (see `linsolve.rs` for the measured choice).

mod cg;
mod continuation;
mod curvature;
#[cfg(feature = "direct-solver")]
mod direct;
mod ic0;
mod line_search;
mod linear;
mod linsolve;
mod momentum;
mod patch;
mod pattern;
mod potential;
mod settings;
mod shift;
mod stage;
mod translation;

use crate::error::{significant, Error, Result};
use crate::integrate::ensure_len;
use crate::model::{Jacobian, System, Vec3};
use linsolve::{Indefiniteness, LinearProblem, LinearSolve};
use potential::PotentialScratch;
pub use settings::{ImplicitSettings, LinearSolver};
use stage::Stage;

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
    /// Newton iterations whose matrix carried a Levenberg–Marquardt shift (the exact one was
    /// indefinite, or the last step overshot; see `shift.rs`): how often a stage was hard.
    pub shifted_iterations: u64,
    /// Trust-region iterations of patch eliminations (`patch.rs`), each on a stalled stage.
    pub patch_iterations: u64,
    jac: Option<Jacobian>,
    f: Vec<Vec3>,
    xn: Vec<Vec3>,
    vn: Vec<Vec3>,
    vbase: Vec<Vec3>,
    vpred: Vec<Vec3>,
    pot: PotentialScratch,
    r: Vec<Vec3>,
    dv: Vec<Vec3>,
    /// Where a failed stage's direct iteration stopped: its v' and residual G.
    stop_v: Vec<Vec3>,
    stop_r: Vec<Vec3>,
    /// The root path's previous roots, the roots of its pieces in order, and the Lanczos
    /// start at a root (`continuation.rs`).
    path_prev: Vec<Vec3>,
    path_roots: Vec<Vec3>,
    path_start: Vec<Vec3>,
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
    /// Numeric factorisations of a preconditioner so far: IC(0)'s (`LinearSolver::BlockIc0Cg`)
    /// and the sparse Cholesky's (`LinearSolver::Cholesky`, a `direct-solver` build).
    pub fn factorizations(&self) -> u64 {
        self.lin.factorizations()
    }
    /// Applications of a factored preconditioner so far (forward and backward substitutions).
    pub fn factor_solves(&self) -> u64 {
        self.lin.factor_solves()
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
            &mut self.path_prev,
            &mut self.stop_v,
            &mut self.stop_r,
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
    fn residual(&mut self, st: &Stage<'_>) -> Residual {
        let Stage { sys, x0, v0, h, .. } = *st;
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
        let mut scale = st.v_scale0.max(max_abs(&self.vn)).max(kick);
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

    /// Solves the backward-Euler stage from (x̂, v̂) = (`x0`, `v0`) with step `h` (β above);
    /// the result is in [`Newton::x`], [`Newton::v`]. Returns the dissipated power at the
    /// solution and the force evaluations made. `who` names the method in errors.
    pub(crate) fn solve(
        &mut self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        h: f64,
        stop: Stop,
        who: &'static str,
    ) -> Result<(f64, u64)> {
        self.prepare(sys);
        let kappa = match stop {
            Stop::FirstOrder => self.settings.kappa,
            Stop::SecondOrder => self.settings.kappa * self.settings.kappa,
        };
        let st = Stage::new(sys, x0, v0, h, kappa);
        let (mut res, mut evals) = self.start(&st, stop);
        let mut jac = self.take_jacobian(sys);
        jac.shift = 0.0;
        let mut solved = self.iterate(&st, &mut jac, &mut res, &mut evals, usize::MAX);
        let mut eliminated = 0;
        if patch::eliminable(sys, self.shift_mass > 0.0) {
            (solved, eliminated) = self.eliminate_patches(&st, &mut jac, &mut evals, solved);
        }
        if let Err(failure @ Failure::NoConvergence { .. }) = solved {
            // Where the direct iteration stopped, for the explanation should the path stop too.
            self.stop_v.copy_from_slice(&self.vn);
            self.stop_r.copy_from_slice(&self.r);
            solved = match self.along_path(&st, &mut jac, &mut evals) {
                Ok(power) => Ok(power),
                Err(solved) => Err(self.explain(&st, &mut jac, failure, solved)),
            };
        }
        self.jac = Some(jac);
        let power =
            solved.map_err(|failure| failure.error(who, self.settings.max_newton, eliminated))?;
        Ok((power, evals))
    }

    /// Sets the first iterate and the error estimate's predictor; returns the residual there
    /// and the force evaluations made. The first-order methods start at v̂; the second-order
    /// ones at the linearly implicit solution (Jacobian at the base), exact for linear forces,
    /// so that at hω ≫ 1 Newton stays on the base's side of a spring's anchor instead of
    /// jumping to a root where |d| folds the force law (found on the anchored spring at
    /// hω = 31.6).
    fn start(&mut self, st: &Stage<'_>, stop: Stop) -> (Residual, u64) {
        let mut evals = 0u64;
        let guessed = stop == Stop::SecondOrder && {
            evals += 1;
            self.linearized(st.sys, st.x0, st.v0, st.h).is_ok()
        };
        if !guessed {
            self.vn.copy_from_slice(st.v0);
        }
        let mut res = self.residual(st);
        evals += 1;
        if guessed {
            // Keep the linearly implicit start only where it beats v̂: on a folding cloth the
            // start-of-step linearisation can be far off.
            self.vbase.copy_from_slice(&self.vn);
            self.vn.copy_from_slice(st.v0);
            let at_base = self.residual(st);
            evals += 1;
            if at_base.merit <= res.merit || !res.merit.is_finite() {
                res = at_base;
                self.predict(st);
            } else {
                self.vn.copy_from_slice(&self.vbase);
                res = self.residual(st);
                evals += 1;
            }
        } else {
            // The explicit predictor v0 + h M⁻¹ f(x0 + h v0, v0) is first order, so ½|v' − v_pred|
            // estimates backward Euler's local error in velocity at no extra force evaluation.
            // (From v' rather than v̂: the same predictor where the momentum shift moved v'.)
            self.predict(st);
        }
        (res, evals)
    }

    /// The explicit predictor from the current iterate and its residual: v' − M⁻¹G.
    fn predict(&mut self, st: &Stage<'_>) {
        for p in 0..st.x0.len() {
            self.vpred[p] = self.vn[p] - self.r[p] * st.sys.inv_mass[p];
        }
    }

    /// Newton's iteration resumed from the current iterate `self.vn`, the shift back at 0
    /// ([`Newton::iterate`] with `patience`); returns its outcome and the merit it ended at.
    fn iterate_from_here(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        evals: &mut u64,
        patience: usize,
    ) -> (std::result::Result<f64, Failure>, f64) {
        let mut res = self.residual(st);
        *evals += 1;
        jac.shift = 0.0;
        let solved = self.iterate(st, jac, &mut res, evals, patience);
        (solved, res.merit)
    }

    /// Newton's iteration from the iterate `res` describes until a stop accepts it; returns
    /// the dissipated power there. Counts its force evaluations into `evals`. It fails at the
    /// iteration cap, or once `patience` iterations in a row have not lowered its lowest
    /// merit (`usize::MAX`: never).
    fn iterate(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        res: &mut Residual,
        evals: &mut u64,
        patience: usize,
    ) -> std::result::Result<f64, Failure> {
        let n = st.x0.len();
        let mut small_update = false;
        let mut prev_merit = f64::INFINITY;
        let (mut lowest, mut lowest_at) = (f64::INFINITY, 0usize);
        for iter in 0..=self.settings.max_newton {
            if res.merit < lowest {
                (lowest, lowest_at) = (res.merit, iter);
            }
            if !res.max.is_finite() || !res.merit.is_finite() {
                return Err(Failure::NonFinite);
            }
            let lte = self.error_estimate(st);
            if self.accepts(st, res, lte, iter, small_update) {
                return Ok(res.power);
            }
            if iter == self.settings.max_newton || iter - lowest_at >= patience {
                break;
            }
            self.newton_iterations += 1;
            for p in 0..n {
                self.r[p] = -self.r[p];
            }
            let abs_tol2 = self.linear_tolerance(st, res, lte, prev_merit);
            prev_merit = res.merit;
            self.direction(st, jac, abs_tol2)?;
            self.vbase.copy_from_slice(&self.vn);
            // Gᵀd: the right-hand side holds −G.
            let gd: f64 = -(0..n).map(|p| self.r[p].dot(&self.dv[p])).sum::<f64>();
            let (alpha, e) = self.backtrack(st, res, gd);
            *evals += e;
            jac.shift = shift::after_step(jac.shift, alpha);
            // Converged when the update is below the tolerance or the round-off floor.
            small_update = alpha * max_abs(&self.dv)
                <= self.settings.newton_tol * st.v_scale0.max(max_abs(&self.vn)) + st.x_floor;
        }
        Err(self.unreached(st, res))
    }

    /// The failure of a stage that ran out of iterations at the iterate `res` describes (its
    /// residual in `self.r`): how far from the root it stopped, and where. The matrix's
    /// eigenvalue there is estimated only if the root path fails too (`continuation.rs`).
    fn unreached(&self, st: &Stage<'_>, res: &Residual) -> Failure {
        let sys = st.sys;
        let size = |p: usize| (self.r[p] * sys.inv_mass[p]).amax();
        let worst = (0..sys.len())
            .filter(|&p| sys.free[p])
            .fold(None, |best: Option<usize>, p| match best {
                Some(b) if size(b) >= size(p) => Some(b),
                _ => Some(p),
            })
            .unwrap_or(0);
        Failure::NoConvergence {
            at: Unreached {
                rms: (res.merit / st.free_mass).sqrt(),
                largest: size(worst),
                particle: worst,
                scale: res.scale,
                tol: self.settings.root_tol,
                curvature: None,
            },
            path: None,
        }
    }

    /// The stage's first-order error estimate ½|v' − v_pred| in the mass-weighted RMS norm
    /// (velocity units): a max norm would let a few particles at a pinned corner decide for
    /// the whole cloth.
    fn error_estimate(&self, st: &Stage<'_>) -> f64 {
        let sys = st.sys;
        let mut lte2 = 0.0;
        for p in 0..st.x0.len() {
            if sys.free[p] {
                lte2 += sys.mass[p] * (self.vn[p] - self.vpred[p]).norm_squared();
            }
        }
        0.5 * (lte2 / st.free_mass).sqrt()
    }

    /// Whether the iterate `res` describes ends the stage: at `newton_tol`, or at the root
    /// tolerance with a small last update, a residual under κ × `lte`, or the iteration cap
    /// (module docs). Counts the stops on the error estimate.
    fn accepts(
        &mut self,
        st: &Stage<'_>,
        res: &Residual,
        lte: f64,
        iter: usize,
        small_update: bool,
    ) -> bool {
        let set = &self.settings;
        let tight = res.max <= set.newton_tol * res.scale || res.scale == 0.0;
        let res_rms = (res.merit / st.free_mass).sqrt();
        let root = res_rms <= set.root_tol * res.scale || tight;
        let loose = iter > 0 && st.kappa > 0.0 && res_rms <= st.kappa * lte;
        // The cheap stops only where the stage meets the root tolerance (module docs).
        if tight || (root && (small_update || loose || iter == set.max_newton)) {
            if loose && !tight && !small_update {
                self.error_limited_steps += 1;
            }
            return true;
        }
        false
    }

    /// The linear solve's stop Σ |rᵢ|²/mᵢ ≤ the returned value, given the residual `res`,
    /// the error estimate `lte` and the previous iterate's merit `prev_merit`. Inexact Newton
    /// (Dembo, Eisenstat & Steihaug, SIAM J. Numer. Anal. 19, 1982): the linear residual need
    /// only fall to η |G| with Eisenstat & Walker's forcing η = min(η_max, 0.9 (|G|/|G_prev|)²)
    /// (SIAM J. Sci. Comput. 17, 1996, choice 2), and never below half the error-based stop's
    /// target, which it would oversolve.
    fn linear_tolerance(&self, st: &Stage<'_>, res: &Residual, lte: f64, prev_merit: f64) -> f64 {
        let set = &self.settings;
        let eta = if prev_merit.is_finite() {
            (0.9 * res.merit / prev_merit).min(set.forcing)
        } else {
            set.forcing
        };
        // The error-based floor, never above a tenth of the root tolerance (in RMS), which
        // the next iterate must meet in max norm.
        let target2 = if st.kappa > 0.0 {
            (0.5 * st.kappa * lte)
                .min(ROOT_FLOOR * set.root_tol * res.scale)
                .powi(2)
                * st.free_mass
        } else {
            0.0
        };
        target2.max(eta * eta * res.merit)
    }

    /// Solves the shifted Newton matrix at the iterate for the direction `self.dv` from the
    /// right-hand side −G in `self.r`, to `abs_tol2`; counts the linear and shifted iterations.
    fn direction(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        abs_tol2: f64,
    ) -> std::result::Result<(), Failure> {
        let mut rhs = std::mem::take(&mut self.r);
        let prob = LinearProblem {
            sys: st.sys,
            x: &self.xn,
            v: &self.vn,
            h: st.h,
            set: &self.settings,
            abs_tol2,
        };
        let solved = self.lin.solve(
            jac,
            &prob,
            |_, _| {},
            &mut rhs,
            &mut self.dv,
            Indefiniteness::Shift,
        );
        self.r = rhs;
        self.cg_iterations += solved.map_err(|_| Failure::Indefinite)?;
        if jac.shift > 0.0 {
            self.shifted_iterations += 1;
        }
        Ok(())
    }
}

/// Why a stage was not solved. The error is built from it only on failure: a step must not
/// allocate.
#[derive(Debug, Clone, Copy)]
enum Failure {
    /// A residual was not finite.
    NonFinite,
    /// No stop accepted an iterate within the iteration cap, nor along the stage's root path
    /// (`continuation.rs`): where the direct iteration stopped, and where the path did.
    NoConvergence {
        at: Unreached,
        path: Option<continuation::PathEnd>,
    },
    /// No shift made the Newton matrix positive definite.
    Indefinite,
}

/// Where a stage's direct iteration stopped: the residual's mass-weighted RMS and its largest
/// component |M⁻¹G| (at `particle`), the stage's velocity scale, the root tolerance (a
/// fraction of it), and the exact Newton matrix's lowest eigenvalue there, relative to the
/// mass term's.
#[derive(Debug, Clone, Copy)]
struct Unreached {
    rms: f64,
    largest: f64,
    particle: usize,
    scale: f64,
    tol: f64,
    curvature: Option<f64>,
}

impl Unreached {
    /// Where the iteration stopped, in words.
    fn describe(&self) -> String {
        let Unreached {
            rms,
            largest,
            particle,
            scale,
            tol,
            curvature,
        } = *self;
        format!(
            "its residual M⁻¹G stopped at an RMS of {} m/s, {} of the stage's velocity scale of \
             {} m/s (a root is within {tol:e} of it), largest {} m/s at particle {particle}{}",
            significant(rms, 4),
            significant(rms / scale, 4),
            significant(scale, 4),
            significant(largest, 4),
            curvature.map_or(String::new(), |c| format!(
                "; there the Newton matrix's lowest eigenvalue is at most {} times the mass \
                 term's (a Lanczos estimate: 1 is the mass term alone, 0 a singular matrix, \
                 below 0 an indefinite one)",
                significant(c, 4)
            )),
        )
    }
}

impl Failure {
    /// The step error for the method `who`, whose iteration cap is `max_newton`, after
    /// `eliminated` patch eliminations.
    fn error(self, who: &str, max_newton: usize, eliminated: usize) -> Error {
        Error::Step(match self {
            Failure::NonFinite => format!("{who}: non-finite residual in Newton iteration"),
            Failure::NoConvergence { at, path } => format!(
                "{who}: Newton did not converge in {max_newton} iterations{}: {}{}",
                match eliminated {
                    0 => String::new(),
                    1 => ", nor after eliminating its stalled patch once".into(),
                    k => format!(", nor after eliminating its stalled patch {k} times"),
                },
                at.describe(),
                path.map_or(String::new(), |end| end.describe()),
            ),
            Failure::Indefinite => {
                format!("{who}: Newton matrix is not positive definite at any shift")
            }
        })
    }
}
