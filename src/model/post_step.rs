//! The hook the runner calls after every accepted step. The model only knows this trait; the
//! contact stage in [`crate::collide`] implements it, so imports point down (collide → model).

use super::state::{State, Vec3};
use super::system::System;
use std::any::Any;

/// What a post-step stage did in one step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageStep {
    /// True when some position or velocity changed (the stepper's history must then be reset).
    pub changed: bool,
    /// Mechanical energy the stage removed (J, ≥ 0): work against friction and inelastic
    /// contact, never netted against a gain.
    pub dissipated: f64,
    /// Mechanical energy the stage created (J, ≥ 0), booked apart from `dissipated` so a
    /// loss elsewhere cannot hide it (it stays in the mechanical terms, where the verdict sees it).
    pub created: f64,
}

/// A stage run after every step the stepper accepts (today: contact response with obstacles).
pub trait PostStep: Send + Sync + std::fmt::Debug {
    /// Name listed by [`System::active_terms`]; `None` when the stage does no post-step work
    /// (its effect lives in a force term, which is listed instead).
    fn name(&self) -> Option<&'static str>;
    /// Applies the stage after a step of length `h` that took the particles from positions `x0`
    /// and velocities `v0` to `s`.
    fn apply(&self, sys: &System, x0: &[Vec3], v0: &[Vec3], s: &mut State, h: f64) -> StageStep;
    /// The concrete stage, so the layer that defined it can read its data back.
    fn as_any(&self) -> &dyn Any;
}
