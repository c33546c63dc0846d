//! The modelled cost of a reference solve, priced like any run ([`crate::run::cost`]), so a
//! command's time budget covers its reference as well as its runs.
//!
//! Before a solve: a projection from the scene alone. The adaptive solver (DOP853 at 1e-12)
//! takes at least [`STEPS_PER_RADIAN`] steps per radian of the scene's fastest motion over the
//! horizon (the highest linearised frequency ω_max, or √(|g|/L) of the shortest rigid rod
//! swinging under gravity), and at least 1 / `CONTACT_MAX_STEP_FRACTION` steps with
//! obstacles; each step costs [`EVALS_PER_STEP`] force evaluations (and a contact pass with
//! obstacles), and its two companions about [`COMPANION_SHARE`] times the main solve's work.
//! The fine-step reference runs a known number of steps: its first level, its perturbed run and
//! its second level always run, [`FINE_CERTAIN_RUNS`] times the first level's steps, each
//! priced as the runner prices a step of [`FINE_METHOD`].
//!
//! During a solve: a limit. The projection of the adaptive solver is a floor (contacts that
//! chatter, a fast orbit can need far more steps), so the main solve stops once it has taken
//! the steps its share of the budget pays for, with an error naming `--budget`.

use super::adaptive::CONTACT_MAX_STEP_FRACTION;
use super::finestep::FINE_METHOD;
use crate::error::{Error, Result};
use crate::measure::grid::TimeGrid;
use crate::measure::probe::sig3;
use crate::model::{State, System};
use crate::run::cost::{CostModel, Work};

/// Fewest steps per radian of the fastest motion that the adaptive reference was seen to take
/// on the shipped scenes (the cloth: 1.47; the hanging chain 3.1, the pendulum 10): the
/// projection's floor.
pub const STEPS_PER_RADIAN: f64 = 1.0;

/// Force evaluations of one DOP853 step (twelve stages; the dense output adds three more where
/// it is asked for, which the floor leaves out).
pub const EVALS_PER_STEP: u64 = 12;

/// The two companion solves' work (a looser solve and a perturbed one,
/// [`super::uncertainty`]) relative to the main solve's: the perturbed one takes the same
/// steps, the looser about half.
pub const COMPANION_SHARE: f64 = 1.5;

/// Modelled seconds of one sample of the adaptive reference: the main solve's dense output
/// and its companions' at the sample time, stored (about 1 µs on the shipped scenes).
pub const SAMPLE: f64 = 1e-6;

/// Modelled seconds per particle of one sample: three dense evaluations of its six coordinates.
pub const SAMPLE_PER_PARTICLE: f64 = 20e-9;

/// Runs of the fine-step reference's first level's length that always run: the first level
/// (1), the perturbed run at the same step (1) and the second level at half the step (2).
pub const FINE_CERTAIN_RUNS: f64 = 4.0;

/// What a reference solve is projected to cost before it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// Modelled seconds (s).
    pub seconds: f64,
    /// Steps counted: the main adaptive solve's, or every fine-step run's together.
    pub steps: f64,
    /// What was counted, in words (for the refusal).
    pub what: String,
}

/// The fastest motion the adaptive solver must follow (rad/s): the highest linearised
/// frequency of the scene, or the swing √(|g|/L) of its shortest rigid rod under gravity.
pub fn fastest_motion(sys: &System, s0: &State) -> f64 {
    let omega = crate::measure::modes::modes(sys, s0).omega_max;
    let g = sys.gravity.map_or(0.0, |g| g.norm());
    let swing = sys
        .constraints
        .iter()
        .filter(|c| c.compliance == 0.0 && c.length > 0.0)
        .map(|c| (g / c.length).sqrt())
        .fold(0.0, f64::max);
    omega.max(swing)
}

/// Modelled seconds of one attempted DOP853 step on `sys`: [`EVALS_PER_STEP`] force
/// evaluations, the state update, with obstacles a contact pass per evaluation (the contact
/// model asks which particles are held, and where the step must stop, at every stage), and with
/// rigid rods a solve for their multipliers per evaluation, priced as a Newton iteration.
pub fn dop853_step_seconds(sys: &System) -> f64 {
    let work = Work {
        steps: 1,
        force_evals: EVALS_PER_STEP,
        contact_passes: if sys.post_step.is_some() {
            EVALS_PER_STEP
        } else {
            0
        },
        newton_iterations: if sys.constraints.iter().any(|c| c.compliance == 0.0) {
            EVALS_PER_STEP
        } else {
            0
        },
        ..Default::default()
    };
    CostModel::of(sys).seconds(&work)
}

/// The projected cost of the reference of `sys` from `s0` sampled on `grids` up to `horizon`
/// (the solver [`super::Reference::compute`] would choose; the ensemble is not included).
pub fn project(sys: &System, s0: &State, grids: &[TimeGrid], horizon: f64) -> Projection {
    let samples: f64 = grids.iter().map(|g| g.sample_count() as f64).sum();
    let sample_price = SAMPLE + SAMPLE_PER_PARTICLE * sys.len() as f64;
    if super::has_closed_form(sys) {
        return Projection {
            seconds: samples * sample_price,
            steps: 0.0,
            what: format!("the closed form at {} sample times", sig3(samples)),
        };
    }
    let projection =
        crate::collide::of(sys).is_some_and(|c| c.response == crate::collide::Response::Projection);
    if projection {
        // The kept hierarchy's first step where it fits (its levels never land on samples),
        // else the per-grid runs', which land on every sample time.
        let (h0, landings) = match super::fine_kept::kept_first_step(sys, s0, horizon) {
            Some(h0) => (h0, 0.0),
            None => {
                let finest = grids.iter().map(|g| g.dt).fold(f64::INFINITY, f64::min);
                ((0.5 * finest).min(horizon / 1000.0), samples)
            }
        };
        let steps = (horizon / h0).ceil() + landings;
        let per = fine_step_seconds(sys, s0, h0);
        return Projection {
            seconds: FINE_CERTAIN_RUNS * steps * per,
            steps: FINE_CERTAIN_RUNS * steps,
            what: format!(
                "the fine-step reference: {} steps of {FINE_METHOD} at {} s and below ({} ms per step by the cost model)",
                sig3(FINE_CERTAIN_RUNS * steps),
                sig3(h0),
                sig3(per * 1e3)
            ),
        };
    }
    let omega = fastest_motion(sys, s0);
    let contact_steps = if sys.post_step.is_some() {
        1.0 / CONTACT_MAX_STEP_FRACTION
    } else {
        0.0
    };
    let steps = (horizon * omega * STEPS_PER_RADIAN)
        .max(contact_steps)
        .max(1.0);
    let per = dop853_step_seconds(sys);
    Projection {
        seconds: steps * per * (1.0 + COMPANION_SHARE) + samples * sample_price,
        steps,
        what: format!(
            "the DOP853 reference: at least {} steps over {} s (ω = {} rad/s), with its two companion solves ({} ms per step by the cost model)",
            sig3(steps),
            sig3(horizon),
            sig3(omega),
            sig3(per * 1e3)
        ),
    }
}

/// Modelled seconds of one step of the fine-step reference at step `h`: the runner's price of a
/// [`FINE_METHOD`] step with the scene's contact stage.
fn fine_step_seconds(sys: &System, s0: &State, h: f64) -> f64 {
    crate::measure::probe::seconds_per_step(
        sys,
        s0,
        &crate::method::Registry::builtin(),
        &crate::method::MethodOptions::default(),
        FINE_METHOD,
        h,
        crate::measure::probe::PROBE_STEPS,
    )
    .unwrap_or_else(|| dop853_step_seconds(sys) / 3.0)
}

/// Refuses at once a reference projected past `budget` (s), naming the figure and `--budget`;
/// else returns the projection.
pub fn check(
    sys: &System,
    s0: &State,
    grids: &[TimeGrid],
    horizon: f64,
    budget: f64,
) -> Result<Projection> {
    let p = project(sys, s0, grids, horizon);
    if p.seconds > budget {
        return Err(Error::option(
            "--budget",
            format!(
                "the reference alone would take about {} s of modelled work ({}), beyond the budget of {} s; give a larger --budget or a shorter run (--duration, --steps)",
                sig3(p.seconds),
                p.what,
                sig3(budget)
            ),
        ));
    }
    Ok(p)
}

/// The most steps the main adaptive solve may attempt within `seconds` of modelled work,
/// leaving its companions their share.
pub fn dop853_step_limit(sys: &System, seconds: f64) -> StepLimit {
    let per = dop853_step_seconds(sys) * (1.0 + COMPANION_SHARE);
    StepLimit {
        steps: (seconds / per).floor().clamp(1.0, u64::MAX as f64) as u64,
        seconds,
    }
}

/// A limit on the main adaptive solve's attempted steps: what its share of a budget pays for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepLimit {
    /// Most attempted steps of the main solve.
    pub steps: u64,
    /// The modelled seconds they stand for (s).
    pub seconds: f64,
}

impl StepLimit {
    /// The error of a solve stopped at this limit before reaching `horizon` (s).
    pub fn error(&self, horizon: f64) -> Error {
        Error::option(
            "--budget",
            format!(
                "the reference (DOP853) stopped after {} solver steps, the {} s of modelled work the budget leaves it, before reaching the horizon of {} s (the scene needs far more steps than its fastest motion suggests: contacts that chatter, or particles started inside an obstacle); give a larger --budget or a shorter run (--duration, --steps)",
                self.steps,
                sig3(self.seconds),
                sig3(horizon)
            ),
        )
    }
}

/// Modelled seconds of one fine-step run over `span` (s) at step `h`: what an ensemble member
/// of the fine-step reference costs, checked before the members start.
pub fn fine_run_seconds(sys: &System, s0: &State, h: f64, span: f64) -> f64 {
    (span / h).ceil() * fine_step_seconds(sys, s0, h)
}
