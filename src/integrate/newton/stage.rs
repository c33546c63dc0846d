//! One backward-Euler stage as the Newton iteration sees it: the stage's data and the
//! constants derived once from them.

use super::max_abs;
use crate::model::{System, Vec3};

/// A backward-Euler stage being solved: the system, the base state (x̂, v̂) and the step β,
/// with the constants every Newton iteration reads (the base's velocity scale, the updates'
/// round-off floor, the free mass of the RMS norms and the error-based stop's κ). The
/// residual, the stop tests and the line search all read them together.
pub(super) struct Stage<'a> {
    /// The system.
    pub(super) sys: &'a System,
    /// Base positions x̂.
    pub(super) x0: &'a [Vec3],
    /// Base velocities v̂.
    pub(super) v0: &'a [Vec3],
    /// The stage's step β.
    pub(super) h: f64,
    /// max |v̂|, part of every relative tolerance's velocity scale.
    pub(super) v_scale0: f64,
    /// Round-off floor of an update: positions carry ε|x| absolute error, i.e. ε|x|/h in
    /// velocity.
    pub(super) x_floor: f64,
    /// Mass of the free particles (1 where there is none), the weight of the RMS norms.
    pub(super) free_mass: f64,
    /// The error-based stop's fraction of the first-order estimate (κ or κ², by order).
    pub(super) kappa: f64,
}

impl<'a> Stage<'a> {
    /// The stage from (`x0`, `v0`) with step `h` on `sys`, stopping at `kappa` × its error
    /// estimate.
    pub(super) fn new(sys: &'a System, x0: &'a [Vec3], v0: &'a [Vec3], h: f64, kappa: f64) -> Self {
        let n = x0.len();
        let v_scale0 = max_abs(v0);
        let x_floor = 16.0 * f64::EPSILON * max_abs(x0) / h;
        let free_mass: f64 = (0..n).filter(|&p| sys.free[p]).map(|p| sys.mass[p]).sum();
        let free_mass = if free_mass > 0.0 { free_mass } else { 1.0 };
        Stage {
            sys,
            x0,
            v0,
            h,
            v_scale0,
            x_floor,
            free_mass,
            kappa,
        }
    }
}
