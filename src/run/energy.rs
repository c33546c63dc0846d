//! The energy account of a run, term by term.

use crate::model::Energy;
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
    /// Energy the contact stage created since t = 0 (≥ 0; e.g. pushing a particle out of an
    /// obstacle against gravity or a spring). Informational: it is already in the mechanical
    /// terms, so `total` rises by it and the verdict counts it as a gain.
    pub created: f64,
    /// kinetic + gravity + elastic + dissipated − injected: constant for the exact solution,
    /// so its change is the method's energy error in conservative and dissipative scenes.
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
            created: 0.0,
            total: e.mechanical() + dissipated - injected,
        }
    }
    /// The same record with `created` (J) booked as energy a contact stage created.
    pub fn with_created(mut self, created: f64) -> Self {
        self.created = created;
        self
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
            self.created,
            self.total,
        ]
        .iter()
        .all(|v| v.is_finite())
    }
}
