//! Largest stable step per method: exactly from the spectral radius of each method's
//! one-step map on the scene's linearised modes, and empirically by bisection on the real
//! scene.
//!
//! Theory: for every mode q'' + c q' + ω² q = 0 (see `measure::modes`) the method itself
//! is stepped on a one-particle system with exactly that linear force, and its one-step map
//! M(h) on (x, v) is identified from two consecutive steps of two independent trajectories
//! (M = Y₂ Y₁⁻¹, which also covers methods whose memory is a function of (x, v), such as
//! two-step Störmer); a genuinely multistep method (BDF2) has its k-step recurrence identified
//! instead, and its companion matrix decides (see [`step_radius`]). The method
//! is stable at h when the spectral radius ρ(M(h)) ≤ 1 + [`RHO_TOL`] for every mode. The
//! boundary is bracketed on a log grid hω ∈ [[`SCAN_MIN`], [`SCAN_MAX`]] (1e-2 to 1e3; down to
//! 1e-2 ζ on a lightly damped mode, see [`theory::scan_min`]) and
//! bisected to machine precision.
//!
//! Empirical: a run is stable when the runner's one verdict ([`crate::run::verdict`]) calls
//! it ok over the horizon (and at least [`MIN_TRIAL_STEPS`] steps, so growth at a radius of
//! [`RHO_SHOWN`] shows however few steps of a large h the horizon holds): finite states, and an
//! energy balance that never rose by more than `blowup_factor` × the scene's energy scale. The step is doubled or halved to a bracket,
//! then bisected to 0.1 %. Bisection assumes that stability is monotone in dt. A method just
//! inside its linear limit can swing its energy by more than the threshold without growing
//! (symplectic Euler from rest reaches 1/(1 − hω/2) times its energy): the empirical limit is
//! then below the theoretical one, never above it.
//!
//! The map ([`stability_map`]) runs each cell for at least [`MAP_MIN_STEPS`] steps, so a
//! spectral radius of [`RHO_SHOWN`] multiplies the energy of its mode by at least
//! [`GROWTH_SHOWN`] and shows as a blow-up, from the scene's initial state with every free
//! particle displaced by [`MAP_SEED`] × its characteristic length ([`seeded`]): a symmetric
//! scene (a spring hanging straight down) never excites its transverse modes, whose growth
//! would otherwise never show.

mod analyse;
mod empirical;
mod map;
mod statement;
mod theory;
pub mod work;

pub use super::modes::Mode;
pub use analyse::{analyse, write_stability};
pub use empirical::{
    empirical_limit, empirical_limit_within, trial_steps, Empirical, EmpiricalCriterion,
    MIN_TRIAL_STEPS, SEARCH_TRIALS,
};
pub use map::{
    decide, seeded, stability_map, CellDecidedBy, MapConfig, MapRow, GROWTH_SHOWN, MAP_HEADER,
    MAP_MAX_STEPS, MAP_MIN_STEPS, MAP_SEED, RHO_SHOWN,
};
pub use statement::{statement, AGREE};
pub use theory::{
    mode_limit, one_step_map, scan_min, spectral_radius, step_radius, theory_limit, Limit, Verdict,
    RHO_TOL, SCAN_MAX, SCAN_MIN,
};

use super::modes::Modes;
use crate::method::{MethodOptions, Registry};
use serde::Serialize;

/// What decided a method's stability verdict; documents spell it by [`DecidedBy::name`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecidedBy {
    /// The spectral radius of the linearised one-step map.
    SpectralRadius,
    /// The empirical bisection on the energy verdict (no linear theory applies).
    EmpiricalBisection,
    /// A closed form: stable at any step.
    ClosedForm,
    /// Nothing: no theory applies and the empirical search did not run.
    Nothing,
}

impl DecidedBy {
    /// The name documents and tables print.
    pub fn name(self) -> &'static str {
        match self {
            DecidedBy::SpectralRadius => "spectral_radius",
            DecidedBy::EmpiricalBisection => "empirical_bisection",
            DecidedBy::ClosedForm => "closed_form",
            DecidedBy::Nothing => "none",
        }
    }
}

impl Serialize for DecidedBy {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Per-method stability.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodStability {
    /// Method name.
    pub method: String,
    /// The verdict (theory when available, else empirical).
    pub verdict: Verdict,
    /// Largest stable step (s) when `stable_below`.
    pub max_stable_dt: Option<f64>,
    /// max_stable_dt × omega_max.
    pub h_omega: Option<f64>,
    /// What decided the verdict.
    pub decided_by: DecidedBy,
    /// The theory verdict (None for engine methods).
    pub theory_verdict: Option<Verdict>,
    /// The theory limit (s).
    pub theory_max_stable_dt: Option<f64>,
    /// The empirical search.
    pub empirical: Option<Empirical>,
    /// Anything to know (skipped, approximations).
    pub note: Option<String>,
    /// The one statement on this method: the theory's verdict, the empirical search's, which
    /// decides, and why they differ where they do.
    pub statement: String,
}

/// `stability.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilityReport {
    /// The command that re-creates this document (`--out DIR` is added where it is written).
    pub command: String,
    /// Scenario name.
    pub scenario: String,
    /// Highest natural frequency of the linearised scene (rad/s).
    pub omega_max: f64,
    /// The modal analysis.
    pub modes: Modes,
    /// Theory criterion in words.
    pub theory_criterion: String,
    /// Empirical criterion.
    pub empirical_criterion: EmpiricalCriterion,
    /// Per method.
    pub methods: Vec<MethodStability>,
    /// Methods that do not apply, with the reason.
    pub skipped: Vec<(String, String)>,
}

/// Options of [`analyse`].
#[derive(Debug, Clone, Default)]
pub struct StabilityConfig {
    /// Methods, registry, options, blow-up factor, progress and budget: what every
    /// measuring command shares.
    pub common: crate::measure::Common,
    /// Empirical horizon (default: 100 periods of ω_max, else the scene's duration).
    pub horizon: Option<f64>,
    /// Skip the empirical search.
    pub theory_only: bool,
    /// Run the empirical search only for methods without linear theory (where the spectral
    /// radius decides the verdict, the search is a cross-check that costs many runs).
    pub empirical_where_no_theory: bool,
}

/// The linear theory's largest stable step of each of `names` on `sys` from `s0` (s): None
/// for a method without that theory, a scene without modes, or a verdict that is not a
/// positive finite step. The modes are found once for all. What the commands that search over
/// steps or substeps start from (advice's cost floors, the frame-rate search), so a method's
/// stability fact comes from its registry entry.
pub fn theory_limits(
    registry: &Registry,
    options: &MethodOptions,
    sys: &crate::model::System,
    s0: &crate::model::State,
    names: &[String],
) -> crate::error::Result<Vec<Option<f64>>> {
    let mut ms: Option<Modes> = None;
    names
        .iter()
        .map(|name| {
            let method = registry.get(name)?;
            if !method.info.linear_theory() {
                return Ok(None);
            }
            let ms = ms.get_or_insert_with(|| super::modes::modes(sys, s0));
            if ms.modes.is_empty() {
                return Ok(None);
            }
            Ok(match theory_limit(method, options, ms) {
                (Verdict::StableBelow, Some(h)) if h.is_finite() && h > 0.0 => Some(h),
                _ => None,
            })
        })
        .collect()
}
