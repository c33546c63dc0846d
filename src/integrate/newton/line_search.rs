//! The Newton stage's line search: backtracking along the Newton direction on the residual
//! merit or Armijo's condition on the incremental potential.

use super::potential::potential;
use super::stage::Stage;
use super::{Newton, Residual};

/// Armijo's sufficient-decrease constant c₁ (Nocedal & Wright §3.1: 10⁻⁴ is usual).
const ARMIJO: f64 = 1e-4;

impl Newton {
    /// Backtracking by halves from the full step α·`self.dv` (α = 1, ½, ¼, …): a trial is
    /// taken once the residual merit GᵀM⁻¹G falls, or the stage's incremental potential Φ
    /// (damping directions frozen at the base `self.vbase`, so that ∇Φ there is exactly the
    /// residual G) falls by Armijo's margin, Φ(α) ≤ Φ(0) + c₁ α Gᵀd (Nocedal & Wright,
    /// Alg. 3.1), by more than Φ's own round-off. The shifted Newton matrix is positive
    /// definite, so the direction descends on Φ and some α passes; the residual test keeps
    /// the iterates near the floor of a stiff valley that curves (a spinning stiff body),
    /// where Φ alone accepts steps far up its walls that spoil the next linearisation. `gd` =
    /// Gᵀd. After `max_halvings` trials the last is taken. Updates `res` to the accepted
    /// iterate's; returns (α, force evaluations).
    pub(super) fn backtrack(&mut self, st: &Stage<'_>, res: &mut Residual, gd: f64) -> (f64, u64) {
        let mut evals = 0;
        let mut alpha = 1.0;
        // The base's potential and its round-off, computed only if needed.
        let mut base: Option<(f64, f64)> = None;
        for trial_no in 0..=self.settings.max_halvings {
            let trial = self.trial(st, alpha);
            evals += 1;
            let mut done = trial.merit <= res.merit || trial_no == self.settings.max_halvings;
            if !done && trial.merit.is_finite() {
                let (phi0, noise) = match base {
                    Some(b) => b,
                    None => {
                        evals += 1;
                        *base.insert(self.base_potential(st))
                    }
                };
                // Each potential evaluates the dampers' power: a force pass.
                let (phi, _) = potential(st.sys, st.x0, st.v0, &self.vn, st.h, &mut self.pot);
                evals += 1;
                let change = phi - phi0;
                done = change < -noise && change <= ARMIJO * alpha * gd;
            }
            if done {
                if trial_no > 0 {
                    self.damped_updates += 1;
                }
                *res = trial;
                break;
            }
            alpha *= 0.5;
        }
        (alpha, evals)
    }

    /// A line-search trial: v' = `self.vbase` + t·`self.dv`, and the residual there.
    fn trial(&mut self, st: &Stage<'_>, t: f64) -> Residual {
        for p in 0..st.x0.len() {
            self.vn[p] = self.vbase[p] + self.dv[p] * t;
        }
        self.residual(st)
    }

    /// The incremental potential at `self.vbase`, freezing the damping directions there, and
    /// its round-off.
    fn base_potential(&mut self, st: &Stage<'_>) -> (f64, f64) {
        for p in 0..st.x0.len() {
            self.pot.x_frozen[p] = st.x0[p] + self.vbase[p] * st.h;
        }
        potential(st.sys, st.x0, st.v0, &self.vbase, st.h, &mut self.pot)
    }
}
