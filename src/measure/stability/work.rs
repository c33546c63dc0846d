//! The work of the empirical searches as they run: each trial's modelled cost counted against
//! the search's allowance (what the budget leaves it beside the other searches' projections),
//! and the progress shown as modelled work done out of work planned, not searches done.
//!
//! Why: a search's projection prices its trials at its first step, but a search that halves
//! its step doubles each trial's cost, so one search could run for minutes past the budget
//! while the progress line, counting searches, said it was nearly done.

use crate::measure::probe::sig3;
use indicatif::ProgressBar;

/// Progress units per modelled second: the bar counts modelled milliseconds of trials.
pub const UNITS_PER_SECOND: f64 = 1e3;

/// One search's account: what it was projected to cost, what it spent, what it may spend.
#[derive(Debug)]
pub struct SearchWork<'a> {
    bar: &'a ProgressBar,
    projected: f64,
    spent: f64,
    shown: f64,
    allowance: Option<f64>,
    per_step: Option<f64>,
}

impl<'a> SearchWork<'a> {
    /// The account of a search projected at `projected` modelled seconds, allowed `allowance`
    /// (`None`: no limit), shown on `bar` (whose length already holds `projected`).
    pub fn new(bar: &'a ProgressBar, projected: f64, allowance: Option<f64>) -> Self {
        SearchWork {
            bar,
            projected,
            spent: 0.0,
            shown: 0.0,
            allowance,
            per_step: None,
        }
    }

    /// Why a trial of `steps` steps may not start (its projected cost, priced at the last
    /// trial's cost per step, would take the search past its allowance); `None`: it may.
    pub fn refuse(&self, steps: u64) -> Option<String> {
        let (allowance, per) = (self.allowance?, self.per_step?);
        let next = per * steps as f64;
        (self.spent + next > allowance).then(|| {
            format!(
                "search stopped by the budget: its trials took {} s of modelled work and the next ({} steps) would take about {} s more, past the {} s the budget of the command leaves it beside the other searches; `--budget` raises it",
                sig3(self.spent),
                steps,
                sig3(next),
                sig3(allowance)
            )
        })
    }

    /// Books a trial that cost `seconds` (modelled) over `steps` steps.
    pub fn book(&mut self, seconds: f64, steps: u64) {
        let old_len = self.planned();
        self.spent += seconds;
        if steps > 0 {
            self.per_step = Some(seconds / steps as f64);
        }
        self.bar.inc_length(units(self.planned()) - units(old_len));
        self.bar.inc(units(self.spent) - units(self.shown));
        self.shown = self.spent;
    }

    /// The work this search counts in the bar's total: its projection, or once it has spent
    /// more, the most it may spend (its allowance), so the time left is never understated.
    fn planned(&self) -> f64 {
        if self.spent <= self.projected {
            self.projected
        } else {
            self.allowance.map_or(self.spent, |a| a.max(self.spent))
        }
    }

    /// The search ended: the rest of the work it counted in the total is done.
    pub fn finish(&mut self) {
        let planned = self.planned();
        if planned > self.shown {
            self.bar.inc(units(planned) - units(self.shown));
            self.shown = planned;
        }
    }
}

/// `seconds` of modelled work in progress units.
pub fn units(seconds: f64) -> u64 {
    (seconds * UNITS_PER_SECOND).round() as u64
}
