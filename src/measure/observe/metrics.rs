//! Accuracy metrics of one run against a [`Reference`], computed on the fly by an
//! [`Observer`] so trajectories are never stored. Each metric is defined once, here.
//!
//! - Position error e(t) = max over particles |x_i(t) − x_ref,i(t)| (m), at the compared
//!   steps; reported as its final value, its maximum and its RMS over the compared steps.
//! - Relative energy error ε(t) = (total(t) − total(0)) / E, with `total` the
//!   [`EnergyRecord`] account (K + G + E + dissipated − injected, constant for the exact
//!   solution) and E = |K₀| + |G₀| + |E₀| (or the scene's energy scale when that is 0).
//!   Drift = least-squares slope of ε over t (1/s); oscillation = peak-to-peak of ε minus
//!   that line; balance = ε at the last step. Both are fitted to every observed state up to
//!   [`crate::measure::decimated::MAX_KEPT`] of them and to every 2^k-th past that, so
//!   memory is bounded whatever the step count; the largest |ε| and the balance use every
//!   state.
//! - Momentum drift = max over t of |P(t) − P(0) − Σ impulses so far| (kg·m/s), only for
//!   scenes where momentum is conserved (no fixed particles, gravity, drag or other terms).
//! - Constraint violation: max and mean over steps of the largest |‖x_j − x_i‖ − L|.
//! - Quality observables, needing no reference ([`QualityObserver`], which `run` uses on its
//!   own): strain max = max over the observed states (step 0 and every frame) of the largest
//!   |l/l0 − 1| of any spring with l0 > 0 or distance constraint ([`strain_max`]); energy drift
//!   rate = least-squares slope over t of the balance total(t) − total(0) (J/s, the absolute
//!   counterpart of the relative drift); rest jitter = kinetic energy at the last frame over the
//!   scene's [`energy_scale`] (the verdict's scale): the motion a method leaves in a scene that
//!   should have come to rest (elsewhere it is merely the kinetic share at the end). Penetration
//!   max is the contact metrics' deepest penetration
//!   ([`crate::measure::contacts::ContactReport::penetration_max`]), carried over, not
//!   measured again.
//! - Period and phase, only when the tracked velocity component has one dominant mode: the
//!   reference's zero crossings are evenly spaced
//!   ([`crate::measure::reference::period`]), else all four period fields are absent
//!   (null). The run's crossings (times from the cubic Hermite interpolant of each step)
//!   are matched to the reference's by time, never by count; period = spacing of the
//!   matched run crossings per reference interval between the first and last pair, period
//!   error relative to the reference's mean spacing T_ref, phase error 2π·(t − t_ref)/T_ref
//!   at the last pair.

use crate::error::Result;
use crate::measure::apexes::Apexes;
use crate::measure::decimated::Decimated;
use crate::measure::reference::period::match_crossings;
use crate::measure::reference::{Reference, Tracked};
use crate::measure::statistics::{Statistic, WindowReader};
use crate::model::{State, System, Vec3};
use crate::run::{energy_scale, EnergyRecord, Observer};
use serde::Serialize;
use std::collections::BTreeMap;

pub use crate::measure::observables::{bouncing, position_error, strain_max};

/// Least-squares line y = a + b t through points; returns (a, b). Fewer than two distinct
/// t give b = 0.
pub fn linear_fit(t: &[f64], y: &[f64]) -> (f64, f64) {
    let n = t.len() as f64;
    if t.is_empty() {
        return (0.0, 0.0);
    }
    let tm = t.iter().sum::<f64>() / n;
    let ym = y.iter().sum::<f64>() / n;
    let (mut stt, mut sty) = (0.0, 0.0);
    for (ti, yi) in t.iter().zip(y) {
        stt += (ti - tm) * (ti - tm);
        sty += (ti - tm) * (yi - ym);
    }
    let b = if stt > 0.0 { sty / stt } else { 0.0 };
    (ym - b * tm, b)
}

/// Peak-to-peak of y minus the line a + b t.
pub fn detrended_peak_to_peak(t: &[f64], y: &[f64], a: f64, b: f64) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (ti, yi) in t.iter().zip(y) {
        let r = yi - (a + b * ti);
        lo = lo.min(r);
        hi = hi.max(r);
    }
    if hi >= lo {
        hi - lo
    } else {
        0.0
    }
}

/// Where the velocity (dx/dt of the cubic Hermite interpolant through (x0, v0), (x1, v1) over
/// a step h) crosses zero upwards, as a fraction s in [0, 1] of the step.
pub fn hermite_upward_root(x0: f64, v0: f64, x1: f64, v1: f64, h: f64) -> f64 {
    // p'(s) = a s² + b s + c (times 1/h), the derivative of the Hermite cubic.
    let a = 6.0 * x0 + 3.0 * h * v0 - 6.0 * x1 + 3.0 * h * v1;
    let b = -6.0 * x0 - 4.0 * h * v0 + 6.0 * x1 - 2.0 * h * v1;
    let c = h * v0;
    let linear = -v0 / (v1 - v0);
    let roots: Vec<f64> = if a.abs() < 1e-300 {
        if b != 0.0 {
            vec![-c / b]
        } else {
            vec![]
        }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            vec![]
        } else {
            let q = -0.5 * (b + b.signum() * disc.sqrt());
            let mut r = vec![q / a];
            if q != 0.0 {
                r.push(c / q);
            }
            r
        }
    };
    roots
        .into_iter()
        .filter(|s| (0.0..=1.0).contains(s) && 2.0 * a * s + b >= 0.0)
        .min_by(|p, q| (p - linear).abs().total_cmp(&(q - linear).abs()))
        .unwrap_or(linear)
}

/// Every accuracy metric of one run (absent where it does not apply).
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Metrics {
    /// Position error at the last accepted step (m).
    pub error_final: f64,
    /// Maximum position error over the compared steps (m).
    pub error_max: f64,
    /// RMS position error over the compared steps (m).
    pub error_rms: f64,
    /// Number of compared steps.
    pub compared_steps: u64,
    /// Slope of the relative energy error (1/s).
    pub energy_drift: f64,
    /// Slope of the energy balance total(t) − total(0) (J/s): the drift in joules per second,
    /// from the same samples ([`Quality::energy_drift_rate`]).
    pub energy_drift_rate: f64,
    /// Peak-to-peak of the relative energy error about its linear fit.
    pub energy_oscillation: f64,
    /// Maximum |relative energy error|.
    pub energy_error_max: f64,
    /// Relative energy error of the full account (incl. dissipated and injected) at the end.
    pub energy_balance: f64,
    /// Work dissipated by dampers and drag (J) at the end.
    pub dissipated: f64,
    /// Energy injected by impulses (J) at the end.
    pub injected: f64,
    /// Max |ΔP| (kg·m/s) where momentum is conserved.
    pub momentum_drift: Option<f64>,
    /// Max constraint violation (m) where the scene has constraints.
    pub constraint_max: Option<f64>,
    /// Mean constraint violation (m).
    pub constraint_mean: Option<f64>,
    /// Largest strain |l/l0 − 1| of any spring (l0 > 0) or distance constraint over the run
    /// ([`Quality::strain_max`]).
    pub strain_max: f64,
    /// Deepest penetration into any obstacle over the run (m), read off the contact metrics
    /// ([`crate::measure::contacts::ContactReport::penetration_max`]). Absent (null) for a scene
    /// without obstacles, and where contacts were not measured (sweeps and advice leave them
    /// off, see [`crate::measure::case::CaseSettings::contacts`]).
    pub penetration_max: Option<f64>,
    /// Kinetic energy at the last frame over the scene's energy scale
    /// ([`Quality::rest_jitter`]); meaningful for scenes that come to rest.
    pub rest_jitter: f64,
    /// Measured period of the tracked component (s), from its crossings matched to the
    /// reference's. Absent (null), like the three below, when the reference's crossings do not
    /// show one dominant mode ([`crate::measure::reference::DOMINANT_MODE_UNCLEAR`]).
    pub period: Option<f64>,
    /// Reference period (s): the mean spacing of its evenly spaced crossings.
    pub period_reference: Option<f64>,
    /// (T − T_ref)/T_ref.
    pub period_error: Option<f64>,
    /// Phase error at the last matched crossing (rad), unwrapped over the run.
    pub phase_error: Option<f64>,
    /// Maximum position error over the compared steps before the reference's predictability
    /// horizon (m): what position error can verify; `error_max` where all is predictable.
    #[serde(default)]
    pub error_max_predictable: f64,
    /// |strain max − the reference's largest strain at the compared steps|: how much more (or
    /// less) the run stretches than the solution does.
    #[serde(default)]
    pub strain_error: f64,
    /// Past the predictability horizon, each observable of the run against the reference's
    /// ensemble ([`crate::measure::statistics`]); null where all is predictable or there is
    /// no ensemble.
    #[serde(default)]
    pub statistics: Option<BTreeMap<String, Statistic>>,
    /// On a scene with obstacles and gravity: the largest |apex height − the reference's|
    /// over matched bounces (m; [`crate::measure::apexes`]), which one impact's timing does not
    /// dominate; null elsewhere.
    #[serde(default)]
    pub apex_error: Option<f64>,
}

/// Decimated time series for plots (finite values only; a blow-up ends the series).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Series {
    /// Times (s).
    pub t: Vec<f64>,
    /// Position error (m).
    pub position_error: Vec<f64>,
    /// Relative energy error.
    pub energy_error: Vec<f64>,
    /// The energy account (every term, J).
    pub energy: Vec<EnergyRecord>,
}

/// The quality observables of one run that need no reference (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Quality {
    /// Largest |l/l0 − 1| of any spring (l0 > 0) or distance constraint over the observed
    /// states: step 0 and the end of every frame ([`strain_max`]).
    pub strain_max: f64,
    /// Least-squares slope over t of the energy balance total(t) − total(0) (J/s), `total`
    /// the [`EnergyRecord`] account (K + G + E + dissipated − injected), so damping's work is
    /// in it and an exact solution has slope 0.
    pub energy_drift_rate: f64,
    /// Kinetic energy at the last frame over the scene's [`energy_scale`]: what motion a
    /// method leaves in a scene that should have come to rest (numerical jitter). Reported for
    /// every run; where the scene is still moving at the end it is only its kinetic share.
    pub rest_jitter: f64,
}

/// The observer computing [`Quality`]: what `MetricsObserver` reports of it, and what
/// `run` reports without a reference. O(springs + constraints) per observed state.
pub struct QualityObserver<'a> {
    sys: &'a System,
    dt: f64,
    /// The scene's [`energy_scale`] over the run (J).
    scale: f64,
    e0: Option<f64>,
    /// The energy balance's least-squares line, updated state by state.
    fit: OnlineFit,
    strain_max: f64,
    kinetic: f64,
}

/// A least-squares slope updated one point at a time (Welford's running means and
/// co-moments), so a run of any length is fitted in constant memory: `run` streams its frames
/// and keeps none. Serial, so the same bits whatever the thread count.
#[derive(Debug, Clone, Copy, Default)]
struct OnlineFit {
    n: f64,
    mean_t: f64,
    mean_y: f64,
    /// Σ (t − t̄)(y − ȳ).
    sty: f64,
    /// Σ (t − t̄)².
    stt: f64,
}

impl OnlineFit {
    fn push(&mut self, t: f64, y: f64) {
        self.n += 1.0;
        let dt = t - self.mean_t;
        self.mean_t += dt / self.n;
        self.mean_y += (y - self.mean_y) / self.n;
        self.sty += dt * (y - self.mean_y);
        self.stt += dt * (t - self.mean_t);
    }
    /// The slope; 0 for fewer than two distinct t (as [`linear_fit`]).
    fn slope(&self) -> f64 {
        if self.stt > 0.0 {
            self.sty / self.stt
        } else {
            0.0
        }
    }
}

impl<'a> QualityObserver<'a> {
    /// Observes a run of `sys` from `s0` with frame step `dt` over `horizon` seconds (the
    /// horizon enters the energy scale as it does the runner's verdict).
    pub fn new(sys: &'a System, s0: &State, dt: f64, horizon: f64) -> Self {
        QualityObserver {
            sys,
            dt,
            scale: energy_scale(sys, s0, horizon),
            e0: None,
            fit: OnlineFit::default(),
            strain_max: 0.0,
            kinetic: 0.0,
        }
    }

    /// The observables of the states seen so far (call after the run).
    pub fn quality(&self) -> Quality {
        Quality {
            strain_max: self.strain_max,
            energy_drift_rate: self.fit.slope(),
            rest_jitter: if self.scale > 0.0 {
                self.kinetic / self.scale
            } else {
                0.0
            },
        }
    }
}

impl Observer for QualityObserver<'_> {
    fn observe(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        let e0 = *self.e0.get_or_insert(e.total);
        self.fit.push(step as f64 * self.dt, e.total - e0);
        self.strain_max = self.strain_max.max(strain_max(self.sys, &s.x));
        self.kinetic = e.kinetic;
        Ok(())
    }
}

/// The observer computing [`Metrics`] (and optionally a [`Series`]) of a run on grid `grid`
/// of a [`Reference`].
pub struct MetricsObserver<'a> {
    sys: &'a System,
    reference: &'a Reference,
    grid: usize,
    dt: f64,
    e0: Option<f64>,
    e_scale: f64,
    /// (t, relative energy error) of the observed states, decimated past
    /// [`crate::measure::decimated::MAX_KEPT`]: what the drift and oscillation are fitted to.
    energy: Decimated<[f64; 2]>,
    /// Largest |relative energy error| over every observed state.
    eps_abs_max: f64,
    /// Relative energy error of the last observed state.
    eps_last: f64,
    /// The quality observables, from the same observed states.
    quality: QualityObserver<'a>,
    err_sq: f64,
    m: Metrics,
    p0: Option<Vec3>,
    momentum: bool,
    cons_sum: f64,
    cons_n: u64,
    tracked: Option<Tracked>,
    prev: Option<(f64, f64, f64)>,
    crossings: Vec<f64>,
    /// True once the run crossed zero more than [`crate::measure::decimated::MAX_KEPT`] times: its
    /// period and phase are then not reported (no dominant mode to match).
    crossings_overflow: bool,
    series_stride: Option<u64>,
    /// The series, when asked for.
    pub series: Series,
    last_err: f64,
    /// The reference's largest strain at the compared steps.
    strain_ref: f64,
    /// Reads the statistics window, when the reference has an ensemble.
    window: Option<WindowReader>,
    /// Apex heights of the run and of the reference at the compared steps, on a scene with
    /// obstacles and gravity.
    apexes: Option<(Apexes, Apexes)>,
    /// `(divisor, bound)`: the run has seen enough once its position error before the
    /// predictability horizon, over `divisor`, passes `bound` ([`MetricsObserver::stop_past`]).
    stop_past: Option<(f64, f64)>,
}

impl<'a> MetricsObserver<'a> {
    /// Observes a run of step `dt` on grid `grid` of `reference`, from `s0` over `duration`;
    /// `series_points` > 0 records a series of at most about that many points.
    pub fn new(
        sys: &'a System,
        s0: &State,
        reference: &'a Reference,
        grid: usize,
        series_points: u64,
    ) -> Self {
        let g = reference.grids[grid];
        let quality = QualityObserver::new(sys, s0, g.dt, g.time(g.steps));
        let e = sys.state_energy(s0);
        let mut e_scale = e.kinetic.abs() + e.gravity.abs() + e.elastic.abs();
        if e_scale <= 0.0 {
            e_scale = quality.scale;
        }
        if e_scale <= 0.0 {
            e_scale = 1.0;
        }
        let momentum = sys.free.iter().all(|&f| f) && sys.gravity.is_none() && sys.terms.is_empty();
        let series_stride = (series_points > 0).then(|| {
            let samples = g.sample_count() as u64;
            g.stride * samples.div_ceil(series_points).max(1)
        });
        MetricsObserver {
            sys,
            reference,
            grid,
            dt: g.dt,
            e0: None,
            e_scale,
            energy: Decimated::default(),
            eps_abs_max: 0.0,
            eps_last: 0.0,
            quality,
            err_sq: 0.0,
            m: Metrics {
                constraint_max: (!sys.constraints.is_empty()).then_some(0.0),
                ..Default::default()
            },
            p0: None,
            momentum,
            cons_sum: 0.0,
            cons_n: 0,
            tracked: reference.tracked,
            prev: None,
            crossings: Vec::new(),
            crossings_overflow: false,
            series_stride,
            series: Series::default(),
            last_err: 0.0,
            strain_ref: 0.0,
            window: reference
                .ensemble
                .as_ref()
                .map(|e| WindowReader::new(&e.times, g.dt, g.steps)),
            apexes: bouncing(sys).then(|| {
                let threshold =
                    crate::measure::observables::RELATIVE_TOLERANCE * reference.motion_scale();
                let gravity = sys.gravity.expect("a bouncing scene has gravity");
                let a = Apexes::new(gravity, &sys.free, threshold);
                (a.clone(), a)
            }),
            stop_past: None,
        }
    }

    /// Ends the run (through [`Observer::seen_enough`]) once its largest position error
    /// before the predictability horizon, divided by `divisor`, exceeds `bound`: that error only
    /// grows, so a judge holding it to `bound` can no longer pass the run
    /// ([`crate::measure::tolerance::Judge::position_stop`]).
    pub fn stop_past(mut self, (divisor, bound): (f64, f64)) -> Self {
        self.stop_past = Some((divisor, bound));
        self
    }

    /// The metrics of the steps seen so far (call after the run).
    pub fn metrics(&self) -> Metrics {
        let mut m = self.m.clone();
        if m.compared_steps > 0 {
            m.error_rms = (self.err_sq / m.compared_steps as f64).sqrt();
        }
        m.error_final = self.last_err;
        let (t, eps): (Vec<f64>, Vec<f64>) =
            self.energy.kept().iter().map(|p| (p[0], p[1])).unzip();
        let (a, b) = linear_fit(&t, &eps);
        m.energy_drift = b;
        m.energy_oscillation = detrended_peak_to_peak(&t, &eps, a, b);
        m.energy_error_max = self.eps_abs_max;
        m.energy_balance = self.eps_last;
        let q = self.quality.quality();
        m.strain_max = q.strain_max;
        m.energy_drift_rate = q.energy_drift_rate;
        m.rest_jitter = q.rest_jitter;
        m.strain_error = (q.strain_max - self.strain_ref).abs();
        m.apex_error = self.apexes.as_ref().and_then(|(a, r)| a.error(r));
        if let (Some(w), Some(e)) = (&self.window, &self.reference.ensemble) {
            m.statistics = w.observed().map(|o| e.judge(&o));
        }
        if self.cons_n > 0 {
            m.constraint_mean = Some(self.cons_sum / self.cons_n as f64);
        }
        let period = self
            .reference
            .dominant_period()
            .ok()
            .filter(|_| !self.crossings_overflow);
        if let Some(t_ref) = period {
            let rc = &self.reference.crossings;
            let pairs = match_crossings(rc, &self.crossings, t_ref);
            m.period_reference = Some(t_ref);
            if let (Some(&(k0, c0)), Some(&(k1, c1))) = (pairs.first(), pairs.last()) {
                if k1 > k0 {
                    let p = (c1 - c0) / (k1 - k0) as f64;
                    m.period = Some(p);
                    m.period_error = Some((p - t_ref) / t_ref);
                }
                m.phase_error = Some(std::f64::consts::TAU * (c1 - rc[k1]) / t_ref);
            }
        }
        m
    }
}

impl Observer for MetricsObserver<'_> {
    fn seen_enough(&self) -> bool {
        self.stop_past
            .is_some_and(|(d, b)| self.m.error_max_predictable / d > b)
    }
    fn observe(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        let t = step as f64 * self.dt;
        let e0 = *self.e0.get_or_insert(e.total);
        let eps = (e.total - e0) / self.e_scale;
        self.energy.push([t, eps]);
        self.eps_abs_max = self.eps_abs_max.max(eps.abs());
        self.eps_last = eps;
        self.quality.observe(step, s, e)?;
        if let Some(w) = &mut self.window {
            w.observe(self.sys, step, s);
        }
        self.m.dissipated = e.dissipated;
        self.m.injected = e.injected;
        let mut err_now = None;
        if let Some(xr) = self.reference.positions(self.grid, step) {
            let err = position_error(&s.x, xr);
            self.m.error_max = self.m.error_max.max(err);
            if self.reference.predictable_at(t) {
                self.m.error_max_predictable = self.m.error_max_predictable.max(err);
            }
            if let Some(s) = self.reference.strain_max_until(self.sys, self.grid, step) {
                self.strain_ref = s;
            }
            if let Some((a, r)) = &mut self.apexes {
                a.push(&s.x);
                r.push(xr);
            }
            self.err_sq += err * err;
            self.m.compared_steps += 1;
            self.last_err = err;
            err_now = Some(err);
        }
        if self.momentum {
            let p = self.sys.momentum(&s.v);
            let p0 = *self.p0.get_or_insert(p);
            let kicks: Vec3 = self
                .sys
                .impulses
                .iter()
                .filter(|im| self.sys.events.applied_at(im.time, self.dt) < t - 1e-9 * self.dt)
                .map(|im| im.delta_v * self.sys.mass[im.particle])
                .sum();
            let d = (p - p0 - kicks).norm();
            self.m.momentum_drift = Some(self.m.momentum_drift.unwrap_or(0.0).max(d));
        }
        if !self.sys.constraints.is_empty() {
            let c = self.sys.constraint_violation(&s.x);
            self.m.constraint_max = Some(self.m.constraint_max.unwrap_or(0.0).max(c));
            self.cons_sum += c;
            self.cons_n += 1;
        }
        if let Some(tr) = self.tracked {
            let (x1, v1) = (s.x[tr.particle][tr.axis], s.v[tr.particle][tr.axis]);
            if let Some((t0, x0, v0)) = self.prev {
                if v0 < 0.0 && v1 >= 0.0 {
                    let h = t - t0;
                    let sfrac = hermite_upward_root(x0, v0, x1, v1, h);
                    if self.crossings.len() < crate::measure::decimated::MAX_KEPT {
                        self.crossings.push(t0 + sfrac * h);
                    } else {
                        self.crossings_overflow = true;
                    }
                }
            }
            self.prev = Some((t, x1, v1));
        }
        if let (Some(stride), Some(err)) = (self.series_stride, err_now) {
            let last = self.reference.grids[self.grid].steps;
            if step % stride == 0 || step == last {
                self.series.t.push(t);
                self.series.position_error.push(err);
                self.series.energy_error.push(eps);
                self.series.energy.push(*e);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_fit_recovers_a_line_and_ptp_of_a_sine() {
        // Oracle: y = 2 + 3t exactly; then y + 0.5 cos(2πt) (orthogonal to t over whole periods) adds peak-to-peak ≈ 1 about the line.
        let t: Vec<f64> = (0..1001).map(|i| i as f64 * 0.01).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 + 3.0 * t).collect();
        let (a, b) = linear_fit(&t, &y);
        assert!((a - 2.0).abs() < 1e-12 && (b - 3.0).abs() < 1e-12);
        let y2: Vec<f64> = t
            .iter()
            .map(|t| 2.0 + 3.0 * t + 0.5 * (2.0 * std::f64::consts::PI * t).cos())
            .collect();
        let (a, b) = linear_fit(&t, &y2);
        assert!((b - 3.0).abs() < 0.05);
        let ptp = detrended_peak_to_peak(&t, &y2, a, b);
        assert!((ptp - 1.0).abs() < 0.02, "{ptp}");
    }

    #[test]
    fn the_streamed_slope_is_the_two_pass_slope() {
        // Oracle: the two-pass least-squares formula (linear_fit) on the same points: a line
        // 2 + 3t exactly, then a line plus a cosine; a single point has slope 0 in both.
        let t: Vec<f64> = (0..1001).map(|i| i as f64 * 0.01).collect();
        for y in [
            t.iter().map(|t| 2.0 + 3.0 * t).collect::<Vec<f64>>(),
            t.iter().map(|t| -1.0 + 0.5 * t + (7.0 * t).cos()).collect(),
        ] {
            let mut fit = OnlineFit::default();
            for (ti, yi) in t.iter().zip(&y) {
                fit.push(*ti, *yi);
            }
            let b = linear_fit(&t, &y).1;
            assert!(
                (fit.slope() - b).abs() < 1e-12 * b.abs(),
                "{} {b}",
                fit.slope()
            );
        }
        let mut one = OnlineFit::default();
        one.push(1.0, 5.0);
        assert_eq!(one.slope(), 0.0);
    }

    #[test]
    fn hermite_root_finds_the_minimum_of_a_cosine() {
        // x = cos t has v = -sin t crossing zero upwards at t = π.
        let (t0, h) = (3.0f64, 0.3f64);
        let s = hermite_upward_root(t0.cos(), -t0.sin(), (t0 + h).cos(), -(t0 + h).sin(), h);
        let tc = t0 + s * h;
        assert!((tc - std::f64::consts::PI).abs() < 1e-4, "{tc}");
    }
}
