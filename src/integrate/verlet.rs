//! Störmer-Verlet in its two usual forms. Both are second order, symplectic for conservative
//! forces, and stable on an undamped oscillator for hω < 2 (Hairer, Lubich & Wanner,
//! *Geometric Numerical Integration*, §I.1.4).
//!
//! Velocity-dependent forces (dampers, drag) are evaluated at a first-order predicted velocity,
//! which keeps the global order 2 (the predictor's O(h²) error enters multiplied by h).

use super::{ensure_len, StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System, Vec3};

/// Velocity Verlet (kick-drift-kick), one force evaluation per step after the first.
#[derive(Debug, Default)]
pub struct VelocityVerlet {
    a: Vec<Vec3>,
    vp: Vec<Vec3>,
    power: f64,
    cached: bool,
}

impl Stepper for VelocityVerlet {
    fn reset(&mut self) {
        self.cached = false;
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        ensure_len(&mut self.a, n);
        ensure_len(&mut self.vp, n);
        let mut evals = 0;
        if !self.cached {
            self.power = sys.accelerations(&s.x, &s.v, &mut self.a);
            evals += 1;
        }
        let p0 = self.power;
        for p in 0..n {
            self.vp[p] = s.v[p] + self.a[p] * h; // predictor for velocity-dependent forces
            s.v[p] += self.a[p] * (0.5 * h);
            s.x[p] += s.v[p] * h;
        }
        self.power = sys.accelerations(&s.x, &self.vp, &mut self.a);
        evals += 1;
        for p in 0..n {
            s.v[p] += self.a[p] * (0.5 * h);
        }
        self.cached = true;
        s.t += h;
        Ok(StepStats {
            force_evals: evals,
            dissipated: 0.5 * h * (p0 + self.power),
            ..StepStats::default()
        })
    }
}

/// Position Verlet in Störmer's two-step form x_{n+1} = 2x_n - x_{n-1} + h² a_n, started with
/// the second-order step x_1 = x_0 + h v_0 + h²/2 a_0. Velocities are reconstructed to second
/// order as v_{n+1} = (x_{n+1} - x_n)/h + h/2 a_{n+1}. A change of step size restarts it.
#[derive(Debug, Default)]
pub struct PositionVerlet {
    a: Vec<Vec3>,
    x_prev: Vec<Vec3>,
    vp: Vec<Vec3>,
    power: f64,
    h_prev: Option<f64>,
}

impl Stepper for PositionVerlet {
    fn reset(&mut self) {
        self.h_prev = None;
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        ensure_len(&mut self.a, n);
        ensure_len(&mut self.x_prev, n);
        ensure_len(&mut self.vp, n);
        let mut evals = 0;
        let restart = self.h_prev != Some(h);
        if restart {
            self.power = sys.accelerations(&s.x, &s.v, &mut self.a);
            evals += 1;
        }
        let p0 = self.power;
        for p in 0..n {
            let x_new = if restart {
                s.x[p] + s.v[p] * h + self.a[p] * (0.5 * h * h)
            } else {
                s.x[p] * 2.0 - self.x_prev[p] + self.a[p] * (h * h)
            };
            self.x_prev[p] = s.x[p];
            s.x[p] = x_new;
            // Predicted velocity for velocity-dependent forces at the new position.
            self.vp[p] = (x_new - self.x_prev[p]) / h + self.a[p] * (0.5 * h);
        }
        self.power = sys.accelerations(&s.x, &self.vp, &mut self.a);
        evals += 1;
        for p in 0..n {
            s.v[p] = (s.x[p] - self.x_prev[p]) / h + self.a[p] * (0.5 * h);
        }
        self.h_prev = Some(h);
        s.t += h;
        Ok(StepStats {
            force_evals: evals,
            dissipated: 0.5 * h * (p0 + self.power),
            ..StepStats::default()
        })
    }
}
