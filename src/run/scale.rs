//! The scene's energy scale: how much energy the scene can physically move around, from its
//! own lengths, masses, speeds and gravity. [`super::verdict`] calls a run unstable once its
//! energy balance rises by more than a multiple of it.

use crate::model::{State, System};

/// The scene's characteristic length (m): the largest of the initial bounding-box diagonal,
/// the springs' rest lengths, the constraints' lengths and the particles' diameters; when all
/// of these are 0 (a lone point particle), the smallest finite obstacle size (a plane has
/// none). 0 when the scene has no length at all.
pub fn characteristic_length(sys: &System, s0: &State) -> f64 {
    let first = s0.x.first().copied().unwrap_or_default();
    let (mut lo, mut hi) = (first, first);
    for x in &s0.x {
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    let mut len = (hi - lo).norm();
    let sp = &sys.springs;
    for s in 0..sp.len() {
        len = len.max(sp.l0[s]);
    }
    for c in &sys.constraints {
        len = len.max(c.length);
    }
    for r in &sys.radius {
        len = len.max(2.0 * r);
    }
    if len > 0.0 {
        return len;
    }
    crate::collide::of(sys)
        .map(|c| {
            c.set
                .obstacles()
                .iter()
                .map(|o| {
                    let e = o.shape.compute_local_aabb().extents();
                    (e.x * e.x + e.y * e.y + e.z * e.z).sqrt()
                })
                .filter(|d| d.is_finite() && *d > 0.0 && *d < 1e12)
                .fold(f64::INFINITY, f64::min)
        })
        .filter(|d| d.is_finite())
        .unwrap_or(0.0)
}

/// The scene's energy scale (J) over a run of `horizon` seconds:
/// |E₀ terms| + Σ m (|g|·L + ½ (|v₀| + Σ|Δv|)²), with L the
/// [`characteristic_length`]. A scene without any length (a point particle on a plane) uses
/// the distance it would fall freely over the run, L = ½|g|·horizon². A physical run never
/// raises its energy balance, so a rise of a multiple of this scale is a numerical blow-up.
/// Only a scene with no energy, no gravity, no speed and no kicks has scale 0; it is floored
/// at 1e-12 J per kg of free mass (nothing moves there, so round-off is all there is).
pub fn energy_scale(sys: &System, s0: &State, horizon: f64) -> f64 {
    let e = sys.state_energy(s0);
    let mut scale = e.kinetic.abs() + e.gravity.abs() + e.elastic.abs();
    let g = sys.gravity.map_or(0.0, |g| g.norm());
    let mut len = characteristic_length(sys, s0);
    if len == 0.0 {
        len = 0.5 * g * horizon * horizon;
    }
    for p in (0..sys.len()).filter(|&p| sys.free[p]) {
        let kicks: f64 = sys
            .impulses
            .iter()
            .filter(|im| im.particle == p)
            .map(|im| im.delta_v.norm())
            .sum();
        let speed = s0.v[p].norm() + kicks;
        scale += sys.mass[p] * (g * len + 0.5 * speed * speed);
    }
    let free_mass: f64 = (0..sys.len())
        .filter(|&p| sys.free[p])
        .map(|p| sys.mass[p])
        .sum();
    scale.max(1e-12 * free_mass)
}
