//! Accuracy past the predictability horizon: a method against an *ensemble* of references.
//!
//! Past the reference's predictability horizon ([`crate::measure::reference::ReferenceInfo`]) two
//! correct solvers part by macroscopic amounts, so position error measures the chaos, not the
//! method. What stays meaningful is the *statistics* of the motion: an ensemble of
//! [`ENSEMBLE_SIZE`] references, each started from the initial positions moved at the
//! reference's own uncertainty (see `reference/ensemble.rs`), spans what a correct
//! solution may do; a method is consistent when each observable of its run lies within that
//! span.
//!
//! Observables, each one number per run: its time-mean over the window [horizon, end], sampled
//! at [`WINDOW_SAMPLES`] evenly spaced times (a run at step dt is read at the step nearest each
//! time, at most dt/2 away; means, not extremes, so a run read at coarse frames is not judged
//! by the peaks its frames happen to miss):
//! - `com_x`, `com_y`, `com_z`: time-mean of the free particles' centre of mass (m);
//! - `radius_of_gyration`: time-mean of √(Σ m |x − com|² / Σ m) over free particles (m), the
//!   size of the shape: a stretched cloth is larger;
//! - `kinetic_energy`: time-mean of ½ Σ m v² (J): an over-damped run has less;
//! - `strain_max`: time-mean of the largest |l/l0 − 1| over springs and rods at each sample
//!   ([`crate::measure::metrics::strain_max`]): a stretched cloth's is larger.
//!
//! Consistency test, per observable: |method − ensemble mean| ≤ [`SPREADS`] × spread + floor,
//! where spread is the ensemble's sample standard deviation (n − 1) and floor what the
//! tolerance allows where the ensemble barely spreads (an observable the chaos does not touch,
//! such as the centre of mass of a falling cloth): the position tolerance for lengths; for
//! kinetic energy, which goes as speed squared, twice the tolerance relative to the motion
//! scale times |ensemble mean|; for strain, that relative tolerance times the larger of
//! |ensemble mean| and 1 (strain is dimensionless: never a floor below the tolerance itself).
//! The score of an observable is |method − mean| / (SPREADS × spread + floor): at most 1 is
//! consistent.

use crate::measure::observables::strain_max;
use crate::model::{State, System, Vec3};
use serde::Serialize;
use std::collections::BTreeMap;

/// References in an ensemble.
pub const ENSEMBLE_SIZE: usize = 8;

/// Sample times over the window past the horizon.
pub const WINDOW_SAMPLES: usize = 200;

/// Ensemble standard deviations within which a method is consistent (about 99.7 % of a normal
/// distribution; with eight members the spread itself is uncertain by about a quarter).
pub const SPREADS: f64 = 3.0;

/// The observables' names, in the order of [`Observed`].
pub const OBSERVABLES: [&str; 6] = [
    "com_x",
    "com_y",
    "com_z",
    "radius_of_gyration",
    "kinetic_energy",
    "strain_max",
];

/// One run's observables over the window, in the order of [`OBSERVABLES`].
pub type Observed = [f64; 6];

/// Instantaneous values at one state: centre of mass (3), radius of gyration, kinetic energy,
/// strain (free particles only: a fixed one does not move).
pub fn instant(sys: &System, x: &[Vec3], v: &[Vec3]) -> Observed {
    let (mut m, mut c, mut k) = (0.0, Vec3::zeros(), 0.0);
    for p in 0..x.len() {
        if sys.free[p] {
            m += sys.mass[p];
            c += sys.mass[p] * x[p];
            k += 0.5 * sys.mass[p] * v[p].norm_squared();
        }
    }
    let com = if m > 0.0 { c / m } else { Vec3::zeros() };
    let mut g = 0.0;
    for p in 0..x.len() {
        if sys.free[p] {
            g += sys.mass[p] * (x[p] - com).norm_squared();
        }
    }
    let rg = if m > 0.0 { (g / m).sqrt() } else { 0.0 };
    [com.x, com.y, com.z, rg, k, strain_max(sys, x)]
}

/// Accumulates [`instant`] values into a run's [`Observed`]: their means. Samples are added in
/// time order, serially (same bits whatever the threads).
#[derive(Debug, Clone, Default)]
pub struct Accumulator {
    sum: [f64; 6],
    n: usize,
}

impl Accumulator {
    /// Adds one sample.
    pub fn push(&mut self, o: &Observed) {
        for k in 0..6 {
            self.sum[k] += o[k];
        }
        self.n += 1;
    }
    /// Samples added.
    pub fn count(&self) -> usize {
        self.n
    }
    /// The run's observables.
    pub fn observed(&self) -> Observed {
        let n = self.n.max(1) as f64;
        self.sum.map(|v| v / n)
    }
}

/// The window's sample times: [`WINDOW_SAMPLES`] evenly spaced from `start` to `end`, none
/// past `end` (start + (end − start) can round one ulp above it, a time no solve reaches).
pub fn window_times(start: f64, end: f64) -> Vec<f64> {
    let n = WINDOW_SAMPLES;
    (0..n)
        .map(|i| (start + (end - start) * i as f64 / (n - 1) as f64).min(end))
        .collect()
}

/// The ensemble's verdict material: every member's observables and the allowances.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ensemble {
    /// Start of the window: the reference's predictability horizon (s).
    pub start: f64,
    /// End of the window (s).
    pub end: f64,
    /// The window's sample times (s).
    #[serde(skip)]
    pub times: Vec<f64>,
    /// Each member's observables.
    pub members: Vec<Observed>,
    /// Position tolerance behind the length floors (m).
    pub tolerance: f64,
    /// Tolerance relative to the motion scale, behind the energy and strain floors.
    pub relative_tolerance: f64,
    /// How the members were made, in one sentence.
    pub made_by: String,
    /// The scene grid whose reference made it (its window and member solver come from it).
    #[serde(skip)]
    pub grid: Option<crate::measure::grid::TimeGrid>,
}

/// One observable of one run against the ensemble.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct Statistic {
    /// The run's value.
    pub run_mean: f64,
    /// Mean over the ensemble's members.
    pub ensemble_mean: f64,
    /// Sample standard deviation over the members.
    pub ensemble_spread: f64,
    /// What the tolerance allows beyond the spread.
    pub floor: f64,
    /// |method − mean| / (SPREADS × spread + floor).
    pub score: f64,
    /// score ≤ 1.
    pub consistent: bool,
}

impl Ensemble {
    /// The mean and sample standard deviation of observable `k` over the members.
    fn moments(&self, k: usize) -> (f64, f64) {
        let n = self.members.len() as f64;
        let mean = self.members.iter().map(|m| m[k]).sum::<f64>() / n;
        let var = self
            .members
            .iter()
            .map(|m| (m[k] - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0).max(1.0);
        (mean, var.sqrt())
    }

    /// The floor of observable `k` whose ensemble mean is `mean` (see the module docs).
    fn floor(&self, k: usize, mean: f64) -> f64 {
        match k {
            0..=3 => self.tolerance,
            4 => 2.0 * self.relative_tolerance * mean.abs(),
            _ => self.relative_tolerance * mean.abs().max(1.0),
        }
    }

    /// Every observable of a run (`observed`) against the ensemble, by name.
    pub fn judge(&self, observed: &Observed) -> BTreeMap<String, Statistic> {
        OBSERVABLES
            .iter()
            .enumerate()
            .map(|(k, name)| {
                let (mean, spread) = self.moments(k);
                let floor = self.floor(k, mean);
                let allowed = SPREADS * spread + floor;
                let dev = (observed[k] - mean).abs();
                let score = if allowed > 0.0 {
                    dev / allowed
                } else if dev == 0.0 {
                    0.0
                } else {
                    f64::INFINITY
                };
                let s = Statistic {
                    run_mean: observed[k],
                    ensemble_mean: mean,
                    ensemble_spread: spread,
                    floor,
                    score,
                    consistent: score <= 1.0,
                };
                (name.to_string(), s)
            })
            .collect()
    }
}

/// The worst score of a judged run: at most 1 when every observable is consistent.
pub fn worst_score(stats: &BTreeMap<String, Statistic>) -> f64 {
    stats.values().map(|s| s.score).fold(0.0, f64::max)
}

/// Reads a run's observables at the steps nearest the window's sample times (each time once,
/// so a coarse run reads some steps several times and every run weighs the window alike).
#[derive(Debug, Clone)]
pub struct WindowReader {
    /// For each sample time, the step read there, ascending.
    steps: Vec<u64>,
    next: usize,
    acc: Accumulator,
}

impl WindowReader {
    /// The reader of a run of step `dt` and `total` steps over `times`.
    pub fn new(times: &[f64], dt: f64, total: u64) -> Self {
        WindowReader {
            steps: times
                .iter()
                .map(|t| ((t / dt).round() as u64).min(total))
                .collect(),
            next: 0,
            acc: Accumulator::default(),
        }
    }

    /// Observes step `step` of the run at state `s`.
    pub fn observe(&mut self, sys: &System, step: u64, s: &State) {
        if self.steps.get(self.next) != Some(&step) {
            return;
        }
        let o = instant(sys, &s.x, &s.v);
        while self.steps.get(self.next) == Some(&step) {
            self.acc.push(&o);
            self.next += 1;
        }
    }

    /// The observables, when the run reached every sample time.
    pub fn observed(&self) -> Option<Observed> {
        (self.next == self.steps.len()).then(|| self.acc.observed())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ensemble(members: Vec<Observed>) -> Ensemble {
        Ensemble {
            start: 0.0,
            end: 1.0,
            times: vec![],
            members,
            tolerance: 0.01,
            relative_tolerance: 0.01,
            made_by: String::new(),
            grid: None,
        }
    }

    // Oracle: IEEE arithmetic. 5.831 + (20 − 5.831) rounds to 20.000000000000004, a time past
    // the run's end that no member's solve reaches; the window must end at the end itself.
    // Twin: a start whose sum lands exactly keeps its evenly spaced times unchanged.
    #[test]
    fn the_window_never_passes_the_end() {
        let t = window_times(5.831, 20.0);
        assert_eq!((t[0], *t.last().unwrap()), (5.831, 20.0));
        assert!(t.windows(2).all(|w| w[0] < w[1]));
        let u = window_times(5.832, 20.0);
        assert_eq!(u[100], 5.832 + (20.0 - 5.832) * 100.0 / 199.0);
        assert_eq!(*u.last().unwrap(), 20.0);
    }

    // Oracle: the sample mean and the n − 1 standard deviation worked by hand for members
    // 1, 2, 3 (mean 2, s = 1); allowance 3·1 + 0.01 for a length.
    #[test]
    fn the_score_is_the_deviation_over_the_allowance() {
        let m = |v: f64| [v, 0.0, 0.0, 0.0, 0.0, 0.0];
        let e = ensemble(vec![m(1.0), m(2.0), m(3.0)]);
        let s = e.judge(&m(2.0 + 3.01))["com_x"];
        assert_eq!((s.ensemble_mean, s.ensemble_spread), (2.0, 1.0));
        assert!((s.score - 1.0).abs() < 1e-12 && s.consistent, "{s:?}");
        let twin = e.judge(&m(2.0 + 3.02))["com_x"];
        assert!(!twin.consistent, "{twin:?}");
    }

    // Oracle: a spread of zero leaves the floor alone: exactly the tolerance for a length.
    #[test]
    fn a_spreadless_observable_is_held_to_the_tolerance() {
        let m = |v: f64| [0.0, 0.0, 0.0, v, 0.0, 0.0];
        let e = ensemble(vec![m(1.0); 4]);
        assert!(e.judge(&m(1.009))["radius_of_gyration"].consistent);
        assert!(!e.judge(&m(1.011))["radius_of_gyration"].consistent);
    }
}
