//! Static obstacles through parry3d-f64: shapes at poses with a broad phase,
//! per-particle signed-distance queries and the three contact responses (penalty force term,
//! post-step impulse, post-step projection). Their validation metrics are measurement, in
//! [`crate::measure::contacts`]. Nothing here is built or
//! queried for a scene without obstacles ([`query_count`], [`build_count`] show it).

mod contacts;
mod counter;
mod def;
mod impact;
pub mod mesh;
mod obstacles;
mod penalty;

pub use contacts::{of, ContactStep, Contacts};
pub use counter::{build_count, query_count};
pub use def::{
    damping_ratio_for_restitution, restitution_for_damping_ratio, CollisionSetup, ObstacleDef,
    PenaltyDamping, Response, ResponseKind, ShapeDef, ShapeKind,
};
pub use impact::{penalty_impact, PenaltyImpact, STEPS_PER_HALF_PERIOD};
pub use obstacles::{Contact, Obstacle, ObstacleSet, SweepHit, SHEET_CLEARANCE};
pub use penalty::{Penalty, FRICTION_REGULARISATION};
