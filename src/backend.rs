//! Every way springlab can step a scene, by name: the native integrators and external
//! backends (physics engines) behind the same [`Integrator`] trait.

use crate::error::{Error, Result};
use crate::integrate::{Integrator, IntegratorOptions};

/// Names of external backends, accepted wherever an integrator name is.
pub const EXTERNAL: &[&str] = &[crate::rapier::IMPULSE, crate::rapier::MULTIBODY];

/// A fresh integrator or backend by name (aliases accepted).
pub fn create(name: &str, opts: &IntegratorOptions) -> Result<Box<dyn Integrator>> {
    use crate::rapier::{Mode, RapierBackend, IMPULSE, MULTIBODY};
    match crate::integrate::canonical_name(name) {
        Some(IMPULSE) => Ok(Box::new(RapierBackend::new(Mode::Impulse, opts.substeps))),
        Some(MULTIBODY) => Ok(Box::new(RapierBackend::new(Mode::Multibody, opts.substeps))),
        _ => crate::integrate::by_name(name, opts),
    }
}

/// The error for a known external name asked of the native registry.
pub fn not_native(name: &str) -> Error {
    Error::UnknownIntegrator {
        name: name.to_string(),
        known: crate::integrate::known_names().join(", "),
    }
}
