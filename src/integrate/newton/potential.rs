//! The incremental potential of a backward-Euler stage, the line search's fallback merit when
//! a clamped Newton direction raises the residual.

use crate::model::{System, Vec3};

/// Scratch for [`potential`].
#[derive(Debug, Default)]
pub(super) struct PotentialScratch {
    /// x̂ + β v' at the trial.
    pub(super) x_new: Vec<Vec3>,
    /// Positions at which the damping directions are frozen (the line search's base).
    pub(super) x_frozen: Vec<Vec3>,
    /// Force output of the dissipated-power evaluation (unused).
    pub(super) f: Vec<Vec3>,
}

/// The stage's incremental potential Φ(v') = ½ Σ m|v' − v̂|² + U(x̂ + β v') + ½ β P(x_k, v'),
/// with the dissipated power P, a quadratic form in v' for springlab's linear dampers,
/// evaluated with damping directions frozen at the line search's base x_k: its v'-gradient
/// at the base is exactly the residual G, so a clamped Newton direction descends on it.
pub(super) fn potential(
    sys: &System,
    x0: &[Vec3],
    v0: &[Vec3],
    v: &[Vec3],
    h: f64,
    w: &mut PotentialScratch,
) -> f64 {
    let mut kin = 0.0;
    for p in 0..x0.len() {
        w.x_new[p] = x0[p] + v[p] * h;
        if sys.free[p] {
            kin += 0.5 * sys.mass[p] * (v[p] - v0[p]).norm_squared();
        }
    }
    let e = sys.energy(&w.x_new, v);
    let power = sys.forces(&w.x_frozen, v, &mut w.f);
    kin + e.gravity + e.elastic + 0.5 * h * power
}
