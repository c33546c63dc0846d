//! The modelled cost of a run: the work it counted (steps, force evaluations, Newton and
//! linear iterations, a preconditioner's factorisations and substitutions, a stalled stage's
//! patch iterations, link updates, contact passes, an engine's modelled frames) times
//! fixed per-item costs of the scene (particles, springs, force terms).
//!
//! Why a model and not the clock: every decision a command takes on cost (what fits a time
//! budget, which candidate advice ranks first, the cheapest frame rate that meets a tolerance)
//! must come out the same on every re-run and every machine, and a wall time never does. The
//! work counts are deterministic, so the modelled cost is too; measured wall times are
//! reported beside it and decide nothing.
//!
//! A factored preconditioner's work is priced apart from its CG iterations: a block IC(0)
//! factorisation and each application of the factor cost their own per-spring figures (an
//! IC(0) iteration, its factorisation shared in, costs about three block-Jacobi ones). Their
//! figures are fitted on the 100×100 cloth's first 30 frames at 1/60 s (`springlab compare`
//! with `--linear-solver block_ic0_cg`, then `block_jacobi_cg`): the four implicit methods'
//! modelled cost is 0.80-1.04 of the clock with IC(0) and 1.04-1.24 with block Jacobi (two
//! runs each); without them it read 0.35-0.42 with IC(0). The sparse Cholesky of a
//! `direct-solver` build is counted the same way and priced at IC(0)'s figures, which it
//! exceeds by an order of magnitude.
//!
//! The per-item costs are this code's single-thread figures on a 2-core x86-64 machine,
//! fitted to the stepping wall times of the shipped scenes (`springlab compare` on each:
//! `work` against `wall_seconds` in `summary.json`). On them the model is within a factor of
//! 2.2 of the clock for every method, except the closed forms (up to 4.7: their
//! step is trigonometry the model does not price), and mostly within 1.5. They are a scale,
//! not a promise: a faster machine scales every figure alike and leaves every decision as it
//! was.

use crate::model::System;
use serde::Serialize;

/// Seconds per step, whatever the scene: the runner's and the method's fixed overhead.
pub const STEP: f64 = 25e-9;
/// Seconds per particle per step: the state update every method makes.
pub const STEP_PER_PARTICLE: f64 = 2e-9;
/// Seconds per force evaluation, whatever the scene.
pub const FORCE_EVAL: f64 = 40e-9;
/// Seconds per spring per force evaluation.
pub const FORCE_PER_SPRING: f64 = 7.5e-9;
/// Seconds per particle per force term (gravity, drag, penalty contact) per force evaluation.
pub const FORCE_PER_PARTICLE_TERM: f64 = 1.5e-9;
/// Seconds per Newton iteration, whatever the scene.
pub const NEWTON: f64 = 200e-9;
/// Seconds per particle per Newton iteration: residual, line search and momentum balance.
pub const NEWTON_PER_PARTICLE: f64 = 75e-9;
/// Seconds per spring per Newton iteration: the Jacobian blocks.
pub const NEWTON_PER_SPRING: f64 = 33e-9;
/// Seconds per linear (CG) iteration, whatever the scene.
pub const LINEAR: f64 = 40e-9;
/// Seconds per particle per linear iteration: the preconditioner and vector updates.
pub const LINEAR_PER_PARTICLE: f64 = 15e-9;
/// Seconds per spring per linear iteration: its part of the product with the Newton matrix.
pub const LINEAR_PER_SPRING: f64 = 3.25e-9;
/// Seconds per spring per numeric factorisation of a preconditioner: block IC(0)'s
/// elimination with the clamped Jacobian it is built from (a Manteuffel retry is charged
/// alike). Fitted on cloth, per spring only (see the module docs).
pub const FACTORIZATION_PER_SPRING: f64 = 60e-9;
/// Seconds per spring per application of a factored preconditioner: IC(0)'s forward and
/// backward substitutions, one lower block per spring each. Fitted on cloth, per spring
/// only.
pub const FACTOR_SOLVE_PER_SPRING: f64 = 5.5e-9;
/// Seconds per trust-region iteration on a stalled stage's patch, whatever the scene: the
/// dense factorisation or eigendecomposition of its Hessian (at most 360 unknowns), fitted on
/// the 100×100 cloth's stalled bdf2 stages (4-22 ms per iteration, the global passes a Newton
/// iteration makes included, which are priced as one).
pub const PATCH_DENSE: f64 = 8e-3;
/// Seconds per link update (one link in one constraint sweep).
pub const LINK_UPDATE: f64 = 26e-9;
/// Seconds per particle per pass of the contact stage (obstacle queries and responses).
pub const CONTACT_PER_PARTICLE: f64 = 250e-9;

/// Work a run did, counted: the same on every machine and every re-run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Work {
    /// Steps taken (each substep of a frame counts).
    pub steps: u64,
    /// Force evaluations.
    pub force_evals: u64,
    /// Newton iterations of implicit methods.
    pub newton_iterations: u64,
    /// Linear-solver iterations of implicit methods (a direct solve counts one).
    pub linear_iterations: u64,
    /// Numeric factorisations of a preconditioner (IC(0)'s, or a `direct-solver` build's
    /// sparse Cholesky); not written where none were made.
    #[serde(skip_serializing_if = "is_zero")]
    pub factorizations: u64,
    /// Applications of a factored preconditioner; not written where none were made.
    #[serde(skip_serializing_if = "is_zero")]
    pub factor_solves: u64,
    /// Trust-region iterations on the dense patch of a stalled implicit stage; not written
    /// where none were made.
    #[serde(skip_serializing_if = "is_zero")]
    pub patch_iterations: u64,
    /// Link updates (one link in one constraint sweep).
    pub link_updates: u64,
    /// Passes of the contact stage.
    pub contact_passes: u64,
    /// Modelled seconds of an engine's own work ([`crate::integrate::StepStats::engine_seconds`]).
    pub engine_seconds: f64,
}

/// The scene's per-unit costs (s): what one count of each kind of [`Work`] costs on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostModel {
    step: f64,
    force_eval: f64,
    newton_iteration: f64,
    linear_iteration: f64,
    factorization: f64,
    factor_solve: f64,
    contact_pass: f64,
}

/// Whether a count is zero (left out of the written work).
fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl CostModel {
    /// The per-unit costs of `sys`, from its particles, springs, constraints and force terms.
    pub fn of(sys: &System) -> Self {
        let n = sys.len() as f64;
        let springs = sys.springs.len() as f64;
        let terms = sys.terms.len() as f64;
        CostModel {
            step: STEP + STEP_PER_PARTICLE * n,
            force_eval: FORCE_EVAL
                + FORCE_PER_SPRING * springs
                + FORCE_PER_PARTICLE_TERM * n * terms,
            newton_iteration: NEWTON + NEWTON_PER_PARTICLE * n + NEWTON_PER_SPRING * springs,
            linear_iteration: LINEAR + LINEAR_PER_PARTICLE * n + LINEAR_PER_SPRING * springs,
            factorization: FACTORIZATION_PER_SPRING * springs,
            factor_solve: FACTOR_SOLVE_PER_SPRING * springs,
            contact_pass: CONTACT_PER_PARTICLE * n,
        }
    }

    /// Modelled seconds of `work` on this scene.
    pub fn seconds(&self, work: &Work) -> f64 {
        self.step * work.steps as f64
            + self.force_eval * work.force_evals as f64
            + self.newton_iteration * work.newton_iterations as f64
            + self.linear_iteration * work.linear_iterations as f64
            + self.factorization * work.factorizations as f64
            + self.factor_solve * work.factor_solves as f64
            + (self.newton_iteration + PATCH_DENSE) * work.patch_iterations as f64
            + LINK_UPDATE * work.link_updates as f64
            + self.contact_pass * work.contact_passes as f64
            + work.engine_seconds
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    fn chain(beads: usize) -> System {
        let mut t = String::from("[world]\ngravity=[0.0,-9.81,0.0]\n");
        for i in 0..beads {
            t += &format!("[[particle]]\nposition=[{i}.0,0.0,0.0]\nmass=1.0\n");
        }
        for i in 1..beads {
            t += &format!("[[spring]]\nbetween=[{}, {i}]\nstiffness=10.0\n", i - 1);
        }
        Scenario::from_toml_str(&t, "chain.toml").unwrap().build()
    }

    // Oracle: the model is linear in every count and in the scene's items, by construction.
    #[test]
    fn cost_is_linear_in_the_work_and_grows_with_the_scene() {
        let (small, big) = (CostModel::of(&chain(10)), CostModel::of(&chain(20)));
        let w = Work {
            steps: 3,
            force_evals: 3,
            ..Work::default()
        };
        let twice = Work {
            steps: 6,
            force_evals: 6,
            ..Work::default()
        };
        assert!(small.seconds(&w) > 0.0);
        assert!((small.seconds(&twice) - 2.0 * small.seconds(&w)).abs() < 1e-24);
        // Ten more particles and springs (one force term, gravity): three steps and three
        // force evaluations of them.
        let extra = 3.0 * STEP_PER_PARTICLE * 10.0
            + 3.0 * (FORCE_PER_SPRING * 10.0 + FORCE_PER_PARTICLE_TERM * 10.0);
        let grew = big.seconds(&w) - small.seconds(&w);
        assert!(
            (grew - extra).abs() < 1e-12 * extra,
            "{grew:e} vs {extra:e}"
        );
        // A factorisation and a factor solve of IC(0) cost their per-spring figures: ten
        // springs more, three of each.
        let factored = Work {
            factorizations: 3,
            factor_solves: 3,
            ..Work::default()
        };
        let grew = big.seconds(&factored) - small.seconds(&factored);
        let extra = 3.0 * (FACTORIZATION_PER_SPRING + FACTOR_SOLVE_PER_SPRING) * 10.0;
        assert!(
            (grew - extra).abs() < 1e-12 * extra,
            "{grew:e} vs {extra:e}"
        );
        // A patch iteration costs a Newton iteration and the dense decomposition: ten
        // particles and springs more add a Newton iteration's share of them, twice.
        let patched = Work {
            patch_iterations: 2,
            ..Work::default()
        };
        let newton = Work {
            newton_iterations: 2,
            ..Work::default()
        };
        assert!(
            (small.seconds(&patched) - small.seconds(&newton) - 2.0 * PATCH_DENSE).abs() < 1e-15
        );
        let grew = big.seconds(&patched) - small.seconds(&patched);
        let extra = 2.0 * (NEWTON_PER_PARTICLE + NEWTON_PER_SPRING) * 10.0;
        assert!(
            (grew - extra).abs() < 1e-12 * extra,
            "{grew:e} vs {extra:e}"
        );
        let engine = Work {
            engine_seconds: 0.25,
            ..Work::default()
        };
        assert_eq!(small.seconds(&engine), 0.25);
    }
}
