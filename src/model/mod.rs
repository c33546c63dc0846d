//! The mass-spring model: state, force terms, Jacobians and the assembled [`System`].

mod events;
mod jacobian;
pub(crate) mod parallel;
pub use parallel::PARALLEL_MIN_SPRINGS;
mod post_step;
mod springs;
mod state;
mod steps;
mod system;
mod term;

pub use events::Events;
pub use jacobian::{Jacobian, Sym3};
pub use post_step::{PostStep, StageStep};
pub use springs::Springs;
pub use state::{State, Vec3};
pub use steps::{covering_steps, whole_steps};
pub use system::{DistanceConstraint, Energy, Impulse, System};
pub use term::{Drag, EnergyKind, ForceTerm, Gravity, TermKind};
