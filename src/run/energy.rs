//! The energy account of a run, term by term.

use crate::model::{Energy, State, System};
use serde::Serialize;

/// Energy terms at one instant plus the work accounts (J); one row of `energy.csv`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct EnergyRecord {
    /// Translational kinetic energy.
    pub kinetic: f64,
    /// Gravitational potential energy.
    pub gravity: f64,
    /// Elastic energy.
    pub elastic: f64,
    /// Work done against dampers and drag since t = 0 (≥ 0).
    pub dissipated: f64,
    /// Energy injected by impulses since t = 0.
    pub injected: f64,
    /// kinetic + gravity + elastic + dissipated − injected: constant for the exact solution,
    /// so its change is the integrator's energy error in conservative and dissipative scenes.
    pub total: f64,
}

impl EnergyRecord {
    /// Builds the record from the instantaneous terms and the work accounts.
    pub fn new(e: Energy, dissipated: f64, injected: f64) -> Self {
        EnergyRecord {
            kinetic: e.kinetic,
            gravity: e.gravity,
            elastic: e.elastic,
            dissipated,
            injected,
            total: e.mechanical() + dissipated - injected,
        }
    }
    /// Kinetic + potential energy.
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.gravity + self.elastic
    }
    /// True when every field is finite.
    pub fn is_finite(&self) -> bool {
        [
            self.kinetic,
            self.gravity,
            self.elastic,
            self.dissipated,
            self.injected,
            self.total,
        ]
        .iter()
        .all(|v| v.is_finite())
    }
}

/// The scene's energy scale (J): |E₀ terms| + Σ m (|g|·D + ½ (|v₀| + Σ|Δv|)²), D the initial
/// bounding-box diagonal. A physical run never gains mechanical energy beyond what impulses
/// inject, so a gain of many times this scale is a numerical blow-up. Floored at 1e-12 J per
/// kg of free mass, so a scene at rest does not call round-off a blow-up.
pub fn energy_scale(sys: &System, s0: &State) -> f64 {
    let e = sys.state_energy(s0);
    let mut scale = e.kinetic.abs() + e.gravity.abs() + e.elastic.abs();
    let (mut lo, mut hi) = (
        s0.x.first().copied().unwrap_or_default(),
        s0.x.first().copied().unwrap_or_default(),
    );
    for x in &s0.x {
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    let diam = (hi - lo).norm();
    let g = sys.gravity.map_or(0.0, |g| g.norm());
    for p in (0..sys.len()).filter(|&p| sys.free[p]) {
        let kicks: f64 = sys
            .impulses
            .iter()
            .filter(|im| im.particle == p)
            .map(|im| im.delta_v.norm())
            .sum();
        let speed = s0.v[p].norm() + kicks;
        scale += sys.mass[p] * (g * diam + 0.5 * speed * speed);
    }
    let free_mass: f64 = (0..sys.len())
        .filter(|&p| sys.free[p])
        .map(|p| sys.mass[p])
        .sum();
    scale.max(1e-12 * free_mass)
}
