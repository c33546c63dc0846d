//! The facts a method carries: its order, how its stability is judged, how its cost is
//! counted, how it meets the runner (contacts, frames, past states) and the options it reads.
//! Commands, reports and the registry read these; nobody re-derives them by name.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Global order of accuracy in the step size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// Error O(hᵖ) with p ≥ 1.
    Finite(u32),
    /// Exact at any step (a closed form): no convergence to fit.
    Exact,
}

impl Order {
    /// The finite order, `None` for exact methods.
    pub fn finite(self) -> Option<u32> {
        match self {
            Order::Finite(p) => Some(p),
            Order::Exact => None,
        }
    }
}

impl std::fmt::Display for Order {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Order::Finite(p) => write!(f, "{p}"),
            Order::Exact => f.write_str("exact"),
        }
    }
}

/// In documents an order is a number, or the string `"exact"`.
impl Serialize for Order {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Order::Finite(p) => s.serialize_u32(*p),
            Order::Exact => s.serialize_str("exact"),
        }
    }
}

/// Reads what [`Order`]'s `Serialize` writes: a whole number ≥ 1 or `"exact"`.
impl<'de> Deserialize<'de> for Order {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Number(u32),
            Word(String),
        }
        match Raw::deserialize(d)? {
            Raw::Number(p) if p >= 1 => Ok(Order::Finite(p)),
            Raw::Word(w) if w == "exact" => Ok(Order::Exact),
            _ => Err(serde::de::Error::custom(
                "an order is a whole number ≥ 1 or \"exact\"",
            )),
        }
    }
}

/// How a method's largest stable step is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StabilityTheory {
    /// Linear one-step theory applies: the spectral radius of the method's one-step map on
    /// each linearised mode decides, and the empirical search checks it on the real scene.
    SpectralRadius,
    /// Exact (a closed form): stable at every step by construction.
    Unconditional,
    /// No linear theory (a physics engine's solver): only the empirical search on the scene.
    Empirical,
}

/// What a method's cost is counted in, besides wall time (which every method has).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CostUnit {
    /// Evaluations of springlab's force model (`System::accelerations` calls), beside the
    /// modelled cost ([`crate::run::cost`]).
    ForceEvaluations,
    /// The modelled cost only: the method never evaluates springlab's force model (an engine,
    /// a closed form), so a force-evaluation count would read as free.
    ModelledOnly,
}

/// One method's facts, registered once and read everywhere.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodInfo {
    /// Canonical CLI name (`rk4`): lower-case letters, digits and underscores.
    pub name: &'static str,
    /// Other accepted spellings.
    pub aliases: &'static [&'static str],
    /// Global order of accuracy.
    pub order: Order,
    /// One line: what the method is.
    pub summary: &'static str,
    /// How its stability limit is judged.
    pub stability: StabilityTheory,
    /// How its cost is counted.
    pub cost: CostUnit,
    /// True for a physics engine (Rapier): it resolves contacts itself and is left out of
    /// nothing, but its internals (force evaluations, one-step maps) are not ours to inspect.
    pub engine: bool,
    /// True for an implicit method: each step solves a system of equations (Newton or one
    /// linear solve), so it is stable at a frame step and is timed at one.
    pub implicit: bool,
    /// True when the method resolves obstacle contacts itself (a physics engine): the runner
    /// then applies no contact stage of its own.
    pub contacts: bool,
    /// True when the method splits each frame into substeps itself (an engine's solver
    /// substeps): the runner passes it whole frames instead of `RunPlan::substeps` steps.
    pub splits_frames: bool,
    /// k of a k-step method: how many past states, the current one included, its next step
    /// reads (2 for BDF2; 1 for one-step methods); the stability analysis identifies a k-step
    /// recurrence from it.
    pub recurrence_steps: usize,
    /// The options the method reads when it is built; the command line's flags and the
    /// recorded command are generated from them.
    pub options: &'static [super::options::OptionSpec],
    /// The method's colour in every chart (RGB), distinct from every other built-in's; `None`
    /// (a user's method) takes one from a fallback set.
    pub colour: Option<[u8; 3]>,
}

impl MethodInfo {
    /// The facts of an explicit one-step native method of finite `order`: linear stability
    /// theory applies, cost counted in force evaluations, no options. Override fields with
    /// struct update syntax (`MethodInfo { options: &[..], ..MethodInfo::native(..) }`).
    pub const fn native(name: &'static str, order: u32, summary: &'static str) -> Self {
        MethodInfo {
            name,
            aliases: &[],
            order: Order::Finite(order),
            summary,
            stability: StabilityTheory::SpectralRadius,
            cost: CostUnit::ForceEvaluations,
            engine: false,
            implicit: false,
            contacts: false,
            splits_frames: false,
            recurrence_steps: 1,
            options: &[],
            colour: None,
        }
    }
    /// True when the spectral-radius theory applies.
    pub fn linear_theory(&self) -> bool {
        self.stability == StabilityTheory::SpectralRadius
    }
    /// True when `name` is this method's name or one of its aliases.
    pub fn answers_to(&self, name: &str) -> bool {
        self.name == name || self.aliases.contains(&name)
    }
}
