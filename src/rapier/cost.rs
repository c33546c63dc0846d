//! The modelled cost of a Rapier frame, from the scene alone: what the engine builds (bodies,
//! impulse joints, multibody trees and the impulse joints attached to them) times per-item
//! costs fitted to Rapier 0.36's measured frames on the shipped scenes (2-core x86-64, one
//! thread). springlab cannot count the engine's work the way it counts its own, so this is
//! the engine's entry in [`crate::run::cost`]: deterministic, so every decision on an engine's
//! cost (a budget, a ranking, a left-out engine) is the same on every re-run.
//!
//! Shape of the model, per solver substep: every body and every impulse joint costs a fixed
//! amount; a multibody tree of L links costs a part linear in L and a part in L³ (its dense
//! mass matrix is factorised every substep); an impulse joint attached to a tree costs a part
//! proportional to the tree's size (it is solved against the dense matrix). Per frame, each
//! body pays the pipeline's fixed stages.

use super::mode::Mode;
use super::topology::{tree_cap, Topology};
use crate::model::System;

/// Seconds per frame, whatever the scene: the pipeline's fixed stages.
pub const FRAME: f64 = 2.5e-6;
/// Seconds per body per frame (broad phase, islands, read-back).
pub const BODY_PER_FRAME: f64 = 0.37e-6;
/// Seconds per body per substep (integration).
pub const BODY_PER_SUBSTEP: f64 = 0.1e-6;
/// Seconds per impulse joint per substep.
pub const JOINT_PER_SUBSTEP: f64 = 0.21e-6;
/// Seconds per multibody link per substep (kinematics, forces, joint motors).
pub const LINK_PER_SUBSTEP: f64 = 1.77e-6;
/// Seconds per cubed link count of a tree per substep (its dense mass matrix and the joint
/// motors solved against it).
pub const TREE_CUBE_PER_SUBSTEP: f64 = 0.18e-6;
/// Seconds per link of the trees an impulse joint attaches to, per substep.
pub const ATTACHED_LINK_PER_SUBSTEP: f64 = 0.49e-6;

/// What a Rapier stepper builds for a scene: the counts the model prices.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EngineShape {
    /// Rigid bodies (one per particle).
    pub bodies: usize,
    /// Impulse joints (every edge for the impulse method; loops and edges past the tree cap
    /// for the multibody one).
    pub impulse_joints: usize,
    /// Links of each multibody tree.
    pub trees: Vec<usize>,
    /// Links of the trees each impulse joint touches, summed over the impulse joints.
    pub attached_links: usize,
    /// Each substep is a whole Rapier frame of one substep: multibody trees with impulse
    /// joints between them, whose frames are re-aligned before every substep.
    pub frame_per_substep: bool,
}

impl EngineShape {
    /// What `mode` builds for `sys` (the same topology the stepper builds).
    pub fn of(sys: &System, mode: Mode) -> Self {
        let bodies = sys.len();
        match mode {
            Mode::Impulse => EngineShape {
                bodies,
                impulse_joints: Topology::of(sys, 0).fallback.len(),
                ..EngineShape::default()
            },
            Mode::Multibody => {
                let topo = Topology::of(sys, tree_cap(sys));
                let links_of = |p: usize| topo.tree_of[p].map_or(0, |t| topo.links[t]);
                let attached = topo
                    .fallback
                    .iter()
                    .map(|(e, _)| {
                        let (ta, tb) = (topo.tree_of[e.a], topo.tree_of[e.b]);
                        links_of(e.a) + if ta == tb { 0 } else { links_of(e.b) }
                    })
                    .sum();
                EngineShape {
                    bodies,
                    impulse_joints: topo.fallback.len(),
                    attached_links: attached,
                    frame_per_substep: !topo.fallback.is_empty(),
                    trees: topo.links,
                }
            }
        }
    }

    /// Modelled seconds of one frame with `substeps` solver substeps.
    pub fn frame_seconds(&self, substeps: usize) -> f64 {
        let per_substep = BODY_PER_SUBSTEP * self.bodies as f64
            + JOINT_PER_SUBSTEP * self.impulse_joints as f64
            + self
                .trees
                .iter()
                .map(|&l| {
                    let l = l as f64;
                    LINK_PER_SUBSTEP * l + TREE_CUBE_PER_SUBSTEP * l * l * l
                })
                .sum::<f64>()
            + ATTACHED_LINK_PER_SUBSTEP * self.attached_links as f64;
        let (n, fixed) = (
            substeps.max(1) as f64,
            FRAME + BODY_PER_FRAME * self.bodies as f64,
        );
        if self.frame_per_substep {
            n * (fixed + per_substep)
        } else {
            fixed + n * per_substep
        }
    }
}

/// Seconds per soft-body particle per frame (proxies, read-back, the body's bookkeeping).
/// The soft-body prices are fitted to Rapier 0.36's frames on the shipped cloth (1024
/// particles, 5826 edges), hanging chain (20, 19), chain on a box (20, 19, two obstacles) and
/// cloth on a sphere (256, 1378) at 1, 4 and 16 substeps (2-core x86-64, one thread).
pub const SOFT_PARTICLE_PER_FRAME: f64 = 1.2e-6;
/// Seconds per soft-body edge per substep of the constraint solver (a Gauss-Seidel visit with
/// warm start and the extra PGS iterations Rapier gives soft bodies).
pub const SOFT_EDGE_PER_SUBSTEP: f64 = 0.16e-6;
/// Seconds per soft-body edge per substep of the FEM solver (assembly and the capped
/// conjugate gradient's products over the element).
pub const SOFT_FEM_EDGE_PER_SUBSTEP: f64 = 0.17e-6;
/// Seconds per frame of a soft body's contact stage when the scene has obstacles, whatever
/// its size (the soft contact pipeline's fixed passes; 20-particle chain on a box and a plane).
pub const SOFT_CONTACT_PER_FRAME: f64 = 0.25e-3;
/// Seconds per soft-body edge per frame when the scene has obstacles: the edges are the
/// body's collision wire (broad and narrow phase of every segment).
pub const SOFT_WIRE_EDGE_PER_FRAME: f64 = 2.0e-6;
/// Seconds per edge and particle per frame for the FEM solver when the scene has obstacles:
/// every contact constraint on a FEM body is solved against the whole body's system, so the
/// contact stage grows as the wire's edges times the body's particles.
pub const SOFT_FEM_CONTACT_PER_EDGE_PARTICLE: f64 = 0.35e-6;

/// What a soft-body stepper builds for a scene: the counts its price reads.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SoftShape {
    /// Soft-body particles.
    pub particles: usize,
    /// Soft-body edges (springs and compliant rods).
    pub edges: usize,
    /// True when the scene has obstacles (the edges then collide).
    pub collides: bool,
}

impl SoftShape {
    /// The particles and edges a soft-body method builds for `sys`.
    pub fn of(sys: &System) -> Self {
        SoftShape {
            particles: sys.len(),
            edges: sys.springs.len() + sys.constraints.len(),
            collides: sys.post_step.is_some(),
        }
    }

    /// Modelled seconds of one frame with `substeps` solver substeps under `solver`.
    pub fn frame_seconds(&self, solver: super::SoftSolver, substeps: usize) -> f64 {
        let (p, e) = (self.particles as f64, self.edges as f64);
        let (edge, fem_contacts) = match solver {
            super::SoftSolver::Constraints => (SOFT_EDGE_PER_SUBSTEP, 0.0),
            super::SoftSolver::Fem => (
                SOFT_FEM_EDGE_PER_SUBSTEP,
                SOFT_FEM_CONTACT_PER_EDGE_PARTICLE * e * p,
            ),
        };
        let contacts = if self.collides {
            SOFT_CONTACT_PER_FRAME + SOFT_WIRE_EDGE_PER_FRAME * e + fem_contacts
        } else {
            0.0
        };
        FRAME + SOFT_PARTICLE_PER_FRAME * p + contacts + substeps.max(1) as f64 * edge * e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    fn chain(beads: usize, closed: bool) -> System {
        let mut t = String::new();
        for i in 0..beads {
            t += &format!(
                "[[particle]]\nposition=[{i}.0,0.0,0.0]\nmass=1.0\nfixed={}\n",
                i == 0
            );
        }
        for i in 1..beads {
            t += &format!("[[spring]]\nbetween=[{}, {i}]\nstiffness=10.0\n", i - 1);
        }
        if closed {
            t += &format!("[[spring]]\nbetween=[{}, 1]\nstiffness=10.0\n", beads - 1);
        }
        Scenario::from_toml_str(&t, "chain.toml").unwrap().build()
    }

    // Oracle: the topology by hand. A fixed bead and 9 free ones in a line make one tree of
    // 9 links and no impulse joint; closing the loop leaves every edge either a link or an
    // impulse joint, and an impulse joint touching a tree.
    #[test]
    fn shapes_follow_the_topology() {
        let open = EngineShape::of(&chain(10, false), Mode::Multibody);
        assert_eq!((open.bodies, open.impulse_joints), (10, 0));
        assert_eq!((open.trees.clone(), open.attached_links), (vec![9], 0));
        let closed = EngineShape::of(&chain(10, true), Mode::Multibody);
        assert_eq!(
            closed.impulse_joints + closed.trees.iter().sum::<usize>(),
            10
        );
        assert!(closed.impulse_joints >= 1 && closed.attached_links >= 1);
        let imp = EngineShape::of(&chain(10, false), Mode::Impulse);
        assert_eq!((imp.impulse_joints, imp.trees.len()), (9, 0));
        // More substeps cost more; the frame's fixed part is paid once.
        assert!(imp.frame_seconds(4) > imp.frame_seconds(1));
        assert!(imp.frame_seconds(1) > FRAME);
    }

    // Oracle: the spanning forest by hand. A fixed bead and 40 free ones in a line: the tree
    // from the fixed bead stops at the cap (itself and 31 free beads, 31 links), the edge
    // 31–32 falls back to an impulse joint, and bead 32 roots a second tree of the last 9
    // beads (8 links). That joint joins two trees, so it touches the links of both; and since
    // it sits between trees, every substep is a whole frame, fixed part and all.
    #[test]
    fn a_joint_between_two_trees_touches_the_links_of_both() {
        use crate::rapier::topology::MAX_TREE_PARTICLES;
        let sys = chain(41, false);
        assert_eq!(tree_cap(&sys), MAX_TREE_PARTICLES);
        let shape = EngineShape::of(&sys, Mode::Multibody);
        assert_eq!((shape.bodies, shape.impulse_joints), (41, 1));
        assert_eq!(shape.trees, vec![31, 8]);
        assert_eq!(shape.attached_links, 31 + 8);
        assert!(shape.frame_per_substep);
        assert_eq!(shape.frame_seconds(4), 4.0 * shape.frame_seconds(1));
        // Twin: within the cap, one tree and no joint; substeps then repeat only the solver.
        let short = EngineShape::of(&chain(32, false), Mode::Multibody);
        assert_eq!((short.trees.clone(), short.impulse_joints), (vec![31], 0));
        assert!(!short.frame_per_substep);
        assert!(short.frame_seconds(4) < 4.0 * short.frame_seconds(1));
    }
}
