//! Native time-stepping schemes: one trait ([`Stepper`]), one file per method. Their names and facts are registered in
//! [`crate::method`].
//!
//! Write your own scheme by implementing [`Stepper`] and registering it
//! ([`crate::method::Registry::with`]); the runner, every command and the report then treat it
//! exactly like the built-in ones (see `examples/custom_method.rs`).

mod analytic;
mod bdf2;
mod euler;
mod implicit;
mod implicit_euler;
mod implicit_midpoint;
mod linear_implicit_euler;
mod newton;
mod rattle;
mod rk;
mod shake;
mod verlet;
mod verlet_constraints;
mod xpbd;

pub use analytic::Analytic;
pub use bdf2::{Bdf2, Bdf2Rule};
pub use euler::{ExplicitEuler, SymplecticEuler};
pub use implicit::{Implicit, Rule, StageKind};
pub use implicit_euler::{BackwardEuler, ImplicitEuler};
pub use implicit_midpoint::{ImplicitMidpoint, Midpoint};
pub use linear_implicit_euler::{LinearImplicitEuler, LinearizedEuler};
pub use newton::{ImplicitSettings, LinearSolver, Newton};
pub use rattle::{Rattle, RattleSettings};
pub use rk::{RungeKutta, Tableau};
pub use verlet::{PositionVerlet, VelocityVerlet};
pub use verlet_constraints::VerletConstraints;
pub use xpbd::Xpbd;

use crate::error::Result;
use crate::model::{State, System};

/// What one step cost and what it did to the energy accounts.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepStats {
    /// Force evaluations ([`System::accelerations`] calls) made by the step.
    pub force_evals: u64,
    /// Work done against dampers and drag during the step (J, ≥ 0), integrated with the
    /// method's own quadrature so that the energy balance is as accurate as the method.
    pub dissipated: f64,
    /// Constraint or link updates, one per link per sweep (XPBD's Gauss–Seidel sweeps, RATTLE's
    /// iterations, projection sweeps): work the force-evaluation count does not see.
    pub link_updates: u64,
    /// Modelled seconds of work outside springlab's force model (a physics engine's step),
    /// from the engine's own cost model ([`crate::run::cost`]); 0 for native methods.
    pub engine_seconds: f64,
}

/// What a method's equation solver has done so far, counted over every step tried (a failed
/// one included); all zero for a method that solves no equations.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolverWork {
    /// Newton iterations (linear solves).
    pub newton_iterations: u64,
    /// Linear-solver iterations (CG iterations; a direct solve counts one).
    pub linear_iterations: u64,
    /// Numeric factorisations of a preconditioner: block IC(0)'s of the clamped Newton matrix
    /// (each Manteuffel retry counted apart) or the sparse Cholesky's.
    pub factorizations: u64,
    /// Applications of a factored preconditioner (one forward and one backward substitution
    /// each): one per CG solve and at most one per CG iteration, and one per direct solve.
    pub factor_solves: u64,
    /// Newton iterations whose matrix needed a positive-definite modification (the exact
    /// one was indefinite): how often the stages were hard.
    pub modified_iterations: u64,
    /// Trust-region iterations on the dense patch of a stalled stage (nonlinear elimination,
    /// `newton/patch.rs`).
    pub patch_iterations: u64,
}

/// Advances a [`State`] of a [`System`] by one step; owns its scratch buffers.
///
/// ```
/// use springlab::integrate::{Stepper, SymplecticEuler};
/// use springlab::scenario::Scenario;
/// let scene = Scenario::from_toml_str("[[particle]]\nposition=[0.0,0.0,0.0]\nvelocity=[1.0,0.0,0.0]\nmass=1.0", "free.toml").unwrap();
/// let sys = scene.build();
/// let mut s = scene.initial_state();
/// let mut m = SymplecticEuler::default();
/// m.step(&sys, &mut s, 0.5).unwrap();
/// assert_eq!(s.x[0].x, 0.5);
/// ```
pub trait Stepper: Send {
    /// `Err(reason)` when this method cannot run `sys` faithfully (say, it has constraints).
    fn check(&self, sys: &System) -> std::result::Result<(), String> {
        if sys.constraints.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "the scene has {} rigid constraint(s) this method cannot honour; use rattle, verlet_constraints or a Rapier method",
                sys.constraints.len()
            ))
        }
    }
    /// Modelled seconds of one frame of `sys` when the method's cost does not depend on the
    /// run (a physics engine's cost model, [`crate::run::cost`]): budgets then price it
    /// without running it. `None` (the default): the cost is counted from a short run.
    fn modelled_frame_seconds(&self, _sys: &System) -> Option<f64> {
        None
    }
    /// Forgets any history (cached forces, previous positions): the state was changed from
    /// outside (an impulse, a contact) or the step size changes.
    fn reset(&mut self) {}
    /// What its equation solver has done so far (the runner books the difference over each
    /// step as the step's cost); zero for methods that solve no equations.
    fn solver_work(&self) -> SolverWork {
        SolverWork::default()
    }
    /// Advances `s` from `s.t` to `s.t + h`. Fixed particles never move.
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats>;
}

/// Resizes a scratch buffer once (no allocation when the size is unchanged).
pub(crate) fn ensure_len<T: Clone + Default>(buf: &mut Vec<T>, n: usize) {
    if buf.len() != n {
        buf.clear();
        buf.resize(n, T::default());
    }
}
