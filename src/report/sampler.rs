//! The observer the report runs with: decimated energy, position error against a stored
//! reference on the same time grid, paths of a few particles and full snapshots.

use super::results::Sample;
use crate::error::Result;
use crate::model::{State, Vec3};
use crate::run::{EnergyRecord, Observer};

/// Records every `stride`-th step (and the last accepted one).
pub struct Sampler<'a> {
    /// Sample every this many steps.
    pub stride: u64,
    /// Step length (s).
    pub dt: f64,
    /// Reference positions at sample k (same grid), if any.
    pub reference: Option<&'a [Vec<Vec3>]>,
    /// Free particles (the error is over these).
    pub free: &'a [bool],
    /// Particles whose paths are kept.
    pub tracked: &'a [usize],
    /// Steps at which a full snapshot is kept.
    pub snapshot_steps: &'a [u64],
    /// Keep all positions at every sample (used for the reference itself).
    pub keep_all: bool,
    /// Samples so far.
    pub samples: Vec<Sample>,
    /// Paths of the tracked particles.
    pub paths: Vec<Vec<[f64; 3]>>,
    /// Snapshots (time, positions).
    pub snapshots: Vec<(f64, Vec<[f64; 3]>)>,
    /// All positions per sample, when `keep_all`.
    pub all: Vec<Vec<Vec3>>,
    last: Option<u64>,
}

impl<'a> Sampler<'a> {
    /// A sampler with nothing recorded yet.
    pub fn new(
        stride: u64,
        dt: f64,
        reference: Option<&'a [Vec<Vec3>]>,
        free: &'a [bool],
        tracked: &'a [usize],
        snapshot_steps: &'a [u64],
        keep_all: bool,
    ) -> Self {
        Sampler {
            stride: stride.max(1),
            dt,
            reference,
            free,
            tracked,
            snapshot_steps,
            keep_all,
            samples: Vec::new(),
            paths: vec![Vec::new(); tracked.len()],
            snapshots: Vec::new(),
            all: Vec::new(),
            last: None,
        }
    }

    fn record(&mut self, step: u64, s: &State, e: &EnergyRecord) {
        if self.last == Some(step) {
            return;
        }
        self.last = Some(step);
        let t = step as f64 * self.dt;
        let pos_error = if step % self.stride == 0 {
            let k = (step / self.stride) as usize;
            self.reference
                .and_then(|r| r.get(k))
                .map(|xr| rms_error(&s.x, xr, self.free))
        } else {
            None
        };
        self.samples.push(Sample {
            t,
            energy: *e,
            pos_error,
        });
        for (path, &p) in self.paths.iter_mut().zip(self.tracked) {
            path.push(s.x[p].into());
        }
        if self.keep_all {
            self.all.push(s.x.clone());
        }
    }
}

/// RMS over free particles of |x − x_ref| (m).
pub fn rms_error(x: &[Vec3], xr: &[Vec3], free: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for ((a, b), &f) in x.iter().zip(xr).zip(free) {
        if f {
            sum += (a - b).norm_squared();
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

impl Observer for Sampler<'_> {
    fn observe(&mut self, step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        if step % self.stride == 0 {
            self.record(step, s, e);
        }
        if self.snapshot_steps.contains(&step) {
            self.snapshots.push((
                step as f64 * self.dt,
                s.x.iter().map(|&v| v.into()).collect(),
            ));
        }
        Ok(())
    }
    fn finish(&mut self, last_step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        if !self.keep_all {
            self.record(last_step, s, e);
        }
        let t = last_step as f64 * self.dt;
        if !self.snapshot_steps.is_empty() && self.snapshots.last().is_none_or(|(ts, _)| *ts < t) {
            self.snapshots
                .push((t, s.x.iter().map(|&v| v.into()).collect()));
        }
        Ok(())
    }
}
