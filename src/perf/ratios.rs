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

/// Steps the implicit method `method`, built with `opts` (its linear solver and Newton cap),
/// `steps` times at `h` from the scene's initial state and reports its solver work, judged
/// step by step by the runner's verdict ([`crate::run::verdict::Verdict`]: a run whose
/// energy balance grows without bound is unstable from the step the runner names, and runs
/// on as the runner's does). `Err` naming the step when one fails (or when `method` is not
/// implicit), with the reason the runner gives for it (a failure after the energy balance rose
/// past ten scales is the energy's doing, [`crate::run::verdict::Verdict::failed_step`]), or
/// the runner's words where a verdict stops the run (a diverged state, the hard cap). Only
/// the steps are timed, not the verdict's energy accounts.
pub fn implicit_cost(
    scene: &Scenario,
    method: &str,
    opts: &MethodOptions,
    h: f64,
    steps: usize,
) -> std::result::Result<ImplicitCost, String> {
    use crate::run::verdict::{Rule, Verdict};
    use crate::run::{EnergyRecord, Status, DEFAULT_BLOWUP_FACTOR};
    let sys = scene.build();
    let mut s = scene.initial_state();
    let mut stepper = crate::method::create(method, opts).map_err(|e| e.to_string())?;
    if !stepper.info.implicit {
        return Err(format!("{method} has no implicit solver"));
    }
    let (mut verdict, mut last) =
        Verdict::for_run(&sys, &s, h * steps as f64, DEFAULT_BLOWUP_FACTOR);
    let mut status = Status::Ok;
    let mut evals = 0;
    let mut newton_max = 0;
    let mut dissipated = 0.0;
    let mut secs = 0.0;
    for k in 0..steps {
        let before = stepper.solver_work().newton_iterations;
        let t0 = Instant::now();
        let stepped = stepper.step(&sys, &mut s, h);
        secs += t0.elapsed().as_secs_f64();
        let stats = stepped.map_err(|e| match e {
            crate::Error::Step(why) => {
                format!("step {k} failed: {}", verdict.failed_step(&last, &why))
            }
            other => format!("step {k} failed: {other}"),
        })?;
        evals += stats.force_evals;
        dissipated += stats.dissipated;
        newton_max = newton_max.max(stepper.solver_work().newton_iterations - before);
        last = EnergyRecord::new(sys.state_energy(&s), dissipated, 0.0);
        if let Some(fired) = verdict.step(&s, &last) {
            let unstable = Status::Unstable {
                step: k as u64 + 1,
                time: (k + 1) as f64 * h,
                reason: fired.reason,
            };
            if matches!(fired.rule, Rule::Diverged | Rule::Cap) {
                return Err(unstable.to_string());
            }
            if status.is_ok() {
                status = unstable;
            }
        }
    }
    let w = stepper.solver_work();
    let n = steps.max(1) as f64;
    Ok(ImplicitCost {
        steps,
        seconds_per_step: secs / n,
        newton_per_step: w.newton_iterations as f64 / n,
        linear_per_step: w.linear_iterations as f64 / n,
        factorizations_per_step: w.factorizations as f64 / n,
        force_evals_per_step: evals as f64 / n,
        newton_max,
        shifted_per_step: w.modified_iterations as f64 / n,
        patch_per_step: w.patch_iterations as f64 / n,
        status,
    })
}
