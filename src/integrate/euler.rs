//! The two explicit Euler methods, which differ only in which velocity moves the positions.
//!
//! - Explicit (forward) Euler: x += h v_old, v += h a(x_old, v_old). Order 1; on an undamped
//!   oscillator the amplitude grows by √(1 + (hω)²) every step: unstable for every h.
//! - Symplectic (semi-implicit) Euler: v += h a(x, v), x += h v_new. Order 1, symplectic:
//!   the energy error stays bounded; stable on an undamped oscillator for hω < 2.

use super::{ensure_len, StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System, Vec3};

/// One Euler step; `kick_first` selects the symplectic variant.
fn euler_step(
    sys: &System,
    s: &mut State,
    h: f64,
    a: &mut Vec<Vec3>,
    kick_first: bool,
) -> StepStats {
    ensure_len(a, s.len());
    // Forces, not accelerations: 1/m is folded into the kick (one pass fewer per step).
    let power = sys.forces(&s.x, &s.v, a);
    let (f, w) = (&a[..], &sys.inv_mass[..]);
    crate::model::parallel::each_particle2(&mut s.x, &mut s.v, |p, x, v| {
        if kick_first {
            *v += f[p] * (w[p] * h);
            *x += *v * h;
        } else {
            *x += *v * h;
            *v += f[p] * (w[p] * h);
        }
    });
    s.t += h;
    StepStats {
        force_evals: 1,
        dissipated: power * h,
        ..StepStats::default()
    }
}

/// Forward Euler: forces and velocities at the old state.
#[derive(Debug, Default)]
pub struct ExplicitEuler {
    a: Vec<Vec3>,
}

impl Stepper for ExplicitEuler {
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        Ok(euler_step(sys, s, h, &mut self.a, false))
    }
}

/// Symplectic Euler: kick, then drift with the new velocity.
#[derive(Debug, Default)]
pub struct SymplecticEuler {
    a: Vec<Vec3>,
}

impl Stepper for SymplecticEuler {
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        Ok(euler_step(sys, s, h, &mut self.a, true))
    }
}
