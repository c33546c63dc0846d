//! The game view of advice: at each common frame rate, how each candidate fares with one step
//! per frame and with enough substeps to meet the tolerance, and which is cheapest there by
//! the same cost as the pick ([`super::cost`]). Its substeps per frame come from each
//! candidate's verified step (⌈frame / step⌉), which its verification found stable, so the view
//! needs no search (`springlab framerate` searches, from the stability theory's count).

use super::cost::{force_evals_per_second, rank, CostKey, PickedBy};
use crate::error::Result;
use crate::measure::case::{CaseResult, TimedRun, WallTimes};
use crate::measure::grid::TimeGrid;
use crate::measure::tolerance::Judge;
use crate::method::Registry;
use serde::Serialize;

/// Frame rates of the game view (Hz).
pub const FRAME_RATES: [f64; 4] = [30.0, 60.0, 144.0, 240.0];

/// Why an entry that fails the tolerance has no wall time.
const NOT_TIMED: &str = "not timed: the substepped run does not meet the tolerance";

/// Why an entry that meets the tolerance but is not its rate's best has no wall time.
const NOT_BEST: &str =
    "not timed: only each rate's best is timed (the modelled cost ranks; a wall time decides nothing)";

/// How one method fares at one frame rate.
#[derive(Debug, Clone, Serialize)]
pub struct FrameEntry {
    /// Method name.
    pub method: String,
    /// Status with one step per frame.
    pub one_step_status: crate::run::RunStatus,
    /// Error with one step per frame (None when unstable).
    pub one_step_error: Option<f64>,
    /// Substeps per frame needed to meet the tolerance (from its recommended step).
    pub substeps: u64,
    /// Error verified at that many substeps (None when unstable).
    pub substep_error: Option<f64>,
    /// Whether the substepped run meets the tolerance.
    pub meets_tolerance: bool,
    /// Modelled seconds per simulated second at that many substeps (s/s,
    /// [`crate::run::cost`]): what `best` is ranked by; null when the run is not stable.
    pub modelled_per_second: Option<f64>,
    /// Median wall time per simulated second at that many substeps (s/s); null unless the
    /// entry is its rate's `best` (only those are timed).
    pub wall_per_second: Option<f64>,
    /// Why `wall_per_second` is null.
    pub wall_per_second_reason: Option<String>,
    /// The repeated timing behind `wall_per_second`.
    pub timing: Option<WallTimes>,
    /// Force evaluations per simulated second at that many substeps; null for a method that
    /// has no such count.
    pub cost_per_second: Option<f64>,
    /// Why `cost_per_second` is null.
    pub cost_per_second_reason: Option<String>,
    /// Largest strain of the substepped run (None when it is not ok): what an `[expect]` table
    /// at this rate holds ([`crate::measure::expect_answer`]); not written to `advice.json`.
    #[serde(skip)]
    pub strain_max: Option<f64>,
    /// Slope of the substepped run's energy balance (J/s), for the same table.
    #[serde(skip)]
    pub energy_drift_rate: Option<f64>,
    /// The substepped accuracy run's own stepping wall time (s), for a timing that reuses it.
    #[serde(skip)]
    pub measured_wall: f64,
}

/// The rates of the frame view: [`FRAME_RATES`] when `view` is asked, with `game_hz` added
/// where it is not among them; `game_hz` alone without the view.
pub fn rates_of(view: bool, game_hz: Option<f64>) -> Vec<f64> {
    let mut rates: Vec<f64> = if view { FRAME_RATES.to_vec() } else { vec![] };
    if let Some(hz) = game_hz.filter(|h| !rates.contains(h)) {
        rates.push(hz);
    }
    rates
}

/// The game view at one frame rate.
#[derive(Debug, Clone, Serialize)]
pub struct FrameRate {
    /// Frames per second.
    pub fps: f64,
    /// Frame time (s).
    pub frame_dt: f64,
    /// Cheapest method meeting the tolerance at this frame rate, by the advice's cost.
    pub best: Option<String>,
    /// Which rule made `best` the cheapest.
    pub picked_by: Option<PickedBy>,
    /// Per method.
    pub entries: Vec<FrameEntry>,
}

/// The runs of the frame view: per frame rate, per candidate, the one-step run then the
/// substepped run.
pub(super) struct FramePlan {
    /// Frames over the horizon, per frame rate.
    frames: Vec<u64>,
    /// Substeps per frame, per frame rate, per candidate.
    substeps: Vec<Vec<u64>>,
    /// The frame rates (Hz): [`FRAME_RATES`], or none when the view is not asked for.
    rates: Vec<f64>,
}

impl FramePlan {
    /// The plan for candidates whose recommended steps are `steps` (s).
    pub(super) fn new(horizon: f64, steps: &[f64], rates: &[f64]) -> Self {
        FramePlan {
            rates: rates.to_vec(),
            frames: rates
                .iter()
                .map(|&f| crate::measure::framerate::frames_at(horizon, f))
                .collect(),
            substeps: rates
                .iter()
                .map(|&fps| {
                    steps
                        .iter()
                        .map(|&dt| ((1.0 / fps) / dt).ceil().max(1.0) as u64)
                        .collect()
                })
                .collect(),
        }
    }

    /// The grids to run with the index of their candidate, in the order
    /// [`FramePlan::entries`] reads them.
    pub(super) fn grids(&self, max_samples: u64) -> Vec<(usize, TimeGrid)> {
        let mut out = Vec::new();
        for (fi, &fps) in self.rates.iter().enumerate() {
            let frame = 1.0 / fps;
            for (pi, &n) in self.substeps[fi].iter().enumerate() {
                out.push((pi, TimeGrid::new(frame, self.frames[fi], max_samples)));
                out.push((
                    pi,
                    TimeGrid::new(frame / n as f64, self.frames[fi] * n, max_samples),
                ));
            }
        }
        out
    }

    /// The frame view from the results of [`FramePlan::grids`], before timing.
    pub(super) fn entries(
        &self,
        registry: &Registry,
        names: &[String],
        res: &[CaseResult],
        judge: &Judge,
        scenario: &str,
    ) -> Result<Vec<FrameRate>> {
        let np = names.len();
        self.rates
            .iter()
            .enumerate()
            .map(|(fi, &fps)| {
                let entries = names
                    .iter()
                    .enumerate()
                    .map(|(pi, name)| {
                        let one = &res[2 * (fi * np + pi)];
                        let sub = &res[2 * (fi * np + pi) + 1];
                        let se = judge.error(sub);
                        let (cost, why) = force_evals_per_second(
                            registry,
                            name,
                            sub.force_evals,
                            sub.dt * sub.steps as f64,
                        )?;
                        let meets = se.is_some_and(|e| e <= judge.bound);
                        Ok(FrameEntry {
                            method: name.clone(),
                            one_step_status: one.status,
                            one_step_error: judge.error(one),
                            substeps: self.substeps[fi][pi],
                            substep_error: se,
                            meets_tolerance: meets,
                            modelled_per_second: sub
                                .ok()
                                .then(|| sub.modelled_seconds / (sub.dt * sub.steps as f64)),
                            wall_per_second: None,
                            wall_per_second_reason: (!meets).then(|| NOT_TIMED.to_string()),
                            timing: None,
                            cost_per_second: cost,
                            cost_per_second_reason: why,
                            strain_max: sub.metric(|m| m.strain_max),
                            energy_drift_rate: sub.metric(|m| m.energy_drift_rate),
                            measured_wall: sub.wall_seconds,
                        })
                    })
                    .collect::<Result<Vec<FrameEntry>>>()?;
                let (best, picked_by) = cheapest(&entries, scenario)?;
                Ok(FrameRate {
                    fps,
                    frame_dt: 1.0 / fps,
                    best,
                    picked_by,
                    entries,
                })
            })
            .collect()
    }

    /// The substepped run of entry `pi` at frame rate `fi`.
    fn run_of(&self, fi: usize, pi: usize, method: &str) -> TimedRun {
        let n = self.substeps[fi][pi];
        TimedRun {
            method: method.to_string(),
            dt: (1.0 / self.rates[fi]) / n as f64,
            steps: self.frames[fi] * n,
            substeps: None,
        }
    }

    /// The substepped runs to time, with the wall time their accuracy run measured: each
    /// rate's best entry, in view order.
    pub(super) fn timed_runs(&self, view: &[FrameRate]) -> Vec<(TimedRun, f64)> {
        let mut out = Vec::new();
        for (fi, fr) in view.iter().enumerate() {
            for (pi, e) in fr.entries.iter().enumerate() {
                if fr.best.as_deref() == Some(e.method.as_str()) {
                    out.push((self.run_of(fi, pi, &e.method), e.measured_wall));
                }
            }
        }
        out
    }

    /// Fills in each rate's best entry's wall time from `timing_of` (shown beside the modelled
    /// cost that ranked it) and says why every other entry that meets the tolerance has none.
    pub(super) fn apply_timings(
        &self,
        view: &mut [FrameRate],
        timing_of: &dyn Fn(&TimedRun) -> WallTimes,
    ) {
        for (fi, fr) in view.iter_mut().enumerate() {
            let best = fr.best.clone();
            for (pi, e) in fr.entries.iter_mut().enumerate() {
                if !e.meets_tolerance {
                    continue;
                }
                if best.as_deref() != Some(e.method.as_str()) {
                    e.wall_per_second_reason = Some(NOT_BEST.to_string());
                    continue;
                }
                let r = self.run_of(fi, pi, &e.method);
                let t = timing_of(&r);
                e.wall_per_second = Some(t.median_seconds / (r.dt * r.steps as f64));
                e.timing = Some(t);
            }
        }
    }
}

/// The cheapest of `entries` that meet the tolerance, by the advice's cost rule, with the rule
/// that decided.
fn cheapest(entries: &[FrameEntry], scenario: &str) -> Result<(Option<String>, Option<PickedBy>)> {
    let meeting: Vec<&FrameEntry> = entries
        .iter()
        .filter(|e| e.meets_tolerance && e.modelled_per_second.is_some())
        .collect();
    let keys: Vec<CostKey> = meeting
        .iter()
        .map(|e| CostKey {
            method: e.method.clone(),
            modelled_per_second: e.modelled_per_second.unwrap_or(f64::NAN),
            force_evals_per_second: e.cost_per_second,
        })
        .collect();
    let (order, picked_by) = rank(&keys, scenario)?;
    Ok((order.first().map(|&k| meeting[k].method.clone()), picked_by))
}
