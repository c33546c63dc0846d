//! One Rapier rigid body per particle, with a tiny ball collider that collides with nothing.
//!
//! Mass: the particle's mass, set explicitly (the collider has density 0). Rotational inertia:
//! a solid ball of the particle's radius, I = 2/5·m·r². Particles have no rotational inertia;
//! the residual matters only where a joint makes a body rotate (a multibody link turning about
//! its parent, or a spring pivot): it adds I·ω²/2 to the kinetic energy Rapier conserves, a
//! relative effect of 2/5·(r/L)² on the period of a link of length L (4·10⁻⁵ for r = 0.01 m,
//! L = 1 m). Sleeping is off: a sleeping body freezes a stretched spring. Linear drag (force
//! −c·v) becomes Rapier's linear damping c/m (applied implicitly, v ← v/(1 + h·c/m), once per
//! Rapier step h after its substeps); Rapier skips it on multibody links, whose drag is the same
//! law held as a user force (`super::user_forces`).

use super::convert::to_glam;
use crate::model::{State, System};
use rapier3d_f64::prelude::*;

/// Restitution combine rule our colliders carry. Rapier's default is `Average`, which would
/// halve an obstacle's restitution against a particle of restitution 0; `Max` lets the
/// obstacle's coefficient act as given (particles themselves have restitution 0).
pub const RESTITUTION_RULE: CoefficientCombineRule = CoefficientCombineRule::Max;

/// Smallest radius used for a body's inertia, so a zero-radius particle still has an
/// invertible inertia tensor (m).
const MIN_INERTIA_RADIUS: f64 = 1e-3;

/// The body for particle `p` of `sys` at the state's position and velocity. With
/// `lock_rotations` (the impulse-joint method) the body cannot turn: a particle has no
/// rotational degree of freedom, so a ball on an incline slides under Coulomb friction
/// (a = g(sin θ − μ cos θ)) instead of rolling (a = 5/7·g·sin θ). Multibody links must turn
/// about their parents and keep their rotations.
pub fn particle_body(sys: &System, s: &State, p: usize, lock_rotations: bool) -> RigidBody {
    let builder = if sys.free[p] {
        RigidBodyBuilder::dynamic().linvel(to_glam(&s.v[p]))
    } else {
        RigidBodyBuilder::fixed()
    };
    let r = sys.radius[p].max(MIN_INERTIA_RADIUS);
    let m = sys.mass[p];
    let builder = if lock_rotations {
        builder.lock_rotations()
    } else {
        builder
    };
    builder
        .translation(to_glam(&s.x[p]))
        .additional_mass_properties(MassProperties::new(
            Vector::ZERO,
            m,
            Vector::splat(0.4 * m * r * r),
        ))
        .can_sleep(false)
        .linear_damping(sys.drag.unwrap_or(0.0) / m)
        .angular_damping(0.0)
        .build()
}

/// A massless helper body at `x` for multibody spring pivots: negligible mass and inertia
/// (`eps` kg, `eps`·r² kg·m²), no gravity.
pub fn pivot_body(x: Vector, eps: f64, r: f64) -> RigidBody {
    let r = r.max(MIN_INERTIA_RADIUS);
    RigidBodyBuilder::dynamic()
        .translation(x)
        .additional_mass_properties(MassProperties::new(
            Vector::ZERO,
            eps,
            Vector::splat(eps * r * r),
        ))
        .gravity_scale(0.0)
        .can_sleep(false)
        .build()
}

/// The particle's ball collider: radius as given, density 0 (mass comes from the body),
/// restitution and friction 0 combined by `Max` (so an obstacle's values act as given); it
/// collides with the scene's obstacles only, never with other particles.
pub fn particle_collider(sys: &System, p: usize) -> Collider {
    let groups = if sys.post_step.is_some() {
        super::obstacles::particle_groups()
    } else {
        InteractionGroups::none()
    };
    ColliderBuilder::ball(sys.radius[p].max(MIN_INERTIA_RADIUS))
        .density(0.0)
        .collision_groups(groups)
        .solver_groups(groups)
        .restitution(0.0)
        .restitution_combine_rule(RESTITUTION_RULE)
        .friction(0.0)
        .friction_combine_rule(CoefficientCombineRule::Max)
        .contact_skin(0.0)
        .build()
}
