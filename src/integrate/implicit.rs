//! The one stepper of every method built on the shared implicit core ([`Newton`]), in the
//! style of a tableau: a method is a name and a [`StageKind`], how its step is made of
//! backward-Euler stages; [`Implicit`] makes the step for every kind and does what they share
//! (the core's settings and counters, reset, the step's bookkeeping). The methods' own files
//! say what each kind is and why.

use super::newton::{Newton, Stop};
use super::{ensure_len, SolverWork, StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System, Vec3};
use std::marker::PhantomData;

/// How an implicit method's step is made of the shared core's stages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageKind {
    /// The stage itself at the full step (backward Euler).
    Full,
    /// One linear solve with the Jacobian at the step's start (linearly implicit Euler).
    Linearized,
    /// The stage at half the step, then the extrapolation to the step's end (implicit
    /// midpoint).
    Midpoint,
    /// The stage at 2h/3 from the extrapolated base (4yₙ − yₙ₋₁)/3, after a backward-Euler
    /// start (BDF2).
    Bdf2,
}

/// An implicit method's facts for [`Implicit`]: its name and its stage kind.
pub trait Rule: std::fmt::Debug + Default + Send {
    /// The method's name, as registered: what the solver's errors say.
    const NAME: &'static str;
    /// How its step is made.
    const STAGE: StageKind;
}

/// An implicit method: its stage kind on the shared Newton + preconditioned-CG core.
#[derive(Debug, Default)]
pub struct Implicit<R> {
    /// The solver, its settings and its iteration counters.
    pub newton: Newton,
    /// BDF2's previous state (unused by the one-step kinds).
    history: History,
    rule: PhantomData<R>,
}

/// What a two-step kind keeps between steps.
#[derive(Debug, Default)]
struct History {
    x_prev: Vec<Vec3>,
    v_prev: Vec<Vec3>,
    x_base: Vec<Vec3>,
    v_base: Vec<Vec3>,
    /// Dissipated power at the current state (end of the last step).
    power: f64,
    /// Step of the last step; `None` when the history is void (start or reset).
    h_prev: Option<f64>,
}

impl<R: Rule> Implicit<R> {
    /// The shared implicit core: its settings and counters.
    pub fn newton(&self) -> &Newton {
        &self.newton
    }
    /// The shared implicit core, to choose its settings.
    pub fn newton_mut(&mut self) -> &mut Newton {
        &mut self.newton
    }
}

impl<R: Rule> Stepper for Implicit<R> {
    fn solver_work(&self) -> SolverWork {
        let n = &self.newton;
        SolverWork {
            newton_iterations: n.newton_iterations,
            linear_iterations: n.cg_iterations,
            factorizations: n.factorizations(),
            factor_solves: n.factor_solves(),
            modified_iterations: n.shifted_iterations,
            patch_iterations: n.patch_iterations,
        }
    }
    fn reset(&mut self) {
        self.history.h_prev = None;
        self.newton.reset();
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let nw = &mut self.newton;
        let (dissipated, evals) = match R::STAGE {
            StageKind::Full => {
                let (power, evals) = nw.solve(sys, &s.x, &s.v, h, Stop::FirstOrder, R::NAME)?;
                take(nw, s);
                (power * h, evals)
            }
            StageKind::Linearized => {
                let (power, evals) = nw.solve_linearized(sys, &s.x, &s.v, h, R::NAME)?;
                take(nw, s);
                (power * h, evals)
            }
            StageKind::Midpoint => {
                let (power, evals) =
                    nw.solve(sys, &s.x, &s.v, 0.5 * h, Stop::SecondOrder, R::NAME)?;
                let (xm, u) = (nw.x(), nw.v());
                for p in 0..s.len() {
                    if sys.free[p] {
                        s.x[p] = xm[p] * 2.0 - s.x[p];
                        s.v[p] = u[p] * 2.0 - s.v[p];
                    }
                }
                (power * h, evals)
            }
            StageKind::Bdf2 => self.history.bdf2(nw, sys, s, h, R::NAME)?,
        };
        s.t += h;
        Ok(StepStats {
            force_evals: evals,
            dissipated,
            ..StepStats::default()
        })
    }
}

/// Moves `s` to the stage's solution.
fn take(nw: &Newton, s: &mut State) {
    s.x.copy_from_slice(nw.x());
    s.v.copy_from_slice(nw.v());
}

impl History {
    /// BDF2's step: dissipated work (trapezoidal over the step; backward Euler's h·P at the
    /// start) and force evaluations.
    fn bdf2(
        &mut self,
        nw: &mut Newton,
        sys: &System,
        s: &mut State,
        h: f64,
        name: &'static str,
    ) -> Result<(f64, u64)> {
        let n = s.len();
        for buf in [
            &mut self.x_prev,
            &mut self.v_prev,
            &mut self.x_base,
            &mut self.v_base,
        ] {
            ensure_len(buf, n);
        }
        let (power, evals, dissipated);
        if self.h_prev != Some(h) {
            (power, evals) = nw.solve(sys, &s.x, &s.v, h, Stop::SecondOrder, name)?;
            dissipated = power * h;
        } else {
            for p in 0..n {
                // Fixed particles keep their state exactly ((4x − x)/3 need not round to x).
                (self.x_base[p], self.v_base[p]) = if sys.free[p] {
                    (
                        (s.x[p] * 4.0 - self.x_prev[p]) / 3.0,
                        (s.v[p] * 4.0 - self.v_prev[p]) / 3.0,
                    )
                } else {
                    (s.x[p], s.v[p])
                };
            }
            (power, evals) = nw.solve(
                sys,
                &self.x_base,
                &self.v_base,
                2.0 * h / 3.0,
                Stop::SecondOrder,
                name,
            )?;
            dissipated = 0.5 * h * (self.power + power);
        }
        self.x_prev.copy_from_slice(&s.x);
        self.v_prev.copy_from_slice(&s.v);
        take(nw, s);
        self.power = power;
        self.h_prev = Some(h);
        Ok((dissipated, evals))
    }
}
