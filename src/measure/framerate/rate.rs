//! One method at one frame rate: its run at one substep and the search for the fewest
//! substeps that meet the bound, against the reference shared by every rate.

use super::rows::RateEntry;
use super::{frame_run, no_fewest_note, search, FramerateConfig};
use crate::error::Result;
use crate::measure::case::{run_case, CaseResult, CaseSettings};
use crate::measure::reference::Reference;
use crate::measure::tolerance::Judge;
use crate::model::{State, System};

/// What every method's search at every rate shares: the scene, its reference and judge, the
/// runs' settings, and per rate and per method what the search starts from.
pub(super) struct RateSearch<'a> {
    /// The options of the table.
    pub(super) cfg: &'a FramerateConfig,
    /// The scene's system.
    pub(super) sys: &'a System,
    /// Its initial state.
    pub(super) s0: &'a State,
    /// The reference, sampled on every rate's frame grid (grid `r` is rate `r`'s).
    pub(super) reference: &'a Reference,
    /// What decides a run's error and whether it meets the bound.
    pub(super) judge: &'a Judge,
    /// The settings of every run (the substeps and the early stop set per run).
    pub(super) set: &'a CaseSettings,
    /// The methods searched.
    pub(super) names: &'a [String],
    /// Whole frames at each rate.
    pub(super) frames: &'a [u64],
    /// The frame-event floor at each rate ([`super::frame_event_floor`]).
    pub(super) floors: &'a [Option<f64>],
    /// Each method's largest stable step by its linear theory, where known.
    pub(super) starts: &'a [Option<f64>],
    /// Particles of the scene (at least 1), for the cost cap in particle-steps.
    pub(super) particles: f64,
    /// Whether the search may predict counts from the runs' errors ([`search`]): a smooth
    /// scene, without obstacles or kicks.
    pub(super) guided: bool,
}

impl RateSearch<'_> {
    /// Method `b` at rate `r`: its run at one substep and the fewest substeps that meet the
    /// bound, searched from the theory's count up to the substep and cost caps.
    pub(super) fn entry(&self, b: usize, r: usize) -> Result<RateEntry> {
        let cfg = self.cfg;
        let judge = self.judge;
        let name = &self.names[b];
        let mut runs: Vec<(u64, CaseResult)> = Vec::new();
        let mut trial = |n: u64| -> Result<Option<search::Probe>> {
            if let Some(cap) = cfg.cost_cap {
                if n > 1 && self.particles * self.frames[r] as f64 * n as f64 > cap {
                    return Ok(None);
                }
            }
            // One substep is the table's row, shown whole; any other count only has to
            // pass or fail (a pass is shown, and never stops early).
            let s = CaseSettings {
                substeps: Some(n),
                stop: (n > 1).then(|| judge.position_stop()).flatten(),
                ..self.set.clone()
            };
            let c = run_case(self.sys, self.s0, self.reference, r, name, &s)?;
            let probe = search::Probe {
                passes: judge.meets(&c),
                excess: judge.error(&c).map(|e| e / judge.bound),
                blew_up: c.unstable_time,
            };
            runs.push((n, c));
            Ok(Some(probe))
        };
        let start = self.starts[b].map_or(1, |h| (1.0 / (cfg.rates[r] * h)).ceil() as u64);
        let found = search::fewest_substeps_from(start, cfg.max_substeps, self.guided, &mut trial)?;
        let of = |n: u64| {
            runs.iter()
                .find(|(m, _)| *m == n)
                .map(|(_, c)| c)
                .expect("every tried count has its run")
        };
        let one = frame_run(cfg, of(1), 1, judge)?;
        let fewest = match found.fewest {
            Some(n) => Some(frame_run(cfg, of(n), n, judge)?),
            None => None,
        };
        let largest = found.tried.iter().map(|t| t.0).max().unwrap_or(1);
        let fewest_note = fewest
            .is_none()
            .then(|| no_fewest_note(cfg, largest, self.floors[r], judge.tolerance.value));
        Ok(RateEntry {
            method: name.clone(),
            hz: cfg.rates[r],
            frame_dt: 1.0 / cfg.rates[r],
            frames: self.frames[r],
            one_substep: one,
            fewest,
            fewest_note,
            frame_event_floor: self.floors[r],
            tried: found.tried,
        })
    }
}
