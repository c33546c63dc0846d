//! Position Verlet with iterative constraint projection, the method games use for ropes and
//! cloth (Jakobsen, "Advanced Character Physics", GDC 2001), with XPBD compliance for soft
//! constraints (Macklin, Müller & Chentanev, "XPBD", MIG 2016).
//!
//! Per step: x* = x + h v + h² a(x, v) (Verlet with v = (x_n - x_{n-1})/h), then `iterations`
//! Gauss-Seidel sweeps over the distance constraints, then v = (x_{n+1} - x_n)/h.

use super::{ensure_len, StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System, Vec3};

/// Verlet + Jakobsen/XPBD projection; the only native method that honours constraints.
#[derive(Debug)]
pub struct VerletConstraints {
    /// Gauss-Seidel sweeps over the constraints per step.
    pub iterations: usize,
    a: Vec<Vec3>,
    x_old: Vec<Vec3>,
    lambda: Vec<f64>,
}

impl VerletConstraints {
    /// A stepper doing `iterations` projection sweeps per step.
    pub fn new(iterations: usize) -> Self {
        VerletConstraints {
            iterations,
            a: Vec::new(),
            x_old: Vec::new(),
            lambda: Vec::new(),
        }
    }
}

impl Default for VerletConstraints {
    fn default() -> Self {
        Self::new(20)
    }
}

impl Stepper for VerletConstraints {
    fn check(&self, _sys: &System) -> std::result::Result<(), String> {
        Ok(())
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        ensure_len(&mut self.a, n);
        ensure_len(&mut self.x_old, n);
        ensure_len(&mut self.lambda, sys.constraints.len());
        let power = sys.accelerations(&s.x, &s.v, &mut self.a);
        self.x_old.copy_from_slice(&s.x);
        for p in 0..n {
            s.x[p] += (s.v[p] + self.a[p] * h) * h;
        }
        self.lambda.iter_mut().for_each(|l| *l = 0.0);
        for _ in 0..self.iterations {
            for (c, lambda) in sys.constraints.iter().zip(self.lambda.iter_mut()) {
                let (wi, wj) = (sys.inv_mass[c.i], sys.inv_mass[c.j]);
                let d = s.x[c.j] - s.x[c.i];
                let len = d.norm();
                let alpha = c.compliance / (h * h);
                if len == 0.0 || wi + wj + alpha == 0.0 {
                    continue;
                }
                let n_dir = d / len;
                let dl = (-(len - c.length) - alpha * *lambda) / (wi + wj + alpha);
                *lambda += dl;
                s.x[c.i] -= n_dir * (wi * dl);
                s.x[c.j] += n_dir * (wj * dl);
            }
        }
        for p in 0..n {
            s.v[p] = (s.x[p] - self.x_old[p]) / h;
        }
        s.t += h;
        Ok(StepStats {
            force_evals: 1,
            dissipated: power * h,
            link_updates: (self.iterations * sys.constraints.len()) as u64,
            ..StepStats::default()
        })
    }
}
