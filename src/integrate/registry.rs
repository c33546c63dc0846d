//! Integrators by name: the values of the CLI's `--integrator` flag.

use super::*;
use crate::error::Error;

/// The built-in native integrators, in the order reports list them.
pub const NATIVE: &[&str] = &[
    "explicit_euler",
    "symplectic_euler",
    "implicit_euler",
    "rk2",
    "rk4",
    "velocity_verlet",
    "position_verlet",
    "verlet_constraints",
    "analytic",
];

/// Accepted alternative spellings and the canonical name they stand for.
const ALIASES: &[(&str, &str)] = &[("semi_implicit_euler", "symplectic_euler")];

/// Options that some integrators read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegratorOptions {
    /// Constraint projection sweeps per step (`verlet_constraints`).
    pub constraint_iterations: usize,
    /// Solver substeps per frame for physics-engine backends (Rapier's `num_solver_iterations`).
    pub substeps: usize,
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            constraint_iterations: 20,
            substeps: 4,
        }
    }
}

/// The canonical name for `name` (resolving aliases), if it is known.
pub fn canonical_name(name: &str) -> Option<&'static str> {
    if let Some(&n) = NATIVE.iter().find(|&&n| n == name) {
        return Some(n);
    }
    if let Some(&(_, n)) = ALIASES.iter().find(|(a, _)| *a == name) {
        return Some(n);
    }
    crate::backend::EXTERNAL
        .iter()
        .find(|&&n| n == name)
        .copied()
}

/// True when `name` names an integrator or backend.
pub fn is_known(name: &str) -> bool {
    canonical_name(name).is_some()
}

/// Every accepted name, native first, then external backends.
pub fn known_names() -> Vec<&'static str> {
    NATIVE
        .iter()
        .chain(crate::backend::EXTERNAL)
        .copied()
        .collect()
}

/// A fresh native integrator by name.
pub fn by_name(name: &str, opts: &IntegratorOptions) -> crate::error::Result<Box<dyn Integrator>> {
    let unknown = || Error::UnknownIntegrator {
        name: name.to_string(),
        known: known_names().join(", "),
    };
    Ok(match canonical_name(name).ok_or_else(unknown)? {
        "explicit_euler" => Box::new(ExplicitEuler::default()),
        "symplectic_euler" => Box::new(SymplecticEuler::default()),
        "implicit_euler" => Box::new(ImplicitEuler::default()),
        "rk2" => Box::new(RungeKutta::new(Tableau::rk2())),
        "rk4" => Box::new(RungeKutta::new(Tableau::rk4())),
        "velocity_verlet" => Box::new(VelocityVerlet::default()),
        "position_verlet" => Box::new(PositionVerlet::default()),
        "verlet_constraints" => Box::new(VerletConstraints::new(opts.constraint_iterations)),
        "analytic" => Box::new(Analytic::default()),
        other => return Err(crate::backend::not_native(other)),
    })
}
