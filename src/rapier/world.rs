//! Builds a Rapier [`PhysicsWorld`] from a [`System`] and a [`State`].

use super::bodies::{particle_body, particle_collider};
use super::convert::to_glam;
use super::joints::{align_frames, axial_joint, edge_joint};
pub use super::mode::Mode;
use super::multibody::{configure, insert_edge};
use super::topology::{tree_cap, Edge, Topology};
use crate::model::{State, System};
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::*;

/// A built world and the body of each particle.
pub struct Built {
    /// The Rapier world (sets, pipeline, parameters).
    pub world: PhysicsWorld,
    /// Body handle of particle p at index p.
    pub bodies: Vec<RigidBodyHandle>,
    /// The multibody topology (multibody mode only).
    pub topology: Option<Topology>,
    /// Fallback joints between multibody links whose frames follow the particle axis.
    pub axial: Vec<(ImpulseJointHandle, Edge)>,
    /// Whether particle p's body is a multibody link (Rapier's linear damping skips those, so
    /// their drag is a held user force, see `super::user_forces`).
    pub linked: Vec<bool>,
}

/// A Rapier world for `sys` at state `s`. Gravity is the scene's or zero (Rapier's
/// `PhysicsWorld` defaults to −9.81 ŷ). Sleeping is off on every body.
pub fn build(sys: &System, s: &State, mode: Mode, substeps: usize, h: f64) -> Built {
    let mut world = PhysicsWorld::new();
    world.gravity = sys.gravity.as_ref().map(to_glam).unwrap_or(Vector::ZERO);
    set_step(&mut world, substeps, h);
    super::obstacles::contact_parameters(&mut world.integration_parameters);
    let bodies: Vec<RigidBodyHandle> = (0..sys.len())
        .map(|p| {
            world
                .insert(
                    particle_body(sys, s, p, mode == Mode::Impulse),
                    particle_collider(sys, p),
                )
                .0
        })
        .collect();
    // With a penalty contact the penalty spring is the contact (applied as a user force,
    // see `super::user_forces`): the obstacles are not also Rapier colliders.
    if !super::user_forces::any(sys) {
        for c in super::obstacles::obstacle_colliders(sys) {
            world.insert_collider(c, None);
        }
    }
    let impulse = |world: &mut PhysicsWorld, e: Edge| {
        let data = edge_joint(sys, e.kind);
        world
            .impulse_joints
            .insert(bodies[e.a], bodies[e.b], data, true);
    };
    let mut axial = Vec::new();
    let topology = match mode {
        Mode::Impulse => {
            let all = Topology::of(sys, 0);
            for &(e, _) in &all.fallback {
                impulse(&mut world, e);
            }
            None
        }
        Mode::Multibody => {
            let topo = Topology::of(sys, tree_cap(sys));
            let inserted: Vec<_> = topo
                .tree
                .iter()
                .map(|&e| insert_edge(&mut world, sys, s, &bodies, e))
                .collect();
            configure(&mut world, sys, s, &bodies, &inserted);
            for &(e, _) in &topo.fallback {
                let h = world.impulse_joints.insert(
                    bodies[e.a],
                    bodies[e.b],
                    axial_joint(sys, e.kind),
                    true,
                );
                axial.push((h, e));
            }
            Some(topo)
        }
    };
    let linked = bodies
        .iter()
        .map(|&b| world.multibody_joints.rigid_body_link(b).is_some())
        .collect();
    Built {
        world,
        bodies,
        topology,
        axial,
        linked,
    }
}

/// Before a frame: points every axial fallback joint along its particles' current axis.
pub fn align_axial(b: &mut Built) {
    for &(h, e) in &b.axial {
        let (ra, rb) = (
            &b.world.bodies[b.bodies[e.a]],
            &b.world.bodies[b.bodies[e.b]],
        );
        let d = rb.translation() - ra.translation();
        let n = if d.length() > 0.0 {
            d / d.length()
        } else {
            Vector::X
        };
        let (r1, r2) = (*ra.rotation(), *rb.rotation());
        if let Some(j) = b.world.impulse_joints.get_mut(h, false) {
            align_frames(&mut j.data, n, r1, r2);
        }
    }
}

/// Frame step `h`, `substeps` solver iterations (Rapier's substeps), no speed cap.
pub fn set_step(world: &mut PhysicsWorld, substeps: usize, h: f64) {
    world.integration_parameters.dt = h;
    world.integration_parameters.num_solver_iterations = substeps;
    // Rapier caps body speed at 400 m/s by default; a particle model has no such cap.
    world.integration_parameters.normalized_max_linear_velocity = f64::MAX;
}
