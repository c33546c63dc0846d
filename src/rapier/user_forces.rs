//! Force terms Rapier has no model for, applied the way a game programmer adds a custom force
//! to a Rapier body: evaluated from the bodies' state at the start of each Rapier step and held
//! (as a user force) over that step and its solver substeps.
//!
//! Today that is springlab's penalty contact (`penalty_contacts`): with it the scene's
//! obstacles are not Rapier colliders (the penalty spring is the contact), so Rapier runs the
//! same contact model as the native methods, integrated with the force frozen over the frame:
//! explicit in the contact, like symplectic Euler, and stable only while h·√(k/m) stays below
//! about 2.

use super::convert::{to_glam, to_na};
use crate::model::{ForceTerm, System, Vec3};
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet};

/// Names of the force terms this module applies.
pub const USER_FORCE_TERMS: [&str; 1] = ["penalty_contacts"];

/// Whether the term called `name` is applied as a user force.
pub fn is_user_force(name: &str) -> bool {
    USER_FORCE_TERMS.contains(&name)
}

/// Whether `sys` carries a term applied as a user force (its obstacles are then not Rapier
/// colliders: the term is the contact).
pub fn any(sys: &System) -> bool {
    sys.terms.iter().any(|t| is_user_force(t.name()))
}

/// Scratch of the user forces (allocated once per world).
#[derive(Debug, Default)]
pub struct UserForces {
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    f: Vec<Vec3>,
}

impl UserForces {
    fn terms(sys: &System) -> impl Iterator<Item = &dyn ForceTerm> {
        sys.terms
            .iter()
            .filter(|t| is_user_force(t.name()))
            .map(|t| t.as_ref())
    }

    /// Power (W) the user-force terms dissipate at (x, v).
    pub fn power(&mut self, sys: &System, x: &[Vec3], v: &[Vec3]) -> f64 {
        if !any(sys) {
            return 0.0;
        }
        self.f.clear();
        self.f.resize(x.len(), Vec3::zeros());
        Self::terms(sys)
            .map(|t| t.add_forces(x, v, &mut self.f))
            .sum()
    }

    /// Sets every free body's user force to the terms' force at its current state (replacing
    /// the previous step's); a no-op for a scene without such terms.
    pub fn apply(&mut self, sys: &System, bodies: &[RigidBodyHandle], set: &mut RigidBodySet) {
        if !any(sys) {
            return;
        }
        self.x.clear();
        self.v.clear();
        for &h in bodies {
            let rb = &set[h];
            self.x.push(to_na(rb.translation()));
            self.v.push(to_na(rb.linvel()));
        }
        self.f.clear();
        self.f.resize(self.x.len(), Vec3::zeros());
        for t in Self::terms(sys) {
            t.add_forces(&self.x, &self.v, &mut self.f);
        }
        for (p, &h) in bodies.iter().enumerate() {
            if sys.free[p] {
                let rb = &mut set[h];
                rb.reset_forces(false);
                rb.add_force(to_glam(&self.f[p]), true);
            }
        }
    }
}
