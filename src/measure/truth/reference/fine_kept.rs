//! One fine-step hierarchy per scene and horizon, kept for the process and sampled by every
//! grid that asks for it ([`super::finestep`] says what the levels are).
//!
//! The levels' steps come from the scene, never from the grids: the first is the horizon /
//! [`FIRST_LEVEL_STEPS`], halved until the scene's fastest linearised mode turns by at most
//! [`FASTEST_MODE_RADIANS`] per step (Gershgorin's bound on the mass-normalised stiffness at the
//! initial state); each level steps on its own lattice and lands only on impulse times and the
//! horizon ([`super::fine_level`]). So the hierarchy is the same bits whichever request (or
//! thread) made it, and a study's compare, sweep, advice and frame-rate grids, and the scene
//! grid its ensemble is made on, pay for one (a horizon is read to 10 significant digits, so a
//! grid whose last time n·dt rounds past the run's duration shares it). Only the last two levels are kept, whole
//! (positions and velocities at every knot); a grid samples both the same way and their
//! distance there is the uncertainty, plus the finest level's interpolant error estimate at a
//! sample interpolated inside a step.
//!
//! Refinement stops when two successive levels agree to [`FINE_AGREEMENT`] × the motion scale
//! at every knot of the coarser one, after [`FINE_LEVELS_MAX`] levels, or before a level would
//! pass [`FINE_STEP_BUDGET`] steps. The motion scale is the largest displacement at the first
//! level's knots. The predictability horizon comes from a run from perturbed initial positions
//! ([`super::uncertainty::perturbed`]) at the first step, its departure from the first level
//! kept per knot: a sample between two knots takes the larger of their departures.
//!
//! Memory is bounded: a hierarchy whose last two levels would pass [`HIERARCHY_BYTES`] (planned
//! from the most levels it may run) is not made, and such a scene's references run on their
//! grids as before ([`super::finestep::fine_step`]); the cache remembers that. The cache holds
//! at most [`CACHE_BYTES`], dropping the oldest hierarchies first (a dropped one is made again,
//! to the same bits).

use super::fine_level::{knot_bytes, most_knots, record, Level, Via};
use super::finestep::{Fine, FINE_AGREEMENT, FINE_LEVELS_MAX, FINE_METHOD, FINE_STEP_BUDGET};
use super::uncertainty::{perturbed, PREDICTABILITY_THRESHOLD};
use crate::error::Result;
use crate::measure::observables::position_error;
use crate::method::create as by_name;
use crate::method::MethodOptions;
use crate::model::{State, System};
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

/// Steps of the first level over the horizon: half the step of a run of 1000 steps, the
/// fewest reference steps the per-grid fine-step reference ever took.
pub const FIRST_LEVEL_STEPS: f64 = 2000.0;

/// Largest turn of the scene's fastest linearised mode in one step of the first level (rad):
/// well inside rk4's stability interval (2.8) on the imaginary axis.
pub const FASTEST_MODE_RADIANS: f64 = 1.0;

/// Most bytes one kept hierarchy may hold (its last two levels).
pub const HIERARCHY_BYTES: usize = 512 << 20;

/// Most bytes the cache holds over all kept hierarchies.
pub const CACHE_BYTES: usize = 1 << 30;

/// A kept hierarchy: its last two levels and what the others measured.
#[derive(Debug)]
pub(super) struct Hierarchy {
    /// Which hierarchy this is (distinct per solve in a process; for tests of the sharing).
    pub id: u64,
    /// The finest level: the reference.
    pub fine: Level,
    /// The level before it, at twice its step.
    pub coarse: Level,
    /// Levels run.
    pub levels: usize,
    /// Force evaluations of every level and the perturbed run.
    pub evals: u64,
    /// Largest displacement from the initial positions at the first level's knots (m).
    pub motion: f64,
    /// The first level's knot times (s) and the perturbed run's distance from it there (m).
    departure: (Vec<f64>, Vec<f64>),
}

impl Hierarchy {
    fn bytes(&self) -> usize {
        self.fine.bytes() + self.coarse.bytes() + 16 * self.departure.0.len()
    }

    /// The reference at the sorted `times`: the finest level's positions; per time the distance
    /// between the last two levels (at least `floor`, m) plus the finest level's interpolant
    /// estimate; the predictability horizon. Each time is sampled on its own (in parallel), so
    /// the numbers do not depend on the thread count.
    pub(super) fn sample(&self, sys: &System, times: &[f64], floor: f64) -> Result<Fine> {
        by_name(FINE_METHOD, &MethodOptions::default())?;
        let fresh = || by_name(FINE_METHOD, &MethodOptions::default()).expect("made above");
        let both: Vec<Result<_>> = times
            .par_iter()
            .map_init(fresh, |st, &t| {
                let a = self.fine.sample(sys, t, st.as_mut())?;
                let b = self.coarse.sample(sys, t, st.as_mut())?;
                let u = position_error(&a.x, &b.x).max(floor) + a.estimate;
                Ok((a.x, u, a.via))
            })
            .collect();
        let (mut samples, mut uncertainty) = (Vec::new(), Vec::new());
        let (mut interpolated, mut landed) = (0, 0);
        for r in both {
            let (x, u, via) = r?;
            samples.push(x);
            uncertainty.push(u);
            interpolated += usize::from(via == Via::Hermite);
            landed += usize::from(via == Via::Landed);
        }
        let threshold = PREDICTABILITY_THRESHOLD * self.scale();
        let horizon = times
            .iter()
            .find(|&&t| self.departure_at(t) > threshold)
            .copied();
        Ok(Fine {
            samples,
            uncertainty,
            horizon,
            step: self.fine.h,
            levels: self.levels,
            evals: self.evals,
            motion: self.motion,
            between: Some((interpolated, landed)),
        })
    }

    fn scale(&self) -> f64 {
        if self.motion > 0.0 {
            self.motion
        } else {
            1.0
        }
    }

    /// The perturbed run's departure at `t`: at a first-level knot time, there; between two
    /// knots, the larger of theirs.
    fn departure_at(&self, t: f64) -> f64 {
        let (times, d) = &self.departure;
        let k = times.partition_point(|&u| u < t);
        if k == times.len() {
            return d[k - 1];
        }
        if k == 0 || times[k] == t {
            return d[k];
        }
        d[k - 1].max(d[k])
    }
}

/// A cache entry: the kept hierarchy, or None when it was too big to keep.
type Entry = (String, Option<Arc<Hierarchy>>);

static CACHE: Mutex<Vec<Entry>> = Mutex::new(Vec::new());

/// The kept hierarchy of `sys` from `s0` to `horizon`, made when no request has yet; None when
/// its last two levels would not fit [`HIERARCHY_BYTES`] or one of its first three runs failed
/// (the caller runs on its grids instead, and meets the failure there if it is one).
pub(super) fn shared(sys: &System, s0: &State, horizon: f64) -> Result<Option<Arc<Hierarchy>>> {
    let horizon = kept_horizon(horizon);
    let key = format!("{sys:?}|{s0:?}|{horizon:?}");
    if let Some((_, kept)) = lock().iter().find(|(k, _)| *k == key) {
        return Ok(kept.clone());
    }
    // Made outside the lock: two threads asking at once both make it, to the same bits, and
    // the first to finish is kept.
    let made = make(sys, s0, horizon)?.map(Arc::new);
    let mut cache = lock();
    if let Some((_, kept)) = cache.iter().find(|(k, _)| *k == key) {
        return Ok(kept.clone());
    }
    let size = made.as_ref().map_or(0, |h| h.bytes());
    let mut held: usize = cache
        .iter()
        .filter_map(|(_, h)| h.as_ref().map(|h| h.bytes()))
        .sum();
    while held + size > CACHE_BYTES && !cache.is_empty() {
        let (_, old) = cache.remove(0);
        held -= old.map_or(0, |h| h.bytes());
    }
    cache.push((key, made.clone()));
    Ok(made)
}

fn lock() -> std::sync::MutexGuard<'static, Vec<Entry>> {
    CACHE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Drops the kept hierarchy of `sys`, `s0` and `horizon`, so the next request makes it again
/// (for the tests of the sharing).
#[cfg(test)]
pub(super) fn forget(sys: &System, s0: &State, horizon: f64) {
    let horizon = kept_horizon(horizon);
    let key = format!("{sys:?}|{s0:?}|{horizon:?}");
    lock().retain(|(k, _)| *k != key);
}

/// The horizon a hierarchy is keyed by and its steps are chosen from, for a request to
/// `horizon`: rounded to 10 significant digits, so requests that differ by round-off (a grid's
/// last time n·dt against the run's duration) share one hierarchy. Its levels run
/// [`OVERRUN`] × it further, so every sample time of such a request lies inside them.
fn kept_horizon(horizon: f64) -> f64 {
    format!("{horizon:.9e}").parse().unwrap_or(horizon)
}

/// How far past its horizon (relative) a hierarchy's levels run: beyond any round-off of a
/// request's horizon that rounds to the same 10 digits.
const OVERRUN: f64 = 1e-9;

/// The first level's step of `sys` over `horizon` ([module docs](self)).
pub(super) fn first_step(sys: &System, s0: &State, horizon: f64) -> f64 {
    let mut h = horizon / FIRST_LEVEL_STEPS;
    let w = fastest_rate(sys, s0);
    if w.is_finite() {
        while w * h > FASTEST_MODE_RADIANS {
            h *= 0.5;
        }
    }
    h
}

/// Gershgorin's bound on the scene's fastest linearised natural frequency at `s0` (rad/s):
/// the square root of the largest row sum of |M^-1/2 K M^-1/2| over the free particles, each
/// 3×3 block counted by its largest row sum.
fn fastest_rate(sys: &System, s0: &State) -> f64 {
    let mut jac = sys.new_jacobian();
    sys.jacobian(&s0.x, &s0.v, &mut jac);
    let norm = |m: &nalgebra::Matrix3<f64>| {
        (0..3)
            .map(|r| (0..3).map(|c| m[(r, c)].abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let mut row = vec![0.0; sys.len()];
    for (s, pr) in jac.pairs.iter().enumerate() {
        let (a, b) = (pr[0] as usize, pr[1] as usize);
        let k = norm(&jac.kx[s]);
        for (p, q) in [(a, b), (b, a)] {
            if sys.free[p] {
                row[p] += k / sys.mass[p];
                if sys.free[q] {
                    row[p] += k / (sys.mass[p] * sys.mass[q]).sqrt();
                }
            }
        }
    }
    (0..sys.len())
        .filter(|&p| sys.free[p])
        .map(|p| row[p] + norm(&jac.diag_x[p]) / sys.mass[p])
        .fold(0.0, f64::max)
        .sqrt()
}

/// The most levels a hierarchy from step `h0` over `horizon` may run.
fn most_levels(horizon: f64, h0: f64) -> usize {
    let mut levels = 2;
    while levels < FINE_LEVELS_MAX
        && horizon / (h0 / f64::powi(2.0, levels as i32)) <= FINE_STEP_BUDGET
    {
        levels += 1;
    }
    levels
}

/// The first step of the hierarchy of `sys` from `s0` to `horizon` when its last two levels
/// would fit [`HIERARCHY_BYTES`]; None when the per-grid runs would serve instead. What the
/// hierarchy runs and what its cost projection prices ([`super::cost::project`]).
pub(super) fn kept_first_step(sys: &System, s0: &State, horizon: f64) -> Option<f64> {
    let h0 = first_step(sys, s0, horizon);
    let top = most_levels(horizon, h0);
    let end = horizon * (1.0 + OVERRUN);
    let finest = h0 / f64::powi(2.0, top as i32 - 1);
    let pair = most_knots(sys, end, finest) + most_knots(sys, end, 2.0 * finest);
    (pair.saturating_mul(knot_bytes(sys.len())) <= HIERARCHY_BYTES).then_some(h0)
}

/// Makes the hierarchy, or None when it would not fit or one of its first three runs failed.
fn make(sys: &System, s0: &State, horizon: f64) -> Result<Option<Hierarchy>> {
    let Some(h0) = kept_first_step(sys, s0, horizon) else {
        return Ok(None);
    };
    let top = most_levels(horizon, h0);
    let end = horizon * (1.0 + OVERRUN);
    let sp = perturbed(sys, s0);
    // Level 2 always runs, so it runs beside level 1 and the perturbed run: three
    // independent runs, each sequential, so the bits do not depend on the thread count; an
    // error is reported in the order the levels would have met it.
    let ((first, pert), second) = rayon::join(
        || rayon::join(|| record(sys, s0, end, h0), || record(sys, &sp, end, h0)),
        || record(sys, s0, end, 0.5 * h0),
    );
    let (Ok((first, e1)), Ok((pert, e2)), Ok((mut fine, e3))) = (first, pert, second) else {
        return Ok(None);
    };
    let mut evals = e1 + e2 + e3;
    let times: Vec<f64> = (0..first.knots()).map(|i| first.time(i)).collect();
    let x0: Vec<f64> = s0.x.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    let motion = (0..first.knots())
        .map(|i| distance(first.x(i), &x0))
        .fold(0.0, f64::max);
    let departure = (0..first.knots())
        .map(|i| distance(first.x(i), pert.x(i)))
        .collect();
    drop(pert);
    let scale = if motion > 0.0 { motion } else { 1.0 };
    let mut coarse = first;
    let mut levels = 2;
    let mut stepper = by_name(FINE_METHOD, &MethodOptions::default())?;
    loop {
        let mut worst = 0.0_f64;
        for i in 0..coarse.knots() {
            let a = fine.sample(sys, coarse.time(i), stepper.as_mut())?;
            let b = super::dense::to_vec3(coarse.x(i));
            worst = worst.max(position_error(&a.x, &b));
        }
        if worst <= FINE_AGREEMENT * scale || levels >= top {
            break;
        }
        drop(coarse);
        let (next, e) = record(sys, s0, end, 0.5 * fine.h)?;
        evals += e;
        coarse = std::mem::replace(&mut fine, next);
        levels += 1;
    }
    Ok(Some(Hierarchy {
        id: super::solution::new_id(),
        fine,
        coarse,
        levels,
        evals,
        motion,
        departure: (times, departure),
    }))
}

/// Largest distance between two particles' positions given as 3n numbers (m).
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.chunks_exact(3)
        .zip(b.chunks_exact(3))
        .map(|(p, q)| {
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::grid::TimeGrid;
    use crate::measure::reference::Reference;
    use crate::scenario::Scenario;

    #[test]
    fn two_grids_from_one_kept_hierarchy_are_the_bits_of_each_grid_asking_first() {
        // Oracle: a hierarchy made afresh for the other grid (the kept one dropped first). A
        // ball bouncing on a projection plane (a height no other test uses, so the first
        // request makes it), on two grids off each other's and the levels' lattices.
        let toml = "[world]\ngravity=[0.0,-9.81,0.0]\n\
             [[particle]]\nposition=[0.0,0.93,0.0]\nmass=1.0\nradius=0.1\n\
             [[obstacle]]\nshape=\"plane\"\npoint=[0.0,0.0,0.0]\nnormal=[0.0,1.0,0.0]\nrestitution=0.5\n\
             [collision]\nresponse=\"projection\"\n";
        let scene = Scenario::from_toml_str(toml, "ball_order.toml").unwrap();
        let (sys, s0) = (scene.build(), scene.initial_state());
        let a = TimeGrid::new(0.0123, 81, 81);
        let b = TimeGrid::new(0.01, 100, 100);
        let horizon = 1.0;
        let reference = |g: TimeGrid| Reference::compute(&sys, &s0, &[g], horizon).unwrap();
        let same = |x: &Reference, y: &Reference, g: TimeGrid| {
            for n in g.sample_steps() {
                assert_eq!(x.positions(0, n), y.positions(0, n), "step {n}");
                assert_eq!(x.uncertainty_at(0, n), y.uncertainty_at(0, n), "step {n}");
            }
            assert_eq!(x.info, y.info);
        };
        let a_first = reference(a);
        let b_second = reference(b);
        let id = a_first.solve_id().expect("a kept hierarchy");
        assert_eq!(b_second.solve_id(), Some(id));
        forget(&sys, &s0, horizon);
        let b_first = reference(b);
        assert!(b_first.solve_id().is_some_and(|other| other != id));
        let a_second = reference(a);
        assert_eq!(a_second.solve_id(), b_first.solve_id());
        same(&b_first, &b_second, b);
        same(&a_first, &a_second, a);
    }

    #[test]
    fn a_kept_hierarchy_is_the_same_bits_with_one_and_two_threads() {
        // Oracle: the one-thread reference (the tool promises the same bits whatever the thread
        // count). A ball on a projection plane, made afresh in each pool.
        let toml = "[world]\ngravity=[0.0,-9.81,0.0]\n\
             [[particle]]\nposition=[0.0,0.87,0.0]\nvelocity=[0.3,0.0,0.0]\nmass=1.0\nradius=0.1\n\
             [[obstacle]]\nshape=\"plane\"\npoint=[0.0,0.0,0.0]\nnormal=[0.0,1.0,0.0]\nrestitution=0.5\n\
             [collision]\nresponse=\"projection\"\n";
        let scene = Scenario::from_toml_str(toml, "ball_threads.toml").unwrap();
        let (sys, s0) = (scene.build(), scene.initial_state());
        let grid = TimeGrid::new(0.0123, 81, 81);
        let run = |threads: usize| {
            forget(&sys, &s0, 1.0);
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Reference::compute(&sys, &s0, &[grid], 1.0).unwrap())
        };
        let (one, two) = (run(1), run(2));
        assert_ne!(
            one.solve_id(),
            two.solve_id(),
            "the second pool made its own"
        );
        for n in grid.sample_steps() {
            assert_eq!(one.positions(0, n), two.positions(0, n), "step {n}");
            assert_eq!(
                one.uncertainty_at(0, n),
                two.uncertainty_at(0, n),
                "step {n}"
            );
        }
        assert_eq!(one.info, two.info);
    }
}
