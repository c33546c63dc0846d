//! The reference measures its own error. Besides the main solve, two companions run over the
//! same sample times:
//!
//! - a **looser** solve at [`LOOSE_FACTOR`] × the main tolerance: its distance to the main
//!   solve bounds the main solve's truncation error (the looser one's error dominates the
//!   difference, so the estimate is conservative);
//! - a **perturbed** solve at the main tolerance from initial positions moved by
//!   [`PERTURBATION`] × the length scale (a round-off-sized change): its distance shows how
//!   far the scene itself amplifies round-off.
//!
//! The per-sample uncertainty is the larger of the two distances (largest over particles, m),
//! never below the round-off floor. The **predictability horizon** is the first sample time
//! at which the perturbed solve departs from the main one by more than
//! [`PREDICTABILITY_THRESHOLD`] × the motion scale: the perturbation has then grown a
//! million-fold (10⁻¹² → 10⁻⁶), so tolerance-level differences between any two correct
//! solvers grow to macroscopic ones and errors past that time measure the chaos, not the
//! method. None when no sample departs that far.
//!
//! Cost: the companions run together (rayon::join, each one sequential, so the numbers do not
//! depend on the thread count) after the main solve: about 1.8 main solves of work in all
//! (the looser one takes ≈ 100^(1/8) ≈ 1.8× fewer steps), about one main solve of wall time
//! on two cores.

use super::adaptive::{length_scale, positions, solve, SolveSpec};
use crate::error::Result;
use crate::measure::observables::position_error;
use crate::model::{State, System, Vec3};

/// Tolerance of the looser companion solve relative to the main one.
pub const LOOSE_FACTOR: f64 = 100.0;

/// Relative size of the initial-position perturbation of the perturbed companion.
pub const PERTURBATION: f64 = 1e-12;

/// Departure of the perturbed solve, relative to the motion scale, that ends the predictable
/// range (a million-fold growth of the perturbation).
pub const PREDICTABILITY_THRESHOLD: f64 = 1e-6;

/// Most attempted steps of a companion, as a multiple of the main solve's (the same problem
/// at the same or a looser tolerance needs about as many): a companion that needs more (a
/// contact sequence that grinds at its tolerance) is abandoned and said so.
pub const COMPANION_WORK_FACTOR: u64 = 3;

/// The companions' verdict at the main solve's sample times.
#[derive(Debug, Clone)]
pub(super) struct Companions {
    /// Per sample time: max(loose distance, perturbed distance) (m).
    pub uncertainty: Vec<f64>,
    /// First sample time where the perturbed solve departs past the threshold (s).
    pub horizon: Option<f64>,
    /// The threshold used (m).
    pub threshold: f64,
    /// Empty, or which companion was abandoned (over its work budget) and what that means.
    pub note: String,
}

/// `s0` with every free particle's position moved by `PERTURBATION` × the length scale, in a
/// fixed alternating pattern of signs.
pub(super) fn perturbed(sys: &System, s0: &State) -> State {
    perturbed_with(sys, s0, &mut |p, c| (3 * p + c) % 2 == 0)
}

/// `s0` with every free particle coordinate moved by ± `PERTURBATION` × the length scale, + where
/// `plus(particle, axis)` (asked in particle, then axis order): the one perturbation the
/// companion solve and the ensemble members share.
pub(super) fn perturbed_with(
    sys: &System,
    s0: &State,
    plus: &mut dyn FnMut(usize, usize) -> bool,
) -> State {
    let eps = PERTURBATION * length_scale(s0);
    let mut s = s0.clone();
    for (p, x) in s.x.iter_mut().enumerate() {
        if sys.free[p] {
            for c in 0..3 {
                x[c] += if plus(p, c) { eps } else { -eps };
            }
        }
    }
    s
}

/// Distances (m) of the solve `spec` to the main solve's positions `main` at its times; None
/// when it gave up over its step budget.
fn distances(spec: &SolveSpec<'_>, main: &[Vec<Vec3>]) -> Result<Option<Vec<f64>>> {
    let n = spec.sys.len();
    let mut d = vec![0.0; spec.times.len()];
    let done = solve(
        spec,
        &mut |i, y| {
            d[i] = position_error(&positions(y, n), &main[i]);
        },
        None,
    )?;
    Ok(done.map(|_| d))
}

/// Runs both companions of a main solve whose positions at `spec.times` are `main`: `spec` is
/// the main solve's request with the companions' step budget and no tracked component;
/// `floor` is the round-off floor (m) and `motion` the motion scale (m).
pub(super) fn companions(
    spec: &SolveSpec<'_>,
    main: &[Vec<Vec3>],
    floor: f64,
    motion: f64,
) -> Result<Companions> {
    let sp = perturbed(spec.sys, spec.s0);
    let loose = SolveSpec {
        rtol: spec.rtol * LOOSE_FACTOR,
        ..*spec
    };
    let pert = SolveSpec { s0: &sp, ..*spec };
    let (loose, pert) = rayon::join(|| distances(&loose, main), || distances(&pert, main));
    Ok(judge(spec.times, loose?, pert?, floor, motion))
}

/// The companions' verdict from their distances to the main solve at `times` (None: that
/// companion was abandoned); `floor` is the round-off floor (m) and `motion` the motion scale
/// (m).
pub(super) fn judge(
    times: &[f64],
    loose: Option<Vec<f64>>,
    pert: Option<Vec<f64>>,
    floor: f64,
    motion: f64,
) -> Companions {
    let threshold = PREDICTABILITY_THRESHOLD * motion;
    let horizon = pert.as_ref().and_then(|pert| {
        times
            .iter()
            .zip(pert)
            .find(|(_, &d)| d > threshold)
            .map(|(&t, _)| t)
    });
    let mut note = String::new();
    if loose.is_none() {
        note +=
            "; the looser solve was abandoned over its work budget (only the perturbed one counts)";
    }
    if pert.is_none() {
        note += "; the perturbed solve was abandoned over its work budget (no horizon measured)";
    }
    let uncertainty = (0..times.len())
        .map(|i| {
            let a = loose.as_ref().map_or(0.0, |d| d[i]);
            let b = pert.as_ref().map_or(0.0, |d| d[i]);
            if loose.is_none() && pert.is_none() {
                f64::INFINITY
            } else {
                a.max(b).max(floor)
            }
        })
        .collect();
    Companions {
        uncertainty,
        horizon,
        threshold,
        note,
    }
}
