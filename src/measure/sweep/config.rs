//! What a sweep is asked to do: its options, and the slice of it one shard runs.

use crate::error::{Error, Result};
use crate::measure::grid::DEFAULT_BUDGET_BYTES;
use crate::method::{MethodOptions, Registry};
use serde::{Deserialize, Serialize};

/// The I-th of N deterministic slices of a sweep (0 ≤ I < N).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Slice index, 0-based.
    pub index: usize,
    /// Number of slices.
    pub count: usize,
}

impl Shard {
    /// True when method `i` belongs to this shard.
    pub fn owns(&self, i: usize) -> bool {
        i % self.count == self.index
    }
}

impl std::str::FromStr for Shard {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let bad = |m: &str| {
            Error::option(
                "--shard",
                format!("{m}: expected I/N with 0 ≤ I < N, got '{s}'"),
            )
        };
        let (i, n) = s.split_once('/').ok_or_else(|| bad("missing '/'"))?;
        let index: usize = i.trim().parse().map_err(|_| bad("I is not a number"))?;
        let count: usize = n.trim().parse().map_err(|_| bad("N is not a number"))?;
        if count == 0 || index >= count {
            return Err(bad("out of range"));
        }
        Ok(Shard { index, count })
    }
}

/// What to sweep. The grid fields are overrides of the dynamics-based default (module doc).
#[derive(Debug, Clone)]
pub struct SweepConfig {
    /// Methods (empty: every applicable native and engine method).
    pub methods: Vec<String>,
    /// Smallest base step (default: hω_max = 0.05); giving it turns extension off unless
    /// `extend` is `Some(true)`.
    pub dt_min: Option<f64>,
    /// Largest step (default: 1.25 × the widest theoretical stability limit).
    pub dt_max: Option<f64>,
    /// Number of log-spaced steps in [dt_min, dt_max] (default: halving-spaced).
    pub points: Option<usize>,
    /// Refine each method toward smaller steps until asymptotic, at the floor or capped
    /// (default: yes unless `dt_min` is given).
    pub extend: Option<bool>,
    /// Cost cap per method in particle-steps (default
    /// [`DEFAULT_COST_CAP`](super::DEFAULT_COST_CAP)).
    pub cost_cap: Option<f64>,
    /// Simulated time (default: the scene's duration).
    pub duration: Option<f64>,
    /// The methods to choose from (built-ins unless a library user added theirs).
    pub registry: Registry,
    /// Method options.
    pub options: MethodOptions,
    /// Blow-up factor of the runner.
    pub blowup_factor: f64,
    /// Run only one slice.
    pub shard: Option<Shard>,
    /// Memory budget for the reference samples (bytes).
    pub budget_bytes: usize,
    /// Show a progress bar on a terminal.
    pub progress: bool,
    /// Repeat short runs for the wall time.
    pub repeat_short: bool,
    /// Time budget (s of runs, summed; see [`budget`](super::budget)); `None`: no budget (the
    /// report's sweeps, whose engines the study already chose by cost). Not applied to a shard.
    pub budget_seconds: Option<f64>,
}

impl Default for SweepConfig {
    fn default() -> Self {
        SweepConfig {
            methods: Vec::new(),
            dt_min: None,
            dt_max: None,
            points: None,
            extend: None,
            cost_cap: None,
            duration: None,
            registry: Registry::builtin(),
            options: MethodOptions::default(),
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
            shard: None,
            budget_bytes: DEFAULT_BUDGET_BYTES,
            progress: false,
            repeat_short: true,
            budget_seconds: None,
        }
    }
}
