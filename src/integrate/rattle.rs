//! RATTLE (Andersen, "Rattle: a velocity version of the Shake algorithm", J. Comput. Phys.
//! 52, 1983; Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §VII.1.4): velocity
//! Verlet for M ẍ = f(x, ẋ) − G(x)ᵀλ with rigid distance constraints g(x) = 0,
//!
//!   v_½ = v + (h/2) M⁻¹ (f − G(x)ᵀλ),  x' = x + h v_½,  g(x') = 0,
//!   v' = v_½ + (h/2) M⁻¹ (f' − G(x')ᵀμ),  G(x') v' = 0.
//!
//! λ is found by SHAKE's iteration along the start-of-step constraint directions and μ by the
//! velocity projection, both to a tight tolerance (see [`super::shake`]). Springs, gravity,
//! drag and every other force term are ordinary forces; velocity-dependent ones are evaluated
//! at a first-order predicted velocity, as in `velocity_verlet`, which keeps order 2. Order 2,
//! symplectic for conservative forces (energy error bounded, O(h²)); without constraints it
//! is velocity Verlet (stable for hω < 2 on an undamped oscillator).
//!
//! Compliant (soft, compliance > 0) constraints are refused by [`Stepper::check`]: RATTLE
//! is a method for rigid constraints, and a soft rod is a spring (a `[[spring]]`) or a job for
//! `verlet_constraints`' XPBD compliance.

use super::shake::{positions, velocities};
use super::{ensure_len, StepStats, Stepper};
use crate::error::{Error, Result};
use crate::model::{State, System, Vec3};

/// Tolerances of RATTLE's constraint iterations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RattleSettings {
    /// Relative tolerance: ||x_j − x_i| − L| ≤ tol · L after the position stage, and the
    /// relative speed along each rod ≤ tol × the largest speed after the velocity stage.
    pub tol: f64,
    /// Gauss–Seidel sweeps allowed per stage before the step fails.
    pub max_sweeps: usize,
}

impl Default for RattleSettings {
    fn default() -> Self {
        RattleSettings {
            tol: 1e-12,
            max_sweeps: 10_000,
        }
    }
}

/// RATTLE: velocity Verlet with SHAKE position and RATTLE velocity constraint stages.
#[derive(Debug, Default)]
pub struct Rattle {
    /// Constraint tolerances.
    pub settings: RattleSettings,
    /// Gauss–Seidel constraint sweeps made so far (both stages), for cost reports.
    pub sweeps: u64,
    a: Vec<Vec3>,
    vp: Vec<Vec3>,
    dir: Vec<Vec3>,
    power: f64,
    cached: bool,
}

impl Stepper for Rattle {
    fn check(&self, sys: &System) -> std::result::Result<(), String> {
        match sys.constraints.iter().position(|c| c.compliance > 0.0) {
            None => Ok(()),
            Some(k) => Err(format!(
                "constraint {k} is compliant (compliance {:e} m/N); rattle enforces rigid constraints only: model a soft rod as a [[spring]] or use verlet_constraints",
                sys.constraints[k].compliance
            )),
        }
    }
    fn reset(&mut self) {
        self.cached = false;
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        ensure_len(&mut self.a, n);
        ensure_len(&mut self.vp, n);
        ensure_len(&mut self.dir, sys.constraints.len());
        let mut evals = 0;
        if !self.cached {
            self.power = sys.accelerations(&s.x, &s.v, &mut self.a);
            evals += 1;
        }
        let p0 = self.power;
        for (d, c) in self.dir.iter_mut().zip(&sys.constraints) {
            *d = s.x[c.j] - s.x[c.i];
        }
        for p in 0..n {
            s.v[p] += self.a[p] * (0.5 * h);
            s.x[p] += s.v[p] * h;
        }
        let set = self.settings;
        let failed = |stage: &str| {
            Error::Step(format!(
                "rattle: the {stage} constraint iteration did not converge in {} sweeps",
                set.max_sweeps
            ))
        };
        let sweeps_before = self.sweeps;
        self.sweeps += positions(
            &sys.constraints,
            &self.dir,
            &sys.inv_mass,
            &mut s.x,
            &mut s.v,
            h,
            &set,
        )
        .map_err(|_| failed("position"))?;
        // Predicted end-of-step velocity for velocity-dependent forces (first order).
        for p in 0..n {
            self.vp[p] = s.v[p] + self.a[p] * (0.5 * h);
        }
        self.power = sys.accelerations(&s.x, &self.vp, &mut self.a);
        evals += 1;
        for p in 0..n {
            s.v[p] += self.a[p] * (0.5 * h);
        }
        let scale = s.v.iter().map(|v| v.amax()).fold(0.0, f64::max);
        self.sweeps += velocities(&sys.constraints, &sys.inv_mass, &s.x, &mut s.v, scale, &set)
            .map_err(|_| failed("velocity"))?;
        self.cached = true;
        s.t += h;
        Ok(StepStats {
            force_evals: evals,
            dissipated: 0.5 * h * (p0 + self.power),
            link_updates: (self.sweeps - sweeps_before) * sys.constraints.len() as u64,
            ..StepStats::default()
        })
    }
}
