//! Tree edges as Rapier multibody joints (reduced coordinates).
//!
//! Compliant constraints are springs (see `joints::spring_params`). Rigid constraint a→b: a spherical joint (linear axes locked) whose anchor on b sits at a's
//! centre: b swings on a rod of length |x_b − x_a|, exactly rigid (no drift).
//!
//! Spring a→b: a multibody joint translates *before* it rotates (body_to_parent =
//! frame1·T(q)·R·frame2⁻¹), so no single joint has a radial degree of freedom. We insert a
//! helper pivot body at a (ball joint a→pivot, mass 1e-6·m_b, no gravity) and a prismatic
//! joint pivot→b along the current direction n: its coordinate q is |d| − L₀ (L₀ the length at
//! insertion). The spring is Rapier's implicit joint spring on q with rest l0 − L₀ and
//! stiffness k, its damper the joint damping c on q: the same law f = k(|d| − l0) + c·ḋ along n.
//!
//! Frames are chosen so that zero joint coordinates reproduce the current positions (Rapier
//! places a child from its joint coordinates, so anchors that do not match would move it), the
//! default joint damping (0.1 on every free angular DOF) is zeroed, and the generalized
//! velocities are set from the particle velocities (insertion starts them at zero).
//!
//! Edges left out of the trees are impulse joints between links, but not the coupled-axes
//! joints of the impulse method: see `joints::axial_joint`.

use super::convert::to_glam;
use super::joints::spring_params;
use super::topology::Edge;
use crate::model::{State, System, Vec3};
use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::prelude::*;

/// Pivot mass as a fraction of the child's mass.
pub const PIVOT_MASS_FRACTION: f64 = 1e-6;

/// A tree edge as inserted: which body carries which joint velocity.
#[derive(Debug, Clone, Copy)]
pub enum Inserted {
    /// Spherical rod joint: `child` swings about the parent's centre.
    Rod {
        /// The edge.
        edge: Edge,
    },
    /// Pivot (ball joint) + prismatic slider.
    Spring {
        /// The edge.
        edge: Edge,
        /// The helper pivot body.
        pivot: RigidBodyHandle,
        /// Length at insertion L₀ (m).
        len0: f64,
    },
}

/// Inserts the multibody joint(s) for tree edge `e`; `bodies[p]` is particle p's body.
pub fn insert_edge(
    world: &mut PhysicsWorld,
    sys: &System,
    s: &State,
    bodies: &[RigidBodyHandle],
    e: Edge,
) -> Inserted {
    let (ha, hb) = (bodies[e.a], bodies[e.b]);
    let d = s.x[e.b] - s.x[e.a];
    match spring_params(sys, e.kind) {
        None => {
            let data = GenericJointBuilder::new(JointAxesMask::LOCKED_SPHERICAL_AXES)
                .local_frame1(Pose::IDENTITY)
                .local_frame2(Pose::from_translation(to_glam(&(-d))))
                .build();
            world
                .multibody_joints
                .insert(ha, hb, data, true)
                .expect("tree edge joins two trees");
            Inserted::Rod { edge: e }
        }
        Some(_) => {
            let len0 = d.norm();
            let n = if len0 > 0.0 { d / len0 } else { Vec3::x() };
            let pivot = world.insert_body(super::bodies::pivot_body(
                to_glam(&s.x[e.a]),
                PIVOT_MASS_FRACTION * sys.mass[e.b],
                sys.radius[e.b],
            ));
            let ball = GenericJointBuilder::new(JointAxesMask::LOCKED_SPHERICAL_AXES).build();
            world
                .multibody_joints
                .insert(ha, pivot, ball, true)
                .expect("pivot joins its parent");
            let q = Rotation::from_rotation_arc(Vector::X, to_glam(&n));
            let slider = GenericJointBuilder::new(JointAxesMask::LOCKED_PRISMATIC_AXES)
                .local_frame1(Pose::from_parts(Vector::ZERO, q))
                .local_frame2(Pose::from_parts(to_glam(&(-d)), q))
                .build();
            world
                .multibody_joints
                .insert(pivot, hb, slider, true)
                .expect("slider joins the pivot");
            Inserted::Spring {
                edge: e,
                pivot,
                len0,
            }
        }
    }
}

/// After every insertion: zero Rapier's default joint damping, set the spring stiffness,
/// rest and damping on the sliders, and the generalized velocities from the particle
/// velocities (roots: their linear velocity; rods: ω = d×v_rel/|d|²; pivots: ω = n×v_rel/|d|;
/// sliders: q̇ = n·v_rel).
pub fn configure(
    world: &mut PhysicsWorld,
    sys: &System,
    s: &State,
    bodies: &[RigidBodyHandle],
    inserted: &[Inserted],
) {
    let mbs = &mut world.multibody_joints;
    // Zero the default damping and velocities of every multibody; set dynamic roots' velocity.
    for (p, &h) in bodies.iter().enumerate() {
        let Some(&link_id) = mbs.rigid_body_link(h) else {
            continue;
        };
        if link_id.id != 0 {
            continue;
        }
        let mb = mbs.get_multibody_mut(link_id.multibody).expect("multibody");
        mb.damping_mut().fill(0.0);
        mb.generalized_velocity_mut().fill(0.0);
        if sys.free[p] {
            let mut gv = mb.generalized_velocity_mut();
            for k in 0..3 {
                gv[k] = s.v[p][k];
            }
        }
    }
    for ins in inserted {
        match *ins {
            Inserted::Rod { edge } => {
                let d = s.x[edge.b] - s.x[edge.a];
                let w = d.cross(&(s.v[edge.b] - s.v[edge.a])) / d.norm_squared();
                set_joint_velocity(mbs, bodies[edge.b], &[w.x, w.y, w.z]);
            }
            Inserted::Spring { edge, pivot, len0 } => {
                let (k, l0, c) = spring_params(sys, edge.kind).expect("spring edge");
                let d = s.x[edge.b] - s.x[edge.a];
                let n = if len0 > 0.0 { d / len0 } else { Vec3::x() };
                let vrel = s.v[edge.b] - s.v[edge.a];
                let w = if len0 > 0.0 {
                    n.cross(&vrel) / len0
                } else {
                    Vec3::zeros()
                };
                set_joint_velocity(mbs, pivot, &[w.x, w.y, w.z]);
                set_joint_velocity(mbs, bodies[edge.b], &[n.dot(&vrel)]);
                let (mb, link) = mbs
                    .get_mut(MultibodyJointHandle(bodies[edge.b].0))
                    .expect("slider");
                mb.link_mut(link)
                    .expect("slider link")
                    .joint
                    .set_spring(0, k, l0 - len0);
                let idx = mb.link(link).expect("slider link").assembly_id();
                mb.damping_mut()[idx] = c;
            }
        }
    }
}

fn set_joint_velocity(mbs: &mut MultibodyJointSet, child: RigidBodyHandle, vel: &[f64]) {
    let (mb, link) = mbs
        .get_mut(MultibodyJointHandle(child.0))
        .expect("joint of child");
    let idx = mb.link(link).expect("link").assembly_id();
    let mut gv = mb.generalized_velocity_mut();
    for (k, &v) in vel.iter().enumerate() {
        gv[idx + k] = v;
    }
}
