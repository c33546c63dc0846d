//! The options a method reads when it is built, declared once as data ([`OptionSpec`]) in the
//! method's registry entry. The command line's flags, their validation, their help and the
//! recorded command that re-creates a document are all generated from these declarations.

use serde::Serialize;
use std::collections::BTreeMap;

/// One option a method reads: its command-line flag, what values it takes with its default,
/// and help.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OptionSpec {
    /// The flag without its dashes (`iterations` is `--iterations`): lower-case words joined
    /// by `-`.
    pub flag: &'static str,
    /// The values it takes and its default.
    pub kind: OptionKind,
    /// One line of help: what the option sets (the methods that read it are added from the
    /// registry).
    pub help: &'static str,
}

/// What values an option takes, with its default.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OptionKind {
    /// A whole number no less than `min` (sweeps, substeps).
    Count {
        /// The value when the option is not given.
        default: usize,
        /// The least value accepted.
        min: usize,
    },
    /// A finite real number in `[min, max]` (a rate, a fraction).
    Real {
        /// The value when the option is not given.
        default: f64,
        /// The least value accepted.
        min: f64,
        /// The greatest value accepted.
        max: f64,
    },
    /// One of `names` (a solver, a mode); the first is the default.
    Choice {
        /// The names accepted, the default first.
        names: &'static [&'static str],
    },
}

/// An option's value (in documents: a number or a name).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
#[serde(untagged)]
pub enum OptionValue {
    /// A whole number.
    Count(usize),
    /// A real number.
    Real(f64),
    /// A name.
    Choice(String),
}

impl std::fmt::Display for OptionValue {
    /// As the command line takes it (a real in the shortest form that reads back the same).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OptionValue::Count(n) => write!(f, "{n}"),
            OptionValue::Real(x) => write!(f, "{x}"),
            OptionValue::Choice(c) => f.write_str(c),
        }
    }
}

impl OptionSpec {
    /// A whole-number option.
    pub const fn count(flag: &'static str, default: usize, min: usize, help: &'static str) -> Self {
        OptionSpec {
            flag,
            kind: OptionKind::Count { default, min },
            help,
        }
    }
    /// A real-valued option in `[min, max]`.
    pub const fn real(
        flag: &'static str,
        default: f64,
        (min, max): (f64, f64),
        help: &'static str,
    ) -> Self {
        OptionSpec {
            flag,
            kind: OptionKind::Real { default, min, max },
            help,
        }
    }
    /// A choice among `names`, the first the default.
    pub const fn choice(
        flag: &'static str,
        names: &'static [&'static str],
        help: &'static str,
    ) -> Self {
        OptionSpec {
            flag,
            kind: OptionKind::Choice { names },
            help,
        }
    }
    /// The value when the option is not given.
    pub fn default_value(&self) -> OptionValue {
        match self.kind {
            OptionKind::Count { default, .. } => OptionValue::Count(default),
            OptionKind::Real { default, .. } => OptionValue::Real(default),
            OptionKind::Choice { names } => {
                OptionValue::Choice(names.first().copied().unwrap_or("").to_string())
            }
        }
    }
    /// `Err(reason)` when `value` is not one this option takes (another kind, out of its
    /// bounds, not one of its names).
    pub fn check(&self, value: &OptionValue) -> Result<(), String> {
        match (self.kind, value) {
            (OptionKind::Count { min, .. }, OptionValue::Count(n)) => at_least(min, *n),
            (OptionKind::Real { min, max, .. }, OptionValue::Real(x)) => within(min, max, *x),
            (OptionKind::Choice { names }, OptionValue::Choice(c)) => {
                if names.contains(&c.as_str()) {
                    Ok(())
                } else {
                    Err(format!("must be one of {}, got {c}", names.join(", ")))
                }
            }
            (_, v) => Err(format!("takes {}, got {v}", self.kind.what())),
        }
    }
    /// The value `text` says (as typed on the command line), checked.
    pub fn parse(&self, text: &str) -> Result<OptionValue, String> {
        let t = text.trim();
        let v = match self.kind {
            OptionKind::Count { min, .. } => OptionValue::Count(
                t.parse()
                    .map_err(|_| format!("expected a whole number ≥ {min}"))?,
            ),
            OptionKind::Real { min, max, .. } => OptionValue::Real(
                t.parse()
                    .map_err(|_| format!("expected a number in [{min}, {max}]"))?,
            ),
            OptionKind::Choice { .. } => OptionValue::Choice(t.to_string()),
        };
        self.check(&v)?;
        Ok(v)
    }
}

impl OptionKind {
    /// What values it takes, in words.
    pub fn what(&self) -> String {
        match self {
            OptionKind::Count { min, .. } => format!("a whole number ≥ {min}"),
            OptionKind::Real { min, max, .. } => format!("a number in [{min}, {max}]"),
            OptionKind::Choice { names } => format!("one of {}", names.join(", ")),
        }
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

/// `Err(reason)` unless `value` is finite and in `[min, max]`.
fn within(min: f64, max: f64, value: f64) -> Result<(), String> {
    if value.is_finite() && value >= min && value <= max {
        Ok(())
    } else {
        Err(format!("must be a number in [{min}, {max}], got {value}"))
    }
}

/// Constraint projection sweeps per step (`verlet_constraints`).
pub const ITERATIONS: OptionSpec =
    OptionSpec::count("iterations", 20, 1, "Constraint projection sweeps per step");

/// XPBD substeps per step: one step of h is n substeps of h/n (`xpbd`'s own splitting, apart
/// from the runner's frame substeps, so the two never change each other's meaning).
pub const XPBD_SUBSTEPS: OptionSpec = OptionSpec::count(
    "xpbd-substeps",
    1,
    1,
    "Substeps per step (one step of h is n XPBD substeps of h/n)",
);

/// Gauss-Seidel constraint sweeps per XPBD substep (`xpbd`).
pub const XPBD_ITERATIONS: OptionSpec = OptionSpec::count(
    "xpbd-iterations",
    1,
    1,
    "Gauss-Seidel constraint sweeps per XPBD substep",
);

/// The linear solver of every Newton iteration of an implicit method (the shared core's
/// [`crate::integrate::LinearSolver`]), by name; the default first.
pub const LINEAR_SOLVER: OptionSpec = OptionSpec::choice(
    "linear-solver",
    crate::integrate::LinearSolver::NAMES,
    "Linear solver of each Newton iteration",
);

/// Iterations each solve of an implicit Newton method's step may take: its direct Newton
/// iteration, each elimination of a stalled patch and each root-path piece (the shared core's
/// [`crate::integrate::ImplicitSettings::max_newton`]).
pub const MAX_NEWTON: OptionSpec = OptionSpec::count(
    "max-newton",
    50,
    1,
    "Newton iterations a step's solve may take (its direct iteration, each elimination of a stalled patch, each root-path piece) before the step fails",
);

/// Solver substeps per frame a physics engine takes when the run does not split frames
/// (Rapier's own `num_solver_iterations` default).
pub const DEFAULT_ENGINE_SUBSTEPS: usize = 4;

/// The option values a method is built with: each declared option reads its given value or
/// its default, so a value that was never set cannot drift from its declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodOptions {
    values: BTreeMap<&'static str, OptionValue>,
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
    pub fn value(&self, spec: &OptionSpec) -> OptionValue {
        self.values
            .get(spec.flag)
            .cloned()
            .unwrap_or_else(|| spec.default_value())
    }
    /// The count `spec` (a [`OptionKind::Count`]) is set to; its default where it was set to
    /// another kind (refused when a method reading it is made).
    pub fn count(&self, spec: &OptionSpec) -> usize {
        match (self.value(spec), spec.default_value()) {
            (OptionValue::Count(n), _) | (_, OptionValue::Count(n)) => n,
            _ => 0,
        }
    }
    /// The real number `spec` (a [`OptionKind::Real`]) is set to.
    pub fn real(&self, spec: &OptionSpec) -> f64 {
        match (self.value(spec), spec.default_value()) {
            (OptionValue::Real(x), _) | (_, OptionValue::Real(x)) => x,
            _ => f64::NAN,
        }
    }
    /// The name `spec` (a [`OptionKind::Choice`]) is set to.
    pub fn choice(&self, spec: &OptionSpec) -> String {
        match (self.value(spec), spec.default_value()) {
            (OptionValue::Choice(c), _) | (_, OptionValue::Choice(c)) => c,
            _ => String::new(),
        }
    }
    /// Sets `spec` to `value` (checked against the option when a method reading it is made,
    /// [`super::Registry::create`]).
    pub fn set(&mut self, spec: &OptionSpec, value: OptionValue) {
        self.values.insert(spec.flag, value);
    }
    /// These options with `spec` set to `value`.
    pub fn with(mut self, spec: &OptionSpec, value: OptionValue) -> Self {
        self.set(spec, value);
        self
    }
    /// Every option `methods` declares, by flag, at its value here (given or default).
    pub fn resolved(&self, methods: &super::Registry) -> BTreeMap<String, OptionValue> {
        methods
            .option_schema()
            .into_iter()
            .map(|(spec, _)| (spec.flag.to_string(), self.value(&spec)))
            .collect()
    }
    /// These options with `substeps` engine solver substeps per frame.
    pub fn with_substeps(mut self, substeps: usize) -> Self {
        self.substeps = substeps;
        self
    }
    /// Refuses, naming its flag, the first option in `schema` whose value it does not take.
    pub fn check(&self, schema: &[OptionSpec]) -> crate::error::Result<()> {
        for spec in schema {
            spec.check(&self.value(spec))
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
        assert_eq!(o.count(&ITERATIONS), 20);
        assert_eq!(
            o.with(&ITERATIONS, OptionValue::Count(3))
                .count(&ITERATIONS),
            3
        );
    }

    #[test]
    fn values_below_the_least_are_named_by_flag() {
        let o = MethodOptions::default().with(&XPBD_SUBSTEPS, OptionValue::Count(0));
        let err = o
            .check(&[ITERATIONS, XPBD_SUBSTEPS])
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("--xpbd-substeps:"), "{err}");
        assert!(MethodOptions::default().check(&[ITERATIONS]).is_ok());
    }
}
