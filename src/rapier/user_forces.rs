//! Force terms Rapier has no model for, applied the way a game programmer adds a custom force
//! to a Rapier body: evaluated from the bodies' state at the start of each Rapier step and held
//! (as a user force) over that step and its solver substeps.
//!
//! Two such forces. Springlab's penalty contact (`penalty_contacts`): with it the scene's
//! obstacles are not Rapier colliders (the penalty spring is the contact), so Rapier runs the
//! same contact model as the native methods, integrated with the force frozen over the frame:
//! explicit in the contact, like symplectic Euler, and stable only while h·√(k/m) stays below
//! about 2.
//!
//! And the scene's drag on the particles that are multibody links: Rapier applies a body's
//! linear damping only to bodies outside multibodies (a link's velocity comes from the
//! multibody's generalized coordinates, whose damping is per joint axis, not per body). The
//! held force is −c·v/(1 + h·c/m) with v the velocity at the start of the step: on a free
//! body it gives v ← v/(1 + h·c/m) over the step, exactly the implicit law of Rapier's own
//! linear damping c/m on the other bodies, stable at any h. Helper bodies (spring pivots)
//! carry no drag.

use super::convert::{to_glam, to_na};
use crate::model::{ForceTerm, System, TermKind, Vec3};
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet};

/// The kinds of force term this module applies.
pub const USER_FORCE_TERMS: [TermKind; 1] = [TermKind::PenaltyContacts];

/// Whether a term of kind `kind` is applied as a user force.
pub fn is_user_force(kind: TermKind) -> bool {
    USER_FORCE_TERMS.contains(&kind)
}

/// Whether `sys` carries a term applied as a user force (its obstacles are then not Rapier
/// colliders: the term is the contact).
pub fn any(sys: &System) -> bool {
    sys.terms.iter().any(|t| is_user_force(t.kind()))
}

/// Scratch of the user forces (allocated once per world).
#[derive(Debug, Default)]
pub struct UserForces {
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    f: Vec<Vec3>,
    /// The held drag of the current step per particle (empty without drag on links).
    drag: Vec<Vec3>,
}

impl UserForces {
    fn terms(sys: &System) -> impl Iterator<Item = &dyn ForceTerm> {
        sys.terms
            .iter()
            .filter(|t| is_user_force(t.kind()))
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

    /// Sets every free body's user force to the terms' force at its current state, plus the
    /// held drag on the bodies `linked` marks (multibody links), for a Rapier step of `h`
    /// (replacing the previous step's); a no-op for a scene without such forces.
    pub fn apply(
        &mut self,
        sys: &System,
        bodies: &[RigidBodyHandle],
        linked: &[bool],
        set: &mut RigidBodySet,
        h: f64,
    ) {
        let drag = sys.drag.filter(|_| linked.iter().any(|&l| l));
        self.drag.clear();
        if !any(sys) && drag.is_none() {
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
        if let Some(c) = drag {
            self.drag.resize(self.x.len(), Vec3::zeros());
            for (p, _) in linked.iter().enumerate().filter(|(_, &l)| l) {
                self.drag[p] = -self.v[p] * (c / (1.0 + h * c / sys.mass[p]));
                self.f[p] += self.drag[p];
            }
        }
        for (p, &h) in bodies.iter().enumerate() {
            if sys.free[p] {
                let rb = &mut set[h];
                rb.reset_forces(false);
                rb.add_force(to_glam(&self.f[p]), true);
            }
        }
    }

    /// Energy (J) the held drag has taken from the motion since the last [`Self::apply`]:
    /// −Σ f·Δx over the bodies' displacements, the work of a force held constant over the step.
    pub fn drag_dissipated(&self, bodies: &[RigidBodyHandle], set: &RigidBodySet) -> f64 {
        self.drag
            .iter()
            .zip(bodies)
            .zip(&self.x)
            .map(|((g, &h), x0)| -g.dot(&(to_na(set[h].translation()) - x0)))
            .sum()
    }
}
