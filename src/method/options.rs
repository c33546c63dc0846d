//! The options a method reads when it is built, declared once as data ([`OptionSpec`]) in the
//! method's registry entry. The command line's flags, their validation, their help and the
//! recorded command that re-creates a document are all generated from these declarations.

use serde::Serialize;
use std::collections::BTreeMap;

/// One option a method reads: its command-line flag, default, least value and help.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct OptionSpec {
    /// The flag without its dashes (`iterations` is `--iterations`): lower-case words joined
    /// by `-`.
    pub flag: &'static str,
    /// The value when the option is not given.
    pub default: usize,
    /// The least value accepted.
    pub min: usize,
    /// One line of help: what the option sets (the methods that read it are added from the
    /// registry).
    pub help: &'static str,
}

impl OptionSpec {
    /// `Err(reason)` when `value` is below the least value.
    pub fn check(&self, value: usize) -> Result<(), String> {
        at_least(self.min, value)
    }
}

/// `Err(reason)` when the count `value` is below `min`: the one bound check of every
/// whole-number option (method options, frame substeps).
pub fn at_least(min: usize, value: usize) -> Result<(), String> {
    if value < min {
        Err(format!("must be at least {min}, got {value}"))
    } else {
        Ok(())
    }
}

/// Constraint projection sweeps per step (`verlet_constraints`).
pub const ITERATIONS: OptionSpec = OptionSpec {
    flag: "iterations",
    default: 20,
    min: 1,
    help: "Constraint projection sweeps per step",
};

/// XPBD substeps per step: one step of h is n substeps of h/n (`xpbd`'s own splitting, apart
/// from the runner's frame substeps, so the two never change each other's meaning).
pub const XPBD_SUBSTEPS: OptionSpec = OptionSpec {
    flag: "xpbd-substeps",
    default: 1,
    min: 1,
    help: "Substeps per step (one step of h is n XPBD substeps of h/n)",
};

/// Gauss-Seidel constraint sweeps per XPBD substep (`xpbd`).
pub const XPBD_ITERATIONS: OptionSpec = OptionSpec {
    flag: "xpbd-iterations",
    default: 1,
    min: 1,
    help: "Gauss-Seidel constraint sweeps per XPBD substep",
};

/// Solver substeps per frame a physics engine takes when the run does not split frames
/// (Rapier's own `num_solver_iterations` default).
pub const DEFAULT_ENGINE_SUBSTEPS: usize = 4;

/// The option values a method is built with: each declared option reads its given value or
/// its default, so a value that was never set cannot drift from its declaration.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MethodOptions {
    values: BTreeMap<&'static str, usize>,
    /// Solver substeps per frame for a method that splits frames itself (a physics engine,
    /// [`super::MethodInfo::splits_frames`]); set from the run's frame substeps, which native
    /// methods take as whole steps from the runner instead.
    pub substeps: usize,
}

impl Default for MethodOptions {
    fn default() -> Self {
        MethodOptions {
            values: BTreeMap::new(),
            substeps: DEFAULT_ENGINE_SUBSTEPS,
        }
    }
}

impl MethodOptions {
    /// The value of `spec`: the one given, else its default.
    pub fn get(&self, spec: &OptionSpec) -> usize {
        self.values.get(spec.flag).copied().unwrap_or(spec.default)
    }
    /// Sets `spec` to `value` (checked against its least value when a method reading it is
    /// made, [`super::Registry::create`]).
    pub fn set(&mut self, spec: &OptionSpec, value: usize) {
        self.values.insert(spec.flag, value);
    }
    /// These options with `spec` set to `value`.
    pub fn with(mut self, spec: &OptionSpec, value: usize) -> Self {
        self.set(spec, value);
        self
    }
    /// Every option `methods` declares, by flag, at its value here (given or default).
    pub fn resolved(&self, methods: &super::Registry) -> BTreeMap<String, usize> {
        methods
            .option_schema()
            .into_iter()
            .map(|(spec, _)| (spec.flag.to_string(), self.get(&spec)))
            .collect()
    }
    /// These options with `substeps` engine solver substeps per frame.
    pub fn with_substeps(mut self, substeps: usize) -> Self {
        self.substeps = substeps;
        self
    }
    /// Refuses, naming its flag, the first option in `schema` whose value is below its least.
    pub fn check(&self, schema: &[OptionSpec]) -> crate::error::Result<()> {
        for spec in schema {
            spec.check(self.get(spec))
                .map_err(|why| crate::error::Error::option(format!("--{}", spec.flag), why))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unset_options_read_their_declared_default() {
        let o = MethodOptions::default();
        assert_eq!(o.get(&ITERATIONS), 20);
        assert_eq!(o.with(&ITERATIONS, 3).get(&ITERATIONS), 3);
    }

    #[test]
    fn values_below_the_least_are_named_by_flag() {
        let o = MethodOptions::default().with(&XPBD_SUBSTEPS, 0);
        let err = o
            .check(&[ITERATIONS, XPBD_SUBSTEPS])
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("--xpbd-substeps:"), "{err}");
        assert!(MethodOptions::default().check(&[ITERATIONS]).is_ok());
    }
}
