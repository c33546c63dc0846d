//! The scene's obstacles as fixed Rapier colliders, with the obstacle's restitution and
//! friction acting as given (combine rule `Max` against particles that carry 0), and the
//! contact parameters that bring Rapier's contact model closest to springlab's.
//!
//! Set to match the scene's model (a particle is a ball that cannot turn, Coulomb friction
//! μ per contact, Newton restitution e against the obstacle):
//! - particle bodies of `rapier_impulse` have their rotations locked (no rolling; see
//!   [`super::bodies::particle_body`]); `rapier_multibody` links must turn and still roll;
//! - friction: [`FrictionModel::Coulomb`], one Coulomb constraint per contact point (the
//!   default `Simplified` model shares one friction constraint and a twist constraint per
//!   manifold); coefficients combined by `Max` so the obstacle's μ and e act as given;
//! - contact skin 0 on every collider (Rapier's default; a skin would hold the ball off the
//!   surface by its thickness); contact recycling off, so each step's contacts are fresh.
//!
//! Where Rapier's model differs and cannot be set equal (each measured by a test in
//! `tests/rapier_contact_model.rs`):
//! - soft contacts: penetration is corrected by a spring of `static_contact_softness`
//!   (60 Hz, damping ratio 10) through the biased solve, not projected away in one step;
//! - speculative contacts: a contact is created within `normalized_prediction_distance`
//!   (0.02 m) and constrains the approach velocity so the ball stops at the surface in the
//!   step it would cross it, so a resting ball sits on a gap of up to about 1e-4 m instead of 0;
//! - its friction cone is solved by projected Gauss-Seidel over `num_solver_iterations`
//!   with friction left out of the biased pass (`friction_in_bias_pass = false`), and bounded
//!   by μ × the normal impulse that stops the approach, without the restitution part: at an
//!   impact it takes at most μ·|v_n| off the tangential speed (measured: 0.58 of the
//!   Newton–Coulomb μ(1 + e)|v_n| that springlab's impulse law takes, for e = 0.5).
//!   Sliding and sticking in resting contact match Coulomb (incline, stopping distance);
//! - an open mesh is one-sided in Rapier: a ball hitting it from the side its triangles face
//!   bounces (no sideways kick on a shared edge now that it cannot turn), one coming from the
//!   back passes through (springlab's own responses treat it as a two-sided sheet).

use crate::model::System;
use rapier3d_f64::prelude::*;

/// Sets the contact parameters of the module docs on `p` (called for every world built).
pub fn contact_parameters(p: &mut IntegrationParameters) {
    p.friction_model = FrictionModel::Coulomb;
    p.contact_recycling = false;
}

/// Collision group of particles: they meet obstacles, never each other.
pub fn particle_groups() -> InteractionGroups {
    InteractionGroups::new(Group::GROUP_1, Group::GROUP_2, InteractionTestMode::And)
}

/// Collision group of obstacles: they meet particles.
fn obstacle_groups() -> InteractionGroups {
    InteractionGroups::new(Group::GROUP_2, Group::GROUP_1, InteractionTestMode::And)
}

/// One standalone (fixed) collider per obstacle of `sys`, none without obstacles. The parry
/// shapes are shared with springlab's own contact stage, so both sides see the same geometry.
pub fn obstacle_colliders(sys: &System) -> Vec<Collider> {
    let Some(c) = crate::collide::of(sys) else {
        return Vec::new();
    };
    c.set
        .obstacles()
        .iter()
        .map(|ob| {
            ColliderBuilder::new(ob.shape.clone())
                .position(ob.pose)
                .restitution(ob.restitution)
                .restitution_combine_rule(CoefficientCombineRule::Max)
                .friction(ob.friction)
                .friction_combine_rule(CoefficientCombineRule::Max)
                .contact_skin(0.0)
                .collision_groups(obstacle_groups())
                .solver_groups(obstacle_groups())
                .build()
        })
        .collect()
}
