//! Trajectory traces for pictures: the paths of a few particles and full snapshots of the
//! scene at a few instants, recorded from a run's accepted states. Pure recording: no metric
//! is computed here (errors and energies are [`crate::measure::metrics`]'s).

use crate::error::Result;
use crate::model::{State, Vec3};
use crate::run::{EnergyRecord, Observer};
use serde::{Deserialize, Serialize};

/// What to trace: which particles' paths, every how many steps, and when to snapshot.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TraceSpec {
    /// Particles whose paths are kept.
    pub tracked: Vec<usize>,
    /// Keep a path point every this many steps (and at the last accepted step).
    pub stride: u64,
    /// Steps at which the whole scene is kept (the last accepted state is always added).
    pub snapshot_steps: Vec<u64>,
    /// Keep every particle's position every this many steps for playback (0: none).
    #[serde(default)]
    pub frame_stride: u64,
}

/// A run's trace.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    /// The tracked particles, in the order of `paths`.
    pub tracked: Vec<usize>,
    /// Times of the path points (s).
    pub t: Vec<f64>,
    /// Positions of each tracked particle at each path point, `paths[p][k]`.
    pub paths: Vec<Vec<[f64; 3]>>,
    /// Whole-scene snapshots (time, every particle's position).
    pub snapshots: Vec<(f64, Vec<[f64; 3]>)>,
    /// Playback frames (time, every particle's position), every `frame_stride` steps up to
    /// the last accepted step. Kept in memory for the report's playback file, not written
    /// into compare's documents (they would grow by the whole trajectory).
    #[serde(skip)]
    pub frames: Vec<(f64, Vec<[f64; 3]>)>,
}

/// Records a [`Trace`] of a run of step `dt`.
pub struct TraceObserver {
    spec: TraceSpec,
    dt: f64,
    last: Option<u64>,
    /// The trace so far.
    pub trace: Trace,
}

impl TraceObserver {
    /// An observer recording `spec` for a run of step `dt`.
    pub fn new(spec: &TraceSpec, dt: f64) -> Self {
        TraceObserver {
            trace: Trace {
                tracked: spec.tracked.clone(),
                paths: vec![Vec::new(); spec.tracked.len()],
                ..Default::default()
            },
            spec: TraceSpec {
                stride: spec.stride.max(1),
                ..spec.clone()
            },
            dt,
            last: None,
        }
    }

    fn point(&mut self, step: u64, x: &[Vec3]) {
        if self.last == Some(step) {
            return;
        }
        self.last = Some(step);
        self.trace.t.push(step as f64 * self.dt);
        for (path, &p) in self.trace.paths.iter_mut().zip(&self.spec.tracked) {
            path.push(x[p].into());
        }
    }
}

impl Observer for TraceObserver {
    fn observe(&mut self, step: u64, s: &State, _e: &EnergyRecord) -> Result<()> {
        if step % self.spec.stride == 0 {
            self.point(step, &s.x);
        }
        if self.spec.frame_stride > 0 && step % self.spec.frame_stride == 0 {
            self.trace.frames.push((
                step as f64 * self.dt,
                s.x.iter().map(|&v| v.into()).collect(),
            ));
        }
        if self.spec.snapshot_steps.contains(&step) {
            let t = step as f64 * self.dt;
            self.trace
                .snapshots
                .push((t, s.x.iter().map(|&v| v.into()).collect()));
        }
        Ok(())
    }
    fn finish(&mut self, last_step: u64, s: &State, _e: &EnergyRecord) -> Result<()> {
        self.point(last_step, &s.x);
        let t = last_step as f64 * self.dt;
        if !self.spec.snapshot_steps.is_empty()
            && self.trace.snapshots.last().is_none_or(|(ts, _)| *ts < t)
        {
            self.trace
                .snapshots
                .push((t, s.x.iter().map(|&v| v.into()).collect()));
        }
        Ok(())
    }
}

/// Up to `count` free particles with the longest reference paths on the reference's first
/// grid (ties to the lower index), in increasing index order: the particles worth drawing.
pub fn longest_paths(
    reference: &crate::measure::reference::Reference,
    free: &[bool],
    count: usize,
) -> Vec<usize> {
    let n = free.len();
    let mut len = vec![0.0; n];
    let Some(g) = reference.grids.first() else {
        return Vec::new();
    };
    let mut prev: Option<&[Vec3]> = None;
    for step in g.sample_steps() {
        let Some(x) = reference.positions(0, step) else {
            continue;
        };
        if let Some(p) = prev {
            for (l, (a, b)) in len.iter_mut().zip(x.iter().zip(p)) {
                let d = (a - b).norm();
                if d.is_finite() {
                    *l += d;
                }
            }
        }
        prev = Some(x);
    }
    let mut idx: Vec<usize> = (0..n).filter(|&p| free[p]).collect();
    idx.sort_by(|&a, &b| len[b].total_cmp(&len[a]).then(a.cmp(&b)));
    idx.truncate(count);
    idx.sort();
    idx
}
