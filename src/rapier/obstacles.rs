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
//! Where Rapier's model differs and cannot be set equal: [`DIFFERENCES`], one entry each,
//! with the test that measures it (the report's collision section lists the same entries
//! beside the figures compare measured). Sliding and sticking in resting contact match
//! Coulomb (incline, stopping distance).

use super::mode::{IMPULSE, MULTIBODY};
use crate::model::System;
use rapier3d_f64::prelude::*;

/// Which of Rapier's documented contact differences an entry of [`DIFFERENCES`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DifferenceKind {
    /// Soft and speculative contacts: a resting gap and a penetration corrected over steps.
    SoftSpeculative,
    /// Friction at an impact bounded by μ·|v_n| (no restitution part).
    ImpactFriction,
    /// Open meshes are one-sided.
    OneSidedMesh,
    /// `rapier_multibody` links turn, so a ball rolls.
    MultibodyRolling,
    /// A penalty contact is a user force held over each frame.
    PenaltyHeldForce,
}

/// One documented difference between Rapier's contact model and springlab's.
#[derive(Debug, Clone, Copy)]
pub struct Difference {
    /// Which difference.
    pub kind: DifferenceKind,
    /// Short name.
    pub title: &'static str,
    /// What differs and why it cannot be set equal.
    pub text: &'static str,
    /// The test (a `#[test]` function name under `tests/`) that measures it.
    pub test: &'static str,
    /// The methods that show it (both Rapier modes, or `rapier_multibody` alone).
    pub methods: &'static [&'static str],
    /// True for a penalty scene's difference (its obstacles are not Rapier colliders, so the
    /// others do not apply there), false for the colliders' differences.
    pub penalty: bool,
}

impl Difference {
    /// Whether `method`'s runs show it.
    pub fn shown_by(&self, method: &str) -> bool {
        self.methods.contains(&method)
    }
    /// Whether it applies to a scene with contact response `response`.
    pub fn applies_to(&self, response: crate::collide::ResponseKind) -> bool {
        self.penalty == (response == crate::collide::ResponseKind::Penalty)
    }
}

/// Rapier's contact model where it differs from springlab's and cannot be set equal: the one
/// text of these differences (module docs, report, and the test that checks each is measured).
pub const DIFFERENCES: [Difference; 5] = [
    Difference {
        kind: DifferenceKind::SoftSpeculative,
        title: "soft and speculative contacts",
        text: "penetration is corrected by a spring of static_contact_softness (60 Hz, damping ratio 10) through the biased solve, not projected away in one step; a contact is created within normalized_prediction_distance (0.02 m) and constrains the approach velocity so the ball stops at the surface in the step it would cross it, so a resting ball sits on a gap of up to about 1e-4 m instead of 0",
        test: "difference_soft_and_speculative_contacts_leave_a_resting_gap_below_2e_4_m",
        methods: &[IMPULSE, MULTIBODY],
        penalty: false,
    },
    Difference {
        kind: DifferenceKind::ImpactFriction,
        title: "impact friction bound μ|v_n|",
        text: "the friction cone is solved by projected Gauss-Seidel with friction left out of the biased pass and bounded by μ × the normal impulse that stops the approach, without the restitution part: an impact takes at most μ·|v_n| off the tangential speed (measured: 0.58 of the Newton–Coulomb μ(1 + e)|v_n| springlab's impulse law takes, for e = 0.5)",
        test: "difference_impact_friction_and_restitution_on_an_oblique_impact",
        methods: &[IMPULSE, MULTIBODY],
        penalty: false,
    },
    Difference {
        kind: DifferenceKind::OneSidedMesh,
        title: "one-sided open meshes",
        text: "an open mesh is one-sided in Rapier: a ball hitting it from the side its triangles face bounces (no sideways kick on a shared edge now that it cannot turn), one coming from the back passes through (springlab's own responses treat it as a two-sided sheet)",
        test: "difference_a_fast_ball_on_a_sheets_shared_edge",
        methods: &[IMPULSE, MULTIBODY],
        penalty: false,
    },
    Difference {
        kind: DifferenceKind::MultibodyRolling,
        title: "rapier_multibody links roll",
        text: "multibody links must turn about their parents, so their rotations cannot be locked: a ball on an incline rolls at 5/7·g·sin θ (a solid sphere) instead of sliding at g(sin θ − μ cos θ)",
        test: "difference_a_rapier_multibody_ball_rolls_down_the_incline",
        methods: &[MULTIBODY],
        penalty: false,
    },
    Difference {
        kind: DifferenceKind::PenaltyHeldForce,
        title: "penalty contact as a held user force",
        text: "Rapier has no penalty contact, so the penalty spring-dashpot is applied to each body as a user force evaluated at the start of each frame and held over the frame and its solver substeps (the obstacles are not colliders): with one substep that is symplectic Euler on the contact, with N substeps the force is frozen while the body moves, an error first order in the frame step",
        test: "rapier_with_a_held_penalty_force_is_symplectic_euler",
        methods: &[IMPULSE, MULTIBODY],
        penalty: true,
    },
];

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
