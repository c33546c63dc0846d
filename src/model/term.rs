//! The force-term abstraction and the two simplest terms, gravity and linear drag.
//!
//! A scene's [`System`](super::System) holds only the terms it uses, so a scene without gravity
//! computes no gravity and a scene without drag pays nothing for it.

use super::jacobian::Jacobian;
use super::state::Vec3;
use nalgebra::Matrix3;

/// Which energy account a term's potential belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnergyKind {
    /// Gravitational potential energy.
    Gravity,
    /// Elastic energy of springs (and penalty contacts).
    Elastic,
    /// No potential: the term only dissipates (drag).
    None,
}

/// What a force term is: how backends and solvers tell terms apart (the name is for people).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TermKind {
    /// The scene's springs and dampers.
    Springs,
    /// Uniform gravity.
    Gravity,
    /// Linear air drag.
    Drag,
    /// Penalty contacts with obstacles.
    PenaltyContacts,
    /// A linear test mode (the stability theory's single-frequency system).
    LinearMode,
}

/// One term of the force model.
pub trait ForceTerm: Send + Sync + std::fmt::Debug {
    /// Short name shown by `springlab check`.
    fn name(&self) -> &'static str;
    /// What the term is, for code that treats terms differently.
    fn kind(&self) -> TermKind;
    /// The scene field that sets the term, named when the term makes a solve fail.
    fn field(&self) -> &'static str;
    /// Where the term's potential energy is accounted.
    fn energy_kind(&self) -> EnergyKind;
    /// Adds the term's forces (N) to `f`; returns the power it dissipates (W, ≥ 0).
    /// Must not allocate: it runs inside every step.
    fn add_forces(&self, x: &[Vec3], v: &[Vec3], f: &mut [Vec3]) -> f64;
    /// Potential energy (J) of the term at positions `x`.
    fn potential_energy(&self, _x: &[Vec3]) -> f64 {
        0.0
    }
    /// Adds ∂f/∂x and ∂f/∂v into `jac`, for implicit methods.
    fn add_jacobian(&self, _x: &[Vec3], _v: &[Vec3], _jac: &mut Jacobian) {}
}

/// Uniform gravity acting on every free particle: f = m g, U = -m g·x.
#[derive(Debug, Clone)]
pub struct Gravity {
    /// Acceleration in m/s².
    pub g: Vec3,
    /// Mass of each particle, 0 for fixed ones (they feel no force that could move them).
    pub mass: Vec<f64>,
}

impl ForceTerm for Gravity {
    fn name(&self) -> &'static str {
        "gravity"
    }
    fn kind(&self) -> TermKind {
        TermKind::Gravity
    }
    fn field(&self) -> &'static str {
        "world.gravity"
    }
    fn energy_kind(&self) -> EnergyKind {
        EnergyKind::Gravity
    }
    fn add_forces(&self, _x: &[Vec3], _v: &[Vec3], f: &mut [Vec3]) -> f64 {
        super::parallel::each_particle(f, |p, fi| *fi += self.g * self.mass[p]);
        0.0
    }
    fn potential_energy(&self, x: &[Vec3]) -> f64 {
        -x.iter()
            .zip(&self.mass)
            .map(|(xi, &m)| m * self.g.dot(xi))
            .sum::<f64>()
    }
}

/// Linear air drag on every particle: f = -c v, dissipating c |v|².
#[derive(Debug, Clone)]
pub struct Drag {
    /// Drag coefficient in kg/s.
    pub c: f64,
}

impl ForceTerm for Drag {
    fn name(&self) -> &'static str {
        "drag"
    }
    fn kind(&self) -> TermKind {
        TermKind::Drag
    }
    fn field(&self) -> &'static str {
        "world.drag"
    }
    fn energy_kind(&self) -> EnergyKind {
        EnergyKind::None
    }
    fn add_forces(&self, _x: &[Vec3], v: &[Vec3], f: &mut [Vec3]) -> f64 {
        let mut power = 0.0;
        for (fi, vi) in f.iter_mut().zip(v) {
            *fi -= vi * self.c;
            power += self.c * vi.norm_squared();
        }
        power
    }
    fn add_jacobian(&self, _x: &[Vec3], _v: &[Vec3], jac: &mut Jacobian) {
        for d in jac.diag_v.iter_mut() {
            *d -= Matrix3::identity() * self.c;
        }
    }
}
