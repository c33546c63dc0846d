//! Backends that are not native integrators (physics engines), selectable by the same names.

use crate::error::Error;

/// Names of external backends, accepted wherever an integrator name is.
pub const EXTERNAL: &[&str] = &[];

/// The error for a known external name asked of the native registry.
pub fn not_native(name: &str) -> Error {
    Error::UnknownIntegrator {
        name: name.to_string(),
        known: crate::integrate::known_names().join(", "),
    }
}
