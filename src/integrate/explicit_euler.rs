//! Explicit (forward) Euler: forces at the old state. Order 1; on an undamped oscillator the
//! amplitude grows by √(1 + (hω)²) every step, so it is unstable for every step size.

use super::{ensure_len, Integrator, StepStats};
use crate::error::Result;
use crate::model::{State, System, Vec3};

/// x += h v_old, v += h a(x_old, v_old).
#[derive(Debug, Default)]
pub struct ExplicitEuler {
    a: Vec<Vec3>,
}

impl Integrator for ExplicitEuler {
    fn name(&self) -> &str {
        "explicit_euler"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        ensure_len(&mut self.a, s.len());
        let power = sys.accelerations(&s.x, &s.v, &mut self.a);
        for ((x, v), a) in s.x.iter_mut().zip(s.v.iter_mut()).zip(&self.a) {
            *x += *v * h;
            *v += a * h;
        }
        s.t += h;
        Ok(StepStats {
            force_evals: 1,
            dissipated: power * h,
        })
    }
}
