//! Output grids: the times at which a run is compared with the reference.

use serde::{Deserialize, Serialize};

/// A uniform output grid t_n = n·dt, n = 0..=steps, compared with the reference every
/// `stride`-th step and at the last step (stride 1: every step).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TimeGrid {
    /// Step (s).
    pub dt: f64,
    /// Number of steps.
    pub steps: u64,
    /// Compare every `stride`-th step (≥ 1), plus the last one.
    pub stride: u64,
}

impl TimeGrid {
    /// The grid of `steps` steps of `dt` with a stride keeping at most `max_samples` samples.
    pub fn new(dt: f64, steps: u64, max_samples: u64) -> Self {
        let stride = steps.div_ceil(max_samples.max(1)).max(1);
        TimeGrid { dt, steps, stride }
    }
    /// Time of step `n`, computed exactly as the runner does.
    pub fn time(&self, n: u64) -> f64 {
        n as f64 * self.dt
    }
    /// The compared steps in increasing order.
    pub fn sample_steps(&self) -> impl Iterator<Item = u64> + '_ {
        let last = self.steps;
        let stride = self.stride;
        (0..=last)
            .step_by(stride as usize)
            .chain((last % stride != 0).then_some(last))
    }
    /// Number of compared steps.
    pub fn sample_count(&self) -> usize {
        (self.steps / self.stride) as usize + 1 + usize::from(self.steps % self.stride != 0)
    }
    /// Index of step `n` among the compared steps, if it is one.
    pub fn sample_index(&self, n: u64) -> Option<usize> {
        if n % self.stride == 0 {
            Some((n / self.stride) as usize)
        } else if n == self.steps {
            Some(self.sample_count() - 1)
        } else {
            None
        }
    }
}

/// Largest number of samples per run so that `runs` runs of `particles` stored positions fit
/// in `budget_bytes` (at least 64).
pub fn max_samples_for(budget_bytes: usize, runs: usize, particles: usize) -> u64 {
    let per = 24 * particles.max(1) * runs.max(1);
    ((budget_bytes / per) as u64).max(64)
}

/// Default memory budget for reference samples: 256 MiB.
pub const DEFAULT_BUDGET_BYTES: usize = 256 << 20;

/// The grid one run of `steps` steps of `dt` is compared on (compare's grid): every step a
/// sample while the samples of `particles` particles fit [`DEFAULT_BUDGET_BYTES`].
pub fn run_grid(dt: f64, steps: u64, particles: usize) -> TimeGrid {
    TimeGrid::new(
        dt,
        steps,
        max_samples_for(DEFAULT_BUDGET_BYTES, 1, particles),
    )
}

/// The scene's own grid over `horizon` (s): its `[run]` step, as many steps as `--duration
/// horizon` gives. The scene's ensemble is made on it, whatever steps a command compares.
pub fn scene_grid(
    scene: &crate::scenario::Scenario,
    particles: usize,
    horizon: f64,
) -> crate::error::Result<TimeGrid> {
    let t = crate::scenario::Timing::resolve(scene, None, Some(horizon))?;
    Ok(run_grid(t.dt, t.steps, particles))
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn samples_cover_first_strided_and_last() {
        let g = TimeGrid {
            dt: 0.1,
            steps: 10,
            stride: 4,
        };
        let s: Vec<u64> = g.sample_steps().collect();
        assert_eq!(s, vec![0, 4, 8, 10]);
        assert_eq!(g.sample_count(), 4);
        assert_eq!(g.sample_index(8), Some(2));
        assert_eq!(g.sample_index(10), Some(3));
        assert_eq!(g.sample_index(5), None);
        let g = TimeGrid::new(0.1, 12, 4);
        assert_eq!(g.stride, 3);
        assert_eq!(g.sample_steps().collect::<Vec<_>>(), vec![0, 3, 6, 9, 12]);
    }
}
