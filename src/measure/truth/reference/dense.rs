//! An adaptive solve kept whole: the positions part of DOP853's dense output for every
//! accepted step, so one solve can be sampled at any time, on any number of grids, long after
//! it ran.
//!
//! Each stored step holds its start and end positions and the seven dense-output rows
//! (Hairer's contd8, [`crate::measure::dop853::interpolate`]); a sample inside a step is the
//! same arithmetic on the same numbers as sampling the live solver there, so it is the same
//! bits. A step ended by a contact event is valid only up to the event, and each segment after
//! an impulse or event starts a new run of steps: a sample at a restart time comes from the
//! step that ends there (the state just before the restart), and no sample interpolates
//! across one.
//!
//! Each sample inside a step carries the interpolant's error estimate: the distance between
//! the 7th-order interpolant and its truncation by the last two rows. The extra stages' rows
//! do not shrink one by one (dropping only the last row underestimates the error about 6× on
//! the oscillator), so the estimate drops two; it is one order lower in the step than the
//! error, so it overestimates more the shorter the step (on the oscillator, ≈ the error at
//! ωh = 0.8, 3× it at ωh = 0.4, more at the steps a 1e-12 tolerance takes).
//!
//! Memory is bounded: a track stops recording past its byte limit and says so
//! ([`DenseTrack::complete`]); the reference then falls back to solving on its grids.

use crate::measure::dop853::{interpolate, Dop853, DENSE_ROWS};
use crate::model::Vec3;

/// One stored step: valid on [`Step::t_old`, `Step::t_end`] (the end is the step's own end
/// or an event inside it).
#[derive(Debug, Clone, Copy)]
struct Step {
    t_old: f64,
    t_new: f64,
    t_end: f64,
    at: usize,
}

/// Rows of the truncated interpolant whose distance to the full one is the error estimate.
const ESTIMATE_ROWS: usize = DENSE_ROWS - 2;

/// Rows per stored step: start, end, then the dense-output rows.
const ROWS: usize = 2 + DENSE_ROWS;

/// The positions part of an adaptive solve's dense output, step by step.
#[derive(Debug, Clone)]
pub(super) struct DenseTrack {
    n3: usize,
    start: Vec<f64>,
    steps: Vec<Step>,
    data: Vec<f64>,
    limit: usize,
    overflow: bool,
}

impl DenseTrack {
    /// An empty track of `n` particles starting from positions `y0` (the first 3n entries of
    /// the state vector), recording at most `limit` bytes.
    pub(super) fn new(n: usize, y0: &[f64], limit: usize) -> Self {
        DenseTrack {
            n3: 3 * n,
            start: y0[..3 * n].to_vec(),
            steps: Vec::new(),
            data: Vec::new(),
            limit,
            overflow: false,
        }
    }

    /// Records the solver's last accepted step, valid up to `t_end` (its end, or an event
    /// inside it); the solver's dense output must be prepared.
    pub(super) fn record(&mut self, solver: &Dop853, t_end: f64) {
        if self.overflow {
            return;
        }
        if (self.data.len() + ROWS * self.n3) * 8 > self.limit {
            self.overflow = true;
            self.steps = Vec::new();
            self.data = Vec::new();
            return;
        }
        let at = self.data.len();
        self.data.extend_from_slice(&solver.y_old[..self.n3]);
        self.data.extend_from_slice(&solver.y[..self.n3]);
        for row in solver.dense_rows() {
            self.data.extend_from_slice(&row[..self.n3]);
        }
        self.steps.push(Step {
            t_old: solver.t_old,
            t_new: solver.t,
            t_end,
            at,
        });
    }

    /// True when every step was recorded (the track stayed within its byte limit).
    pub(super) fn complete(&self) -> bool {
        !self.overflow
    }

    /// Bytes held.
    pub(super) fn bytes(&self) -> usize {
        8 * (self.data.len() + self.start.len())
    }

    /// Positions at time `t` and the interpolant's error estimate there (m, largest over
    /// particles; 0 at a stored state): from the first step whose valid range ends at or after
    /// `t`, so a restart time is sampled just before the restart.
    pub(super) fn sample(&self, t: f64) -> (Vec<Vec3>, f64) {
        self.sample_with(t, true)
    }

    /// Positions at time `t` alone, the same bits as [`DenseTrack::sample`]'s, without the
    /// error estimate (a companion solve's samples need only their distance to the main one).
    pub(super) fn positions(&self, t: f64) -> Vec<Vec3> {
        self.sample_with(t, false).0
    }

    /// [`DenseTrack::sample`], the estimate computed only when `estimate` (else 0).
    fn sample_with(&self, t: f64, estimate: bool) -> (Vec<Vec3>, f64) {
        let k = self.steps.partition_point(|s| s.t_end < t);
        let Some(s) = self.steps.get(k).filter(|_| t > 0.0 || k > 0) else {
            let y = if t <= 0.0 || self.steps.is_empty() {
                &self.start[..]
            } else {
                let s = self.steps[self.steps.len() - 1];
                self.row(&s, 1)
            };
            return (to_vec3(y), 0.0);
        };
        if t == s.t_new {
            return (to_vec3(self.row(s, 1)), 0.0);
        }
        let x = (t - s.t_old) / (s.t_new - s.t_old);
        let y_old = self.row(s, 0);
        let mut y = vec![0.0; self.n3];
        let mut err = 0.0_f64;
        for p in 0..self.n3 / 3 {
            let mut d2 = 0.0;
            for c in 0..3 {
                let i = 3 * p + c;
                let row = |r: usize| self.row(s, 2 + r)[i];
                y[i] = interpolate(row, x, DENSE_ROWS) + y_old[i];
                if estimate {
                    let lower = interpolate(row, x, ESTIMATE_ROWS) + y_old[i];
                    d2 += (y[i] - lower).powi(2);
                }
            }
            err = err.max(d2.sqrt());
        }
        (to_vec3(&y), err)
    }

    fn row(&self, s: &Step, r: usize) -> &[f64] {
        let a = s.at + r * self.n3;
        &self.data[a..a + self.n3]
    }
}

/// Positions from 3n numbers.
pub(super) fn to_vec3(y: &[f64]) -> Vec<Vec3> {
    y.chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the harmonic oscillator x'' = -x, x(t) = cos t, v(t) = -sin t, as three
    // particles' worth of unknowns (the first particle's x and the velocity part moving).
    fn osc(_t: f64, y: &[f64], d: &mut [f64]) {
        d.fill(0.0);
        d[0] = y[3];
        d[3] = -y[0];
    }

    /// The track of one fixed step of `h` from t = 0: the interpolant's worst error against
    /// cos t inside the step.
    fn one_step(h: f64) -> f64 {
        let y0 = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let mut s = Dop853::new(6, 1e-12, 1e-12);
        let mut f = osc;
        s.start(&mut f, 0.0, &y0, h);
        s.step_fixed(&mut f, h);
        s.prepare_dense(&mut f);
        let mut track = DenseTrack::new(1, &y0, 1 << 20);
        track.record(&s, s.t);
        (1..20)
            .map(|k| {
                let t = h * k as f64 / 20.0;
                let (x, est) = track.sample(t);
                assert!(est > 0.0);
                (x[0].x - t.cos()).abs()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn interpolant_has_order_seven() {
        // A local interpolation error of order 7 scales as h^8: halving h divides it by 2^8.
        let (a, b) = (one_step(0.8), one_step(0.4));
        let p = (a / b).log2();
        assert!((7.0..9.0).contains(&p), "observed order {p} ({a:e}, {b:e})");
    }

    #[test]
    fn interpolant_error_is_within_its_estimate_inside_a_controlled_step() {
        // The third step the controller accepted at rtol = atol = 1e-12 from cos 0: inside
        // it, the interpolant's error against cos t is within its estimate, and the estimate
        // is not absurdly loose (within 1000x the error).
        let y0 = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let mut s = Dop853::new(6, 1e-12, 1e-12);
        let mut f = osc;
        s.start(&mut f, 0.0, &y0, 10.0);
        s.step(&mut f, 10.0).unwrap();
        s.step(&mut f, 10.0).unwrap();
        s.step(&mut f, 10.0).unwrap();
        s.prepare_dense(&mut f);
        let mut track = DenseTrack::new(1, &y0, 1 << 20);
        track.record(&s, s.t);
        let (t0, h) = (s.t_old, s.t - s.t_old);
        let (mut worst, mut err_max, mut est_max) = (0.0_f64, 0.0_f64, 0.0_f64);
        for k in 1..40 {
            let t = t0 + h * k as f64 / 40.0;
            let (x, est) = track.sample(t);
            let e = (x[0].x - t.cos()).abs();
            worst = worst.max(e / est);
            err_max = err_max.max(e);
            est_max = est_max.max(est);
        }
        assert!(
            worst <= 1.0,
            "error past its estimate ({worst}) over a step of {h}"
        );
        assert!(
            est_max <= 1000.0 * err_max,
            "estimate {est_max:e} over 1000x the error {err_max:e}"
        );
    }

    #[test]
    fn a_restart_time_is_sampled_from_the_step_that_ends_there() {
        // Oracle: the step's own end value, stored as the solver holds it.
        let y0 = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let mut s = Dop853::new(6, 1e-12, 1e-12);
        let mut f = osc;
        s.start(&mut f, 0.0, &y0, 0.5);
        s.step_fixed(&mut f, 0.5);
        s.prepare_dense(&mut f);
        let mut track = DenseTrack::new(1, &y0, 1 << 20);
        track.record(&s, s.t);
        let end = s.y[0];
        // A restart at 0.5 from a kicked state: the next step starts elsewhere.
        s.start(&mut f, 0.5, &[end, 0.0, 0.0, 5.0, 0.0, 0.0], 1.0);
        s.step_fixed(&mut f, 0.5);
        s.prepare_dense(&mut f);
        track.record(&s, s.t);
        let (at, est) = track.sample(0.5);
        assert_eq!((at[0].x, est), (end, 0.0));
        let (after, _) = track.sample(0.5 + 1e-9);
        assert!(after[0].x > end, "just after the restart the kick shows");
        assert_eq!(track.sample(0.0).0[0].x, 1.0);
    }
}
