//! Rapier 0.36 (f64) engines: the only module that imports Rapier.
//!
//! `rapier_impulse` maps every particle to a rigid body and every spring/constraint to an
//! impulse joint; `rapier_multibody` puts tree edges into multibody joints (reduced
//! coordinates) and leaves loop-closing edges to impulse joints, saying so
//! ([`RapierStepper::topology_note`]). [`scheme_prediction`] gives the known scheme Rapier's
//! behaviour matches, as data to plot next to the measured curve.

mod bodies;
pub(crate) mod convert;
pub mod cost;
mod joints;
mod mode;
mod multibody;
pub(crate) mod obstacles;
mod scheme;
mod soft;
pub(crate) mod stepper;
mod topology;
pub(crate) mod user_forces;
pub(crate) mod world;

pub use bodies::RESTITUTION_RULE;
pub use cost::{EngineShape, SoftShape};
pub use mode::{Mode, IMPULSE, MULTIBODY};
pub use obstacles::{Difference, DifferenceKind, DIFFERENCES};
pub use scheme::{scheme_prediction, Prediction};
pub use soft::{soft_plan, SoftPlan, SoftSolver, SoftStepper, SOFT, SOFT_FEM};
pub use stepper::RapierStepper;
pub use topology::{
    tree_cap, Edge, EdgeKind, FallbackReason, Topology, MAX_TREE_PARTICLES,
    MAX_TREE_PARTICLES_WITH_LOOPS,
};

/// Internals exposed for the trap regression tests (not a stable API).
#[doc(hidden)]
pub mod internals {
    pub use super::bodies::{particle_body, particle_collider};
    pub use super::joints::{constraint_joint, spring_joint};
    pub use super::world::{build, Built};
    pub use rapier3d_f64;
}
