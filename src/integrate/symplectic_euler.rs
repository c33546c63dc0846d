//! Symplectic (semi-implicit) Euler: kick then drift. Order 1, symplectic: energy error stays
//! bounded; stable on an undamped oscillator for hω < 2.

use super::{ensure_len, Integrator, StepStats};
use crate::error::Result;
use crate::model::{State, System, Vec3};

/// v += h a(x, v); x += h v_new.
#[derive(Debug, Default)]
pub struct SymplecticEuler {
    a: Vec<Vec3>,
}

impl Integrator for SymplecticEuler {
    fn name(&self) -> &str {
        "symplectic_euler"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        ensure_len(&mut self.a, s.len());
        let power = sys.accelerations(&s.x, &s.v, &mut self.a);
        for ((x, v), a) in s.x.iter_mut().zip(s.v.iter_mut()).zip(&self.a) {
            *v += a * h;
            *x += *v * h;
        }
        s.t += h;
        Ok(StepStats {
            force_evals: 1,
            dissipated: power * h,
        })
    }
}
