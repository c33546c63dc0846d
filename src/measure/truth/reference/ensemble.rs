//! The reference's ensemble: [`ENSEMBLE_SIZE`] more solves of the scene, each from the initial
//! positions moved by the reference's own round-off-level uncertainty
//! ([`super::uncertainty::PERTURBATION`] × the length scale, the floor of its measured
//! uncertainty) with signs drawn per member from a fixed seed, solved by the reference's own
//! solver (DOP853 at [`super::uncertainty::LOOSE_FACTOR`] × its tolerance, the looser
//! companion's, whose distance to the main solve the reference already counts as its
//! uncertainty; or the fine-step loop at the converged step). Before the predictability
//! horizon the members agree with the reference to its uncertainty; past it they part as far
//! as the scene's chaos takes them, and their spread is what a correct solution may do there
//! ([`crate::measure::statistics`]).
//!
//! Members run in parallel, each sequentially, so the result is the same bits whatever the
//! thread count. Cost: about [`ENSEMBLE_SIZE`] / 1.8 main solves of work.

use super::adaptive::REFERENCE_TOL;
use super::adaptive::{solve, SolveSpec};
use super::rhs::unpack_x;
use super::uncertainty::{LOOSE_FACTOR, PERTURBATION};
use crate::error::Result;
use crate::measure::statistics::{instant, window_times, Accumulator, Ensemble, ENSEMBLE_SIZE};
use crate::model::{State, System};
use rayon::prelude::*;

/// The solver an ensemble member uses.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) enum MemberSolver {
    /// DOP853 at this tolerance, giving up past this many attempted steps.
    Dop853 { rtol: f64, max_steps: u64 },
    /// The fine-step loop at this step.
    FineStep { h: f64 },
}

/// Member `k`'s initial state: every free particle coordinate moved by ± `PERTURBATION` ×
/// the length scale, the signs from a SplitMix64 stream seeded with `k`.
fn member_start(sys: &System, s0: &State, k: usize) -> State {
    let mut state = (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mut next_bit = |_: usize, _: usize| {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) & 1 == 1
    };
    super::uncertainty::perturbed_with(sys, s0, &mut next_bit)
}

/// One member's observables over `times`, or None when its solver gave up.
fn member(
    sys: &System,
    s0: &State,
    times: &[f64],
    end: f64,
    solver: MemberSolver,
) -> Result<Option<crate::measure::statistics::Observed>> {
    let n = sys.len();
    let mut acc = Accumulator::default();
    match solver {
        MemberSolver::Dop853 { rtol, max_steps } => {
            let spec = SolveSpec {
                sys,
                s0,
                times,
                horizon: end,
                rtol,
                tracked: None,
                max_steps: Some(max_steps),
            };
            let done = solve(
                &spec,
                &mut |_, y| {
                    // The state vector is positions then velocities ([`super::rhs::pack`]).
                    let (x, v) = (unpack_x(y, n), unpack_x(&y[3 * n..], n));
                    acc.push(&instant(sys, &x, &v));
                },
                None,
            )?;
            if done.is_none() {
                return Ok(None);
            }
        }
        MemberSolver::FineStep { h } => {
            super::finestep::run_with(sys, s0, times, end, h, &mut |_, s| {
                acc.push(&instant(sys, &s.x, &s.v))
            })?;
        }
    }
    Ok((acc.count() == times.len()).then(|| acc.observed()))
}

/// A made ensemble (or why none could be), kept per scene, window and member solver.
type Made = std::result::Result<Ensemble, String>;

/// Ensembles made in this process, keyed like the kept solves ([`super::solution`]): every
/// command that judges a scene by statistics over the same window reads the same members, made
/// once ([`crate::measure::kept`]; at most 32 kept).
static KEPT: crate::measure::kept::Kept<Made> = crate::measure::kept::Kept::new(32);

/// The ensemble over the window from `start` (the predictability horizon) to `end`, judged
/// with position tolerance `tolerance` (m) and `relative_tolerance`; None when fewer than three
/// members finished (a spread needs them), with the reason. Made once per scene, window and
/// member solver in a process ([`KEPT`]).
pub(super) fn ensemble(
    sys: &System,
    s0: &State,
    start: f64,
    end: f64,
    solver: MemberSolver,
    tolerance: f64,
    relative_tolerance: f64,
) -> Result<Made> {
    let key = format!("{sys:?}|{s0:?}|{start:?}|{end:?}|{solver:?}");
    let made = KEPT.get_or_make(key.clone(), || {
        if let Some(made) = super::stored::load_ensemble(&key) {
            return Ok(made);
        }
        let made = make(sys, s0, start, end, solver)?;
        super::stored::save_ensemble(&key, &made);
        Ok(made)
    })?;
    Ok(made.map(|mut e| {
        e.tolerance = tolerance;
        e.relative_tolerance = relative_tolerance;
        e
    }))
}

/// Makes the ensemble over the window from `start` to `end` (tolerances left at 0 for the
/// caller to set).
fn make(sys: &System, s0: &State, start: f64, end: f64, solver: MemberSolver) -> Result<Made> {
    let (tolerance, relative_tolerance) = (0.0, 0.0);
    let times = window_times(start, end);
    let members: Vec<Result<Option<_>>> = (0..ENSEMBLE_SIZE)
        .into_par_iter()
        .map(|k| member(sys, &member_start(sys, s0, k), &times, end, solver))
        .collect();
    let mut done = Vec::new();
    for m in members {
        if let Some(o) = m? {
            done.push(o);
        }
    }
    if done.len() < 3 {
        return Ok(Err(format!(
            "only {} of {ENSEMBLE_SIZE} ensemble members finished within their work budget",
            done.len()
        )));
    }
    let made_by = match solver {
        MemberSolver::Dop853 { rtol, .. } => format!(
            "{} DOP853 solves at rtol = atol = {rtol:e} ({LOOSE_FACTOR:e} x the reference's tolerance {REFERENCE_TOL:e}), each from initial positions moved by ±{PERTURBATION:e} x the length scale with signs from a fixed seed; {} finished",
            ENSEMBLE_SIZE,
            done.len()
        ),
        MemberSolver::FineStep { h } => format!(
            "{ENSEMBLE_SIZE} fine-step runs at {h:e} s, each from initial positions moved by ±{PERTURBATION:e} x the length scale with signs from a fixed seed"
        ),
    };
    Ok(Ok(Ensemble {
        start,
        end,
        times,
        members: done,
        tolerance,
        relative_tolerance,
        made_by,
        grid: None,
    }))
}

/// The DOP853 member solver of a reference whose main solve attempted `main_steps` steps.
pub(super) fn dop853_members(main_steps: u64) -> MemberSolver {
    MemberSolver::Dop853 {
        rtol: REFERENCE_TOL * LOOSE_FACTOR,
        max_steps: super::uncertainty::COMPANION_WORK_FACTOR * main_steps.max(100),
    }
}
