//! The incremental potential of a backward-Euler stage: the line search's merit, whose
//! gradient is the stage's residual.

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
/// at the base is exactly the residual G, so every descent direction of the Newton solve
/// descends on it. Returns Φ and its round-off: 8ε √(terms) times the sum of its parts'
/// magnitudes (gravity's term by term) plus the forces times the positions' own rounding,
/// below which two values of Φ cannot be told apart.
pub(super) fn potential(
    sys: &System,
    x0: &[Vec3],
    v0: &[Vec3],
    v: &[Vec3],
    h: f64,
    w: &mut PotentialScratch,
) -> (f64, f64) {
    let mut kin = 0.0;
    let mut lift = 0.0;
    let g = sys.gravity.unwrap_or_else(Vec3::zeros);
    for p in 0..x0.len() {
        w.x_new[p] = x0[p] + v[p] * h;
        if sys.free[p] {
            kin += 0.5 * sys.mass[p] * (v[p] - v0[p]).norm_squared();
            lift += sys.mass[p] * g.dot(&w.x_new[p]).abs();
        }
    }
    let e = sys.energy(&w.x_new, v);
    let power = sys.forces(&w.x_frozen, v, &mut w.f);
    let value = kin + e.gravity + e.elastic + 0.5 * h * power;
    // Positions are stored to ε|x|: moving a particle by one rounding changes U by up to
    // |f|·ε|x|, however small U itself is (a spring near rest far from the origin).
    let jiggle: f64 = (0..x0.len())
        .filter(|&p| sys.free[p])
        .map(|p| w.f[p].abs().sum() * w.x_new[p].amax())
        .sum();
    let terms = (x0.len() + sys.springs.len()) as f64;
    let parts = kin + lift + e.elastic + 0.5 * h * power.abs();
    let noise = 8.0 * f64::EPSILON * (terms.sqrt() * parts + jiggle);
    (value, noise)
}
