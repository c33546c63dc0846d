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
//! Rigid constraint: the coupled linear axes with the limit [0, L]. Rapier 0.36 enforces only
//! the upper bound of a coupled limit ("FIXME: handle min limit too" in its solver), so this is
//! a rope: it holds the distance under tension (a pendulum) but lets a compressed rod shorten.
//! A spherical joint with offset anchors would be two-sided but makes each body's rotation
//! part of the constraint, which over-constrains particles with several rods.

use crate::model::System;
use rapier3d_f64::prelude::*;

/// The impulse-joint spring for spring `s` of `sys` (anchors at the body centres).
pub fn spring_joint(sys: &System, s: usize) -> GenericJoint {
    let sp = &sys.springs;
    GenericJointBuilder::new(JointAxesMask::empty())
        .coupled_axes(JointAxesMask::LIN_AXES)
        .motor_position(JointAxis::LinX, sp.l0[s], sp.k[s], sp.c[s])
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
