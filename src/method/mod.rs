//! Methods as data: every native scheme and engine springlab can run, registered once with its
//! facts (name, aliases, order, summary, stability theory, cost unit, how it meets the runner,
//! the options it reads) and its constructor.
//!
//! `list`, every command and the report read these facts from a [`Registry`]; a library user
//! adds a method with [`Registry::with`] and passes the registry to the measuring commands.
//! This module sits above `integrate` and `rapier` (it imports both; neither imports it, and
//! `integrate` does not import `rapier`).

mod builtin;
mod info;
mod instance;
pub mod options;
mod registry;

pub use info::{CostUnit, MethodInfo, Order, StabilityTheory};
pub use instance::Instance;
pub use options::{MethodOptions, OptionSpec};
pub use registry::{Constructor, Method, Registry};

use crate::error::Result;

/// A fresh instance of a built-in method, by name (aliases accepted): shorthand for
/// `Registry::builtin().create(name, opts)`.
pub fn create(name: &str, opts: &MethodOptions) -> Result<Instance> {
    Registry::builtin().create(name, opts)
}
