//! The frame-rate table's rows: one method at one rate, with its one-substep run and the
//! fewest substeps that meet the bound.

use crate::measure::case::WallTimes;
use serde::Serialize;

/// Which run of a method at a rate a row is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RowKind {
    /// One substep per frame.
    OneSubstep,
    /// The fewest substeps that is stable and meets the tolerance.
    Fewest,
}

impl RowKind {
    /// The CSV spelling.
    pub fn label(self) -> &'static str {
        match self {
            RowKind::OneSubstep => "one_substep",
            RowKind::Fewest => "fewest",
        }
    }
}

/// One measured run: a method at a frame rate with some substeps per frame.
#[derive(Debug, Clone, Serialize)]
pub struct FrameRun {
    /// Substeps per frame.
    pub substeps: u64,
    /// `ok` or `unstable`.
    pub status: crate::run::RunStatus,
    /// Stable and within the tolerance.
    pub meets_tolerance: bool,
    /// The error by the document's metric
    /// ([`JudgedBy::metric`](crate::measure::tolerance::JudgedBy::metric)), held to its bound.
    pub error: Option<f64>,
    /// Maximum position error over the accepted frames (m), compare's `error_max`.
    pub max_position_error: Option<f64>,
    /// Slope of the relative energy error (1/s), compare's `energy_drift`.
    pub energy_drift: Option<f64>,
    /// Modelled seconds per frame ([`crate::run::cost`]): what "the cheapest that does"
    /// ranks by; null for an unstable run.
    pub modelled_seconds_per_frame: Option<f64>,
    /// Median stepping wall time per frame (s); null for an unstable run (not timed).
    pub wall_seconds_per_frame: Option<f64>,
    /// The repeated timing behind it.
    pub timing: Option<WallTimes>,
    /// Force evaluations per frame; null for a method without such a count.
    pub force_evals_per_frame: Option<f64>,
    /// Why `force_evals_per_frame` is null.
    pub force_evals_reason: Option<String>,
    /// Time of the blow-up (s), for an unstable run.
    pub unstable_time: Option<f64>,
    /// What tripped, for an unstable run.
    pub unstable_reason: Option<String>,
    /// Largest strain of the run (None when it is not ok): what an `[expect]` table at this
    /// rate holds ([`crate::measure::expect_answer`]); not written to `framerate.json`.
    #[serde(skip)]
    pub strain_max: Option<f64>,
    /// Slope of the run's energy balance (J/s), for the same table.
    #[serde(skip)]
    pub energy_drift_rate: Option<f64>,
}

/// One method at one frame rate.
#[derive(Debug, Clone, Serialize)]
pub struct RateEntry {
    /// Method name.
    pub method: String,
    /// Frame rate (Hz).
    pub hz: f64,
    /// Frame step (s).
    pub frame_dt: f64,
    /// Frames run.
    pub frames: u64,
    /// The run at one substep per frame.
    pub one_substep: FrameRun,
    /// The run at the fewest substeps meeting the tolerance (null when none up to the limit).
    pub fewest: Option<FrameRun>,
    /// Why `fewest` is null.
    pub fewest_note: Option<String>,
    /// With `[run] events = "frame"`: the position error (m) the exact solution itself makes
    /// when its kicks move to this rate's frame boundaries, against the reference with the
    /// kicks at their own times. No substep count removes it: it is the floor of every error
    /// in this entry. Null for exact events or a scene without impulses.
    pub frame_event_floor: Option<f64>,
    /// Every substep count tried, with whether it met the tolerance.
    pub tried: Vec<(u64, bool)>,
}
