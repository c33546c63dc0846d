//! The simulated system: masses, the active force terms, constraints and impulses.

use super::jacobian::Jacobian;
use super::springs::Springs;
use super::state::{State, Vec3};
use super::term::{EnergyKind, ForceTerm};

/// A rigid distance constraint |x_j - x_i| = length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceConstraint {
    /// First particle.
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Rod length in m.
    pub length: f64,
    /// XPBD compliance in m/N (0: rigid).
    pub compliance: f64,
}

impl DistanceConstraint {
    /// Elastic energy (J): a compliant constraint (XPBD compliance α > 0) is a spring of
    /// stiffness 1/α at its length, storing ½·stretch²/α; a rigid one stores none.
    pub fn energy(&self, x: &[Vec3]) -> f64 {
        if self.compliance > 0.0 {
            let stretch = (x[self.j] - x[self.i]).norm() - self.length;
            0.5 * stretch * stretch / self.compliance
        } else {
            0.0
        }
    }
}

/// An instantaneous velocity change of one particle at a given time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impulse {
    /// Time in s.
    pub time: f64,
    /// Particle index.
    pub particle: usize,
    /// Velocity change in m/s.
    pub delta_v: Vec3,
}

/// Energy terms at one instant (J).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Energy {
    /// Translational kinetic energy ½ Σ m |v|².
    pub kinetic: f64,
    /// Gravitational potential energy.
    pub gravity: f64,
    /// Elastic energy of springs, compliant constraints (½·stretch²/compliance) and penalty
    /// contacts.
    pub elastic: f64,
}

impl Energy {
    /// Kinetic + potential energy.
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.gravity + self.elastic
    }
}

/// A particle system ready to integrate: only the terms the scene uses are present.
#[derive(Debug)]
pub struct System {
    /// Mass of each particle in kg (as given, also for fixed ones).
    pub mass: Vec<f64>,
    /// 1/m for free particles, 0 for fixed ones.
    pub inv_mass: Vec<f64>,
    /// `true` for particles that move.
    pub free: Vec<bool>,
    /// Collision radius per particle in m.
    pub radius: Vec<f64>,
    /// Springs (also present, in `terms`, as a force term when non-empty).
    pub springs: Springs,
    /// Uniform gravity, if the scene has it.
    pub gravity: Option<Vec3>,
    /// Linear drag coefficient, if the scene has it.
    pub drag: Option<f64>,
    /// Rigid distance constraints.
    pub constraints: Vec<DistanceConstraint>,
    /// Impulses sorted by time.
    pub impulses: Vec<Impulse>,
    /// When the impulses take effect relative to a run's frames (`[run] events`).
    pub events: super::Events,
    /// Active force terms other than the springs (gravity, drag, contacts...).
    pub terms: Vec<Box<dyn ForceTerm>>,
    /// Post-step stage (the contact stage), present only when the scene has obstacles: the
    /// runner calls it after every accepted step. `None` means no collision work at all.
    pub post_step: Option<Box<dyn super::PostStep>>,
}

impl System {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.mass.len()
    }
    /// True when the system has no particles.
    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }

    /// Names of the active force terms, in evaluation order (springs first), plus
    /// "constraints" and "impulses" when present.
    pub fn active_terms(&self) -> Vec<&'static str> {
        let mut names = Vec::new();
        if !self.springs.is_empty() {
            names.push(self.springs.name());
        }
        names.extend(self.terms.iter().map(|t| t.name()));
        if !self.constraints.is_empty() {
            names.push("constraints");
        }
        if !self.impulses.is_empty() {
            names.push("impulses");
        }
        if let Some(name) = self.post_step.as_ref().and_then(|c| c.name()) {
            names.push(name);
        }
        names
    }

    /// The force term with the largest acceleration on a free particle at (`x`, `v`): its name,
    /// the scene field that sets it and that acceleration (m/s²). For messages when a solve
    /// fails: it names what the user would change. None without free particles or terms.
    pub fn dominant_term(
        &self,
        x: &[Vec3],
        v: &[Vec3],
    ) -> Option<(&'static str, &'static str, f64)> {
        let springs: Option<&dyn ForceTerm> =
            (!self.springs.is_empty()).then_some(&self.springs as &dyn ForceTerm);
        let mut f = vec![Vec3::zeros(); self.len()];
        springs
            .into_iter()
            .chain(self.terms.iter().map(|t| t.as_ref()))
            .map(|t| {
                f.iter_mut().for_each(|fi| *fi = Vec3::zeros());
                t.add_forces(x, v, &mut f);
                let a = (0..self.len())
                    .filter(|&p| self.free[p])
                    .map(|p| f[p].amax() * self.inv_mass[p])
                    .fold(0.0, f64::max);
                (t.name(), t.field(), a)
            })
            .max_by(|a, b| a.2.total_cmp(&b.2))
    }

    /// Writes the total force on every particle into `f`; returns the dissipated power (W).
    pub fn forces(&self, x: &[Vec3], v: &[Vec3], f: &mut [Vec3]) -> f64 {
        super::parallel::each_particle(f, |_, fi| *fi = Vec3::zeros());
        let mut power = 0.0;
        if !self.springs.is_empty() {
            power += self.springs.add_forces(x, v, f);
        }
        for t in &self.terms {
            power += t.add_forces(x, v, f);
        }
        power
    }

    /// Writes accelerations (0 for fixed particles) into `a`; returns the dissipated power (W).
    /// This is "one force evaluation" in every cost count.
    pub fn accelerations(&self, x: &[Vec3], v: &[Vec3], a: &mut [Vec3]) -> f64 {
        let power = self.forces(x, v, a);
        super::parallel::each_particle(a, |p, ai| *ai *= self.inv_mass[p]);
        power
    }

    /// Kinetic, gravitational and elastic energy of a state.
    pub fn energy(&self, x: &[Vec3], v: &[Vec3]) -> Energy {
        let kinetic = 0.5
            * v.iter()
                .zip(&self.mass)
                .zip(&self.free)
                .filter(|(_, &f)| f)
                .map(|((vi, &m), _)| m * vi.norm_squared())
                .sum::<f64>();
        let mut e = Energy {
            kinetic,
            gravity: 0.0,
            elastic: 0.0,
        };
        if !self.springs.is_empty() {
            e.elastic += self.springs.potential_energy(x);
        }
        for c in &self.constraints {
            e.elastic += c.energy(x);
        }
        for t in &self.terms {
            match t.energy_kind() {
                EnergyKind::Gravity => e.gravity += t.potential_energy(x),
                EnergyKind::Elastic => e.elastic += t.potential_energy(x),
                EnergyKind::None => {}
            }
        }
        e
    }

    /// The part of the elastic energy that moving particle `p` alone changes: the springs and
    /// compliant constraints at `p`, plus elastic force terms (penalty contacts) in full. A
    /// post-step stage that moves particles one at a time books each move's elastic change as
    /// the difference of this before and after it; the moves' changes sum to the total's.
    pub fn elastic_at(&self, p: usize, x: &[Vec3]) -> f64 {
        let mut e = 0.0;
        if !self.springs.is_empty() {
            e += self.springs.energy_at(p, x);
        }
        for c in self.constraints.iter().filter(|c| c.i == p || c.j == p) {
            e += c.energy(x);
        }
        for t in self.terms.iter() {
            if t.energy_kind() == EnergyKind::Elastic {
                e += t.potential_energy(x);
            }
        }
        e
    }

    /// Energy of a [`State`].
    pub fn state_energy(&self, s: &State) -> Energy {
        self.energy(&s.x, &s.v)
    }

    /// A zero Jacobian with this system's pair topology.
    pub fn new_jacobian(&self) -> Jacobian {
        let pairs = self
            .springs
            .i
            .iter()
            .zip(&self.springs.j)
            .map(|(&a, &b)| [a, b])
            .collect();
        Jacobian::with_owners(self.len(), pairs, self.springs.owner_lists(self.len()))
    }

    /// Fills `jac` at (x, v), dropping the fraction `clamp` of compressed springs' indefinite
    /// stiffness ([`Jacobian::clamp`]), and prepares the Newton matrix of step `h`
    /// (M(1 + `jac.shift`) − h ∂f/∂v − h² ∂f/∂x): what every implicit solve takes its matrix from.
    pub fn newton_matrix(&self, x: &[Vec3], v: &[Vec3], h: f64, clamp: f64, jac: &mut Jacobian) {
        jac.clamp = clamp;
        self.jacobian(x, v, jac);
        jac.prepare_newton(&self.mass, &self.free, h);
    }

    /// Fills `jac` with ∂f/∂x and ∂f/∂v at (x, v).
    pub fn jacobian(&self, x: &[Vec3], v: &[Vec3], jac: &mut Jacobian) {
        jac.clear();
        if !self.springs.is_empty() {
            self.springs.add_jacobian(x, v, jac);
        }
        for t in &self.terms {
            t.add_jacobian(x, v, jac);
        }
    }

    /// Total linear momentum Σ m v of the free particles (kg·m/s).
    pub fn momentum(&self, v: &[Vec3]) -> Vec3 {
        v.iter()
            .zip(&self.mass)
            .zip(&self.free)
            .filter(|(_, &f)| f)
            .map(|((vi, &m), _)| vi * m)
            .sum()
    }

    /// Largest |violation| of the distance constraints at `x` (m), 0 without constraints.
    pub fn constraint_violation(&self, x: &[Vec3]) -> f64 {
        self.constraints
            .iter()
            .map(|c| ((x[c.j] - x[c.i]).norm() - c.length).abs())
            .fold(0.0, f64::max)
    }
}
