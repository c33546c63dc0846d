//! Linear momentum of a free system in the backward-Euler stage.
//!
//! Where every particle is free and the only forces are springs (pairwise, so they depend on
//! differences of positions and velocities only) and uniform gravity, a uniform velocity shift
//! c moves x' = x̂ + βv' rigidly and leaves every force as it is, so the stage residual
//! G(v') = M (v' − v̂) − β f(x', v') changes by exactly M c. Its sum ΣG = P' − P̂ − β Σf is the
//! stage's momentum balance, and c = −ΣG / Σm zeroes it: an exact Newton step in the
//! translations, which also lowers GᵀM⁻¹G by |ΣG|²/Σm (and the incremental potential, which
//! is quadratic along a translation with Hessian Σm). Inexact linear solves do not keep ΣG at
//! zero (block Jacobi weights particles of unequal mass unequally), so every iterate is
//! shifted: the stage then keeps linear momentum to round-off whatever its tolerance.

use super::Newton;
use crate::model::{System, Vec3};

impl Newton {
    /// Shifts the iterate v' (and x' = x̂ + βv') by the uniform c = −ΣG/Σm that zeroes the
    /// stage's momentum balance, given the forces `self.f` at the iterate (unchanged by the
    /// shift on a translation-invariant system). `total_mass`: Σm over the particles.
    pub(super) fn balance_momentum(&mut self, sys: &System, v0: &[Vec3], h: f64, total_mass: f64) {
        let mut unbalanced = Vec3::zeros();
        for p in 0..v0.len() {
            unbalanced += (self.vn[p] - v0[p]) * sys.mass[p] - self.f[p] * h;
        }
        let c = -unbalanced / total_mass;
        for p in 0..v0.len() {
            self.vn[p] += c;
            self.xn[p] += c * h;
        }
    }
}
