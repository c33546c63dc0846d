//! Springs and rigid constraints as Rapier impulse joints.
//!
//! Spring: a generic joint whose three linear axes are *coupled* (the constrained quantity is
//! the anchor distance |d|) with a position motor on that distance: target l0, stiffness k,
//! damping c, **force-based** (`GenericJointBuilder` motors default to `AccelerationBased`,
//! which scales k and c by the effective mass and changes the physics). This is Rapier's
//! `SpringJoint`; with anchors at the body centres it applies f = k(|d| − l0) + c (n·v_rel)
//! along n = d/|d|: our spring law exactly. The residual difference is the integration: Rapier
//! solves the motor as a soft constraint, implicitly in the velocity (see `scheme`).
//!
//! A compliant constraint (XPBD compliance α > 0) is a spring of stiffness 1/α at its length.
//!
//! Rigid constraint: the coupled linear axes with the limit [0, L]. Rapier 0.36 enforces only
//! the upper bound of a coupled limit ("FIXME: handle min limit too" in its solver), so this is
//! a rope: it holds the distance under tension (a pendulum) but lets a compressed rod shorten.
//! A spherical joint with offset anchors would be two-sided but makes each body's rotation
//! part of the constraint, which over-constrains particles with several rods.

use super::topology::EdgeKind;
use crate::model::System;
use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::prelude::*;

/// The impulse-joint spring for spring `s` of `sys` (anchors at the body centres).
pub fn spring_joint(sys: &System, s: usize) -> GenericJoint {
    let sp = &sys.springs;
    spring_with(sp.k[s], sp.l0[s], sp.c[s])
}

/// Stiffness, rest length and damping of an edge that acts as a spring: a spring, or a
/// compliant constraint (XPBD compliance α is a spring of stiffness 1/α at the rod length).
/// `None` for a rigid constraint.
pub fn spring_params(sys: &System, kind: EdgeKind) -> Option<(f64, f64, f64)> {
    match kind {
        EdgeKind::Spring(s) => Some((sys.springs.k[s], sys.springs.l0[s], sys.springs.c[s])),
        EdgeKind::Constraint(c) => {
            let dc = &sys.constraints[c];
            (dc.compliance > 0.0).then(|| (1.0 / dc.compliance, dc.length, 0.0))
        }
    }
}

/// The impulse joint for an edge: a spring joint ([`spring_params`]) or a rope.
pub fn edge_joint(sys: &System, kind: EdgeKind) -> GenericJoint {
    match (spring_params(sys, kind), kind) {
        (Some((k, l0, c)), _) => spring_with(k, l0, c),
        (None, EdgeKind::Constraint(c)) => constraint_joint(sys, c),
        (None, EdgeKind::Spring(_)) => unreachable!("springs always have parameters"),
    }
}

fn spring_with(k: f64, l0: f64, c: f64) -> GenericJoint {
    GenericJointBuilder::new(JointAxesMask::empty())
        .coupled_axes(JointAxesMask::LIN_AXES)
        .motor_position(JointAxis::LinX, l0, k, c)
        .motor_model(JointAxis::LinX, MotorModel::ForceBased)
        .build()
}

/// The impulse joint for rigid constraint `c` of `sys`: a rope of the constraint's length.
pub fn constraint_joint(sys: &System, c: usize) -> GenericJoint {
    let len = sys.constraints[c].length;
    GenericJointBuilder::new(JointAxesMask::empty())
        .coupled_axes(JointAxesMask::LIN_AXES)
        .limits(JointAxis::LinX, [0.0, len])
        .build()
}

/// An impulse joint for an edge between multibody links, acting along one joint axis (X)
/// instead of coupled axes: Rapier 0.36's multibody joint solver (`generic_joint_constraint_
/// builder.rs`) ignores coupled axes, which turns a coupled spring into a motor along world X
/// and blew up our cloth. Springs get a force-based motor on X, rigid constraints the
/// two-sided limit [L, L] on X. The frames must keep X along the current particle axis:
/// [`align_frames`] does that before every frame, so the spring acts along the frame-start
/// axis (the coupled version updates the axis every substep; the difference is second order in
/// the rotation of the axis during one frame).
pub fn axial_joint(sys: &System, kind: EdgeKind) -> GenericJoint {
    let b = GenericJointBuilder::new(JointAxesMask::empty());
    match (spring_params(sys, kind), kind) {
        (Some((k, l0, c)), _) => b
            .motor_position(JointAxis::LinX, l0, k, c)
            .motor_model(JointAxis::LinX, MotorModel::ForceBased),
        (None, EdgeKind::Constraint(c)) => {
            let len = sys.constraints[c].length;
            b.limits(JointAxis::LinX, [len, len])
        }
        (None, EdgeKind::Spring(_)) => unreachable!("springs always have parameters"),
    }
    .build()
}

/// Points both frames' X axes of an [`axial_joint`] along `n` (world), anchors at the centres.
pub fn align_frames(joint: &mut GenericJoint, n: Vector, rot1: Rotation, rot2: Rotation) {
    let q = Rotation::from_rotation_arc(Vector::X, n);
    joint.set_local_frame1(Pose::from_parts(Vector::ZERO, rot1.inverse() * q));
    joint.set_local_frame2(Pose::from_parts(Vector::ZERO, rot2.inverse() * q));
}
