//! The converged fine-step reference, for contact models with no continuous counterpart (the
//! `projection` response: positions are pushed out and velocities re-derived after each step,
//! a rule defined only for a discrete step).
//!
//! The scene is run with [`FINE_METHOD`] and the scene's own contact stage at steps h₀, h₀/2,
//! h₀/4, … Refinement stops when two successive levels agree to [`FINE_AGREEMENT`] × the motion
//! scale, after [`FINE_LEVELS_MAX`] levels, or before a level would pass [`FINE_STEP_BUDGET`]
//! steps. The finest level is the reference; the per-sample distance between the last two
//! levels is its uncertainty (the first-order contact rule makes the error roughly halve per
//! level, so that distance is about the finest level's own error). The predictability horizon
//! comes from a perturbed run (initial positions moved as in [`super::uncertainty`]) at h₀
//! against the unperturbed one at h₀.
//!
//! Two ways to run it:
//! - **kept** (every scene whose last two levels fit in memory): h₀ from the scene, the
//!   hierarchy made once per scene and horizon and sampled by every grid between its steps
//!   (`fine_kept`, `fine_level`);
//! - **per grid** (`fine_step`, the others): h₀ = half the finest requested grid step, at
//!   most the horizon / 1000, every level landing exactly on every sample time and impulse.

use super::uncertainty::{perturbed, PREDICTABILITY_THRESHOLD};
use crate::error::{Error, Result};
use crate::measure::observables::position_error;
use crate::method::create as by_name;
use crate::method::MethodOptions;
use crate::model::{State, System, Vec3};

/// The method of the fine-step reference.
pub const FINE_METHOD: &str = "rk4";
/// Agreement of two successive levels (relative to the motion scale) that ends refinement.
pub const FINE_AGREEMENT: f64 = 1e-6;
/// Most refinement levels.
pub const FINE_LEVELS_MAX: usize = 4;
/// Most steps of one level (the next level is not run past it).
pub const FINE_STEP_BUDGET: f64 = 400_000.0;

/// The fine-step reference at the sample times.
#[derive(Debug, Clone)]
pub(super) struct Fine {
    /// Positions per sample time (finest level).
    pub samples: Vec<Vec<Vec3>>,
    /// Per sample time: distance between the last two levels, at least `floor` (m).
    pub uncertainty: Vec<f64>,
    /// First sample time where the perturbed run departs past the threshold.
    pub horizon: Option<f64>,
    /// Step of the finest level (s).
    pub step: f64,
    /// Levels run.
    pub levels: usize,
    /// Force evaluations in all levels.
    pub evals: u64,
    /// Largest displacement from the initial positions at the samples (m).
    pub motion: f64,
    /// Samples interpolated inside a fine step and samples landed on by a partial fine step
    /// (a kept hierarchy; None when every level landed on the sample times).
    pub between: Option<(usize, usize)>,
}

/// One run at step `h`, positions at `times`.
fn run_at(
    sys: &System,
    s0: &State,
    times: &[f64],
    horizon: f64,
    h: f64,
) -> Result<(Vec<Vec<Vec3>>, u64)> {
    let mut out = vec![Vec::new(); times.len()];
    let evals = run_with(sys, s0, times, horizon, h, &mut |i, s| out[i] = s.x.clone())?;
    Ok((out, evals))
}

/// One run of the fine-step method with its contact stage at step `h` from `s0` to
/// `horizon`, calling `sink(i, state)` at each of the sorted `times` (steps shortened to land
/// on them); returns the force evaluations. The per-grid fine-step reference and the ensemble
/// members ([`super::ensemble`]) are both this loop (the kept levels step on their own lattice,
/// [`super::fine_level`]): a reference run is not a [`crate::run::run`] (its steps land on
/// sample times and impulse times, which the runner's fixed grid does not).
pub(super) fn run_with(
    sys: &System,
    s0: &State,
    times: &[f64],
    horizon: f64,
    h: f64,
    sink: &mut dyn FnMut(usize, &State),
) -> Result<u64> {
    let mut stepper = by_name(FINE_METHOD, &MethodOptions::default())?;
    let mut s = s0.clone();
    s.t = 0.0;
    let mut next = 0;
    let mut imp = 0;
    let mut evals = 0;
    let eps = 1e-9 * h;
    let mut x0 = s.x.clone();
    let mut v0 = s.v.clone();
    stepper.reset();
    loop {
        while next < times.len() && times[next] <= s.t + eps {
            sink(next, &s);
            next += 1;
        }
        while imp < sys.impulses.len() && sys.impulses[imp].time <= s.t + eps {
            let im = sys.impulses[imp];
            s.v[im.particle] += im.delta_v;
            stepper.reset();
            imp += 1;
        }
        if s.t >= horizon - eps {
            break;
        }
        let mut target = (s.t + h).min(horizon);
        if let Some(&t) = times.get(next) {
            target = target.min(t);
        }
        if let Some(im) = sys.impulses.get(imp) {
            target = target.min(im.time);
        }
        let step = target - s.t;
        x0.clone_from(&s.x);
        v0.clone_from(&s.v);
        evals += stepper.step(sys, &mut s, step)?.force_evals;
        if let Some(c) = &sys.post_step {
            if c.apply(sys, &x0, &v0, &mut s, step).changed {
                stepper.reset();
            }
        }
        s.t = target;
        if !s.x.iter().all(|x| x.iter().all(|c| c.is_finite())) {
            return Err(Error::Step(format!(
                "fine-step reference ({FINE_METHOD} at {h:e} s) blew up at t = {}",
                s.t
            )));
        }
    }
    while next < times.len() {
        sink(next, &s);
        next += 1;
    }
    Ok(evals)
}

/// The converged fine-step reference of `sys` from `s0` at `times`, starting at step `h0`, run
/// on the request's own sample times (a scene whose hierarchy is too big to keep).
pub(super) fn fine_step(
    sys: &System,
    s0: &State,
    times: &[f64],
    horizon: f64,
    h0: f64,
    floor: f64,
) -> Result<Fine> {
    let h0 = h0.min(horizon / 1000.0);
    let sp = perturbed(sys, s0);
    // Level 2 always runs, so it runs beside level 1 and the perturbed run: three
    // independent runs, each sequential, so the bits do not depend on the thread count; an
    // error is reported in the order the levels would have met it.
    let ((first, pert), second) = rayon::join(
        || {
            rayon::join(
                || run_at(sys, s0, times, horizon, h0),
                || run_at(sys, &sp, times, horizon, h0),
            )
        },
        || run_at(sys, s0, times, horizon, 0.5 * h0),
    );
    let ((mut prev, mut evals), (pert, pe)) = (first?, pert?);
    evals += pe;
    let mut ready = Some(second?);
    let motion = prev
        .iter()
        .flat_map(|x| x.iter().zip(&s0.x).map(|(a, b)| (a - b).norm()))
        .fold(0.0, f64::max);
    let scale = if motion > 0.0 { motion } else { 1.0 };
    let threshold = PREDICTABILITY_THRESHOLD * scale;
    let horizon_t = times
        .iter()
        .zip(pert.iter().zip(&prev))
        .find(|(_, (a, b))| position_error(a, b) > threshold)
        .map(|(&t, _)| t);
    let mut h = h0;
    let mut levels = 1;
    let mut unc = vec![f64::INFINITY; times.len()];
    loop {
        let next_h = 0.5 * h;
        if levels >= 2 && (levels >= FINE_LEVELS_MAX || horizon / next_h > FINE_STEP_BUDGET) {
            break;
        }
        let (cur, e) = match ready.take() {
            Some(level_two) => level_two,
            None => run_at(sys, s0, times, horizon, next_h)?,
        };
        evals += e;
        unc = cur
            .iter()
            .zip(&prev)
            .map(|(a, b)| position_error(a, b).max(floor))
            .collect();
        prev = cur;
        h = next_h;
        levels += 1;
        let worst = unc.iter().copied().fold(0.0, f64::max);
        if worst <= FINE_AGREEMENT * scale {
            break;
        }
    }
    Ok(Fine {
        samples: prev,
        uncertainty: unc,
        horizon: horizon_t,
        step: h,
        levels,
        evals,
        motion,
        between: None,
    })
}
