//! The scene's obstacles as fixed Rapier colliders, with the obstacle's restitution and
//! friction acting as given (combine rule `Max` against particles that carry 0).

use crate::model::System;
use rapier3d_f64::prelude::*;

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
                .collision_groups(obstacle_groups())
                .solver_groups(obstacle_groups())
                .build()
        })
        .collect()
}
