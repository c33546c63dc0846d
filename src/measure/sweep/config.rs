//! What a sweep is asked to do: its options, and the slice of it one shard runs.

use crate::error::{Error, Result};
use crate::measure::grid::DEFAULT_BUDGET_BYTES;
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
    /// Methods, registry, options, blow-up factor, progress and budget: what every
    /// measuring command shares.
    pub common: crate::measure::Common,
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
    /// Run only one slice.
    pub shard: Option<Shard>,
    /// Memory budget for the reference samples (bytes).
    pub budget_bytes: usize,
    /// Repeat short runs for the wall time.
    pub repeat_short: bool,
}

impl Default for SweepConfig {
    fn default() -> Self {
        SweepConfig {
            dt_min: None,
            dt_max: None,
            points: None,
            extend: None,
            cost_cap: None,
            duration: None,
            shard: None,
            budget_bytes: DEFAULT_BUDGET_BYTES,
            repeat_short: true,
            common: crate::measure::Common::default(),
        }
    }
}
