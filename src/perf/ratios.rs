//! The cost ratios that have targets, each measured in one run with the contenders
//! interleaved (A, B, A, B, ...) and the minimum and median per step kept for each: on a
//! shared, noisy machine a slow phase then hits both sides of a ratio instead of one.

use crate::error::Result;
use crate::integrate::Stepper;
use crate::method::MethodOptions;
use crate::model::{State, System, Vec3};
use crate::scenario::Scenario;
use std::time::Instant;

/// One contender: runs a batch of steps and returns the wall time per step (s).
pub type Contender<'a> = Box<dyn FnMut() -> Result<f64> + Send + 'a>;

/// A contender's times per step over the rounds of one interleaved run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundTimes {
    /// The fastest round (s per step): the least disturbed by the machine.
    pub min: f64,
    /// The median round (s per step): what a typical round cost.
    pub median: f64,
}

/// Runs every contender once per round, `rounds` times, in turn; the minimum and median time
/// per step of each.
pub fn interleaved_stats(
    rounds: usize,
    contenders: &mut [Contender<'_>],
) -> Result<Vec<RoundTimes>> {
    let mut all = vec![Vec::with_capacity(rounds.max(1)); contenders.len()];
    for _ in 0..rounds.max(1) {
        for (t, c) in all.iter_mut().zip(contenders.iter_mut()) {
            t.push(c()?);
        }
    }
    Ok(all
        .into_iter()
        .map(|mut t| {
            t.sort_by(f64::total_cmp);
            let m = t.len() / 2;
            let median = if t.len() % 2 == 1 {
                t[m]
            } else {
                0.5 * (t[m - 1] + t[m])
            };
            RoundTimes { min: t[0], median }
        })
        .collect())
}

/// A contender stepping `stepper` `batch` times from `s0` (restarted, untimed, every batch, so
/// conditionally stable methods never time a blown-up state), after one untimed warm-up step.
pub fn stepping<'a>(
    sys: &'a System,
    s0: &'a State,
    mut stepper: Box<dyn Stepper>,
    h: f64,
    batch: usize,
) -> Contender<'a> {
    let mut s = s0.clone();
    let mut warm = false;
    Box::new(move || {
        if !warm {
            stepper.step(sys, &mut s, h)?;
            warm = true;
        }
        s.clone_from(s0);
        stepper.reset();
        let t0 = Instant::now();
        for _ in 0..batch.max(1) {
            stepper.step(sys, &mut s, h)?;
        }
        Ok(t0.elapsed().as_secs_f64() / batch.max(1) as f64)
    })
}

/// A contender running the hand-written baseline loop [`super::hand_step`] `batch` times.
pub fn hand_loop<'a>(sys: &'a System, s0: &'a State, h: f64, batch: usize) -> Contender<'a> {
    let (mut x, mut v) = (s0.x.clone(), s0.v.clone());
    let mut f = vec![Vec3::zeros(); sys.len()];
    Box::new(move || {
        x.clone_from(&s0.x);
        v.clone_from(&s0.v);
        let t0 = Instant::now();
        for _ in 0..batch.max(1) {
            super::hand_step(sys, &mut x, &mut v, &mut f, h);
        }
        std::hint::black_box(&x);
        Ok(t0.elapsed().as_secs_f64() / batch.max(1) as f64)
    })
}

/// A contender running the stencil loop [`super::stencil::GridCloth`] of an `n`×`n` grid
/// cloth `batch` times from `s0`; `None` when `sys` is not exactly such a cloth.
pub fn best_loop<'a>(
    sys: &System,
    s0: &'a State,
    n: usize,
    h: f64,
    batch: usize,
) -> Option<Contender<'a>> {
    let mut g = super::stencil::GridCloth::of(sys, n, n)?;
    Some(Box::new(move || {
        g.set_state(&s0.x, &s0.v);
        let t0 = Instant::now();
        for _ in 0..batch.max(1) {
            g.step(h);
        }
        std::hint::black_box(g.position(0));
        Ok(t0.elapsed().as_secs_f64() / batch.max(1) as f64)
    }))
}

/// A contender running `inner` inside a rayon pool of `threads` threads.
pub fn on_threads<'a>(threads: usize, mut inner: Contender<'a>) -> Result<Contender<'a>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| crate::error::Error::Step(format!("thread pool: {e}")))?;
    Ok(Box::new(move || pool.install(&mut inner)))
}

/// A fresh stepper of the method `name`, with default options.
pub fn fresh_stepper(name: &str) -> Result<Box<dyn Stepper>> {
    crate::method::create(name, &MethodOptions::default()).map(|m| m.stepper)
}

/// What an implicit method's solver did over some steps of one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ImplicitCost {
    /// Steps taken.
    pub steps: usize,
    /// Wall time per step (s).
    pub seconds_per_step: f64,
    /// Newton iterations (linear solves) per step.
    pub newton_per_step: f64,
    /// Linear-solver iterations per step (CG iterations; a direct solve counts one).
    pub linear_per_step: f64,
    /// Numeric factorisations of a preconditioner per step (0 for matrix-free CG; IC(0)'s
    /// each shift attempt and Manteuffel retry counted apart).
    pub factorizations_per_step: f64,
    /// Force evaluations per step.
    pub force_evals_per_step: f64,
    /// Most Newton iterations any one step took (the hardest stage, against the cap
    /// [`crate::integrate::ImplicitSettings::max_newton`]).
    pub newton_max: u64,
    /// Newton iterations per step whose matrix carried a Levenberg–Marquardt shift (the exact
    /// one was indefinite, or the last step overshot).
    pub shifted_per_step: f64,
    /// Trust-region iterations per step on the dense patches of stalled stages (nonlinear
    /// elimination).
    pub patch_per_step: f64,
    /// The runner's verdict on the run: unstable from the step where its energy balance
    /// began to grow without bound, though every stage met its equation.
    pub status: crate::run::Status,
}

/// Runs the implicit method `method`, built with `opts` (its linear solver and Newton cap),
/// `steps` steps at `h` from the scene's initial state through the runner, and reports its
/// solver work and the runner's status: a run whose energy balance grows without bound is
/// unstable from the step the runner names and runs on, as `run`'s does. `Err` naming the
/// step when one fails (or when `method` is not implicit), with the runner's reason for it (a
/// failure after the energy balance rose past ten scales is the energy's doing,
/// [`crate::run::verdict::Verdict::failed_step`]), or the runner's status where a verdict
/// stops the run (a diverged state, the hard cap). The times are the runner's, inside the
/// steps only.
pub fn implicit_cost(
    scene: &Scenario,
    method: &str,
    opts: &MethodOptions,
    h: f64,
    steps: usize,
) -> std::result::Result<ImplicitCost, String> {
    use crate::run::{run_with, NoObserver, RunPlan, Status};
    let sys = scene.build();
    let mut m = crate::method::create(method, opts).map_err(|e| e.to_string())?;
    if !m.info.implicit {
        return Err(format!("{method} has no implicit solver"));
    }
    let mut watched = Watched {
        inner: m.stepper.as_mut(),
        newton_max: 0,
        failed: false,
    };
    let plan = RunPlan {
        stop_at_verdict: false,
        ..RunPlan::new(h, steps as u64)
    };
    let out = run_with(
        &sys,
        &mut watched,
        &m.info,
        scene.initial_state(),
        &plan,
        &mut NoObserver,
    )
    .map_err(|e| e.to_string())?;
    match &out.status {
        Status::Unstable { reason, .. } if watched.failed => {
            return Err(format!("step {} failed: {reason}", out.steps_done))
        }
        unstable if out.steps_done < steps as u64 => return Err(unstable.to_string()),
        _ => {}
    }
    let w = watched.solver_work();
    let n = (out.steps_done as f64).max(1.0);
    Ok(ImplicitCost {
        steps,
        seconds_per_step: out.wall_seconds / n,
        newton_per_step: w.newton_iterations as f64 / n,
        linear_per_step: w.linear_iterations as f64 / n,
        factorizations_per_step: w.factorizations as f64 / n,
        force_evals_per_step: out.force_evals as f64 / n,
        newton_max: watched.newton_max,
        shifted_per_step: w.modified_iterations as f64 / n,
        patch_per_step: w.patch_iterations as f64 / n,
        status: out.status,
    })
}

/// A stepper that passes every call on to `inner`, noting what the runner's outcome does not
/// keep: the most Newton iterations one step took, and whether a step failed.
struct Watched<'a> {
    inner: &'a mut dyn Stepper,
    newton_max: u64,
    failed: bool,
}

impl Stepper for Watched<'_> {
    fn check(&self, sys: &System) -> std::result::Result<(), String> {
        self.inner.check(sys)
    }
    fn modelled_frame_seconds(&self, sys: &System) -> Option<f64> {
        self.inner.modelled_frame_seconds(sys)
    }
    fn reset(&mut self) {
        self.inner.reset();
    }
    fn solver_work(&self) -> crate::integrate::SolverWork {
        self.inner.solver_work()
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<crate::integrate::StepStats> {
        let before = self.inner.solver_work().newton_iterations;
        let stepped = self.inner.step(sys, s, h);
        let took = self.inner.solver_work().newton_iterations - before;
        self.newton_max = self.newton_max.max(took);
        self.failed |= stepped.is_err();
        stepped
    }
}
