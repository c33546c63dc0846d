//! The sweep's time budget: before the cases run, a short probe of each method at the base
//! grid's smallest step counts its modelled seconds per step ([`crate::run::cost`]), which
//! projects the cost of every
//! candidate step it might run. When the methods' projected total exceeds the budget, the
//! budget is shared by water-filling: methods that fit keep every step, and the costliest ones
//! lose their finest steps (the dearest) down to an equal share; a method whose coarsest step
//! alone exceeds its share is left out. The plan records each method's measured cost and its
//! finest allowed step, so the summary states what was left out and why, with the figures.
//!
//! The budget counts modelled seconds of runs summed over methods and steps (one thread's
//! worth), so the decision depends neither on the thread count nor on the machine's speed or
//! load: a re-run decides the same. It is recorded and named wherever it cut something
//! (`--budget` raises it).

use crate::measure::probe::sig3;
use serde::{Deserialize, Serialize};

/// One method's measured cost and what the budget allows it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodBudget {
    /// The method.
    pub method: String,
    /// Its probe's modelled seconds per step.
    pub seconds_per_step: f64,
    /// Projected modelled seconds of all its candidate steps.
    pub projected_seconds: f64,
    /// Index in the plan's `dts` of the smallest step it may run (0: every candidate).
    pub finest: usize,
}

/// The budget a sweep ran under, when one was set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepBudget {
    /// The budget (s of runs, summed).
    pub seconds: f64,
    /// Per method of the plan, in its order.
    pub methods: Vec<MethodBudget>,
}

/// Wall time (s) of running every candidate step from `j` to the coarsest at `per_step`.
fn cost_from(steps: &[u64], per_step: f64, j: usize) -> f64 {
    per_step * steps[j..].iter().map(|&n| n as f64).sum::<f64>()
}

/// The finest allowed step index per method (`steps.len()`: none at all) so that the methods'
/// projected costs sum to at most `budget`: water-filling on the full projected costs, then
/// for each method the finest index whose cost fits its share; a method that fits no step is
/// left out and the others share the budget again.
pub fn allot(steps: &[u64], per_step: &[f64], budget: f64) -> Vec<usize> {
    let none = steps.len();
    let mut out = vec![0; per_step.len()];
    let mut active: Vec<usize> = (0..per_step.len()).collect();
    loop {
        let full: Vec<f64> = active
            .iter()
            .map(|&i| cost_from(steps, per_step[i], 0))
            .collect();
        if full.iter().sum::<f64>() <= budget {
            for &i in &active {
                out[i] = 0;
            }
            return out;
        }
        // The share m with Σ min(full_i, m) = budget, by bisection (the sum is monotone in m).
        let (mut lo, mut hi) = (0.0, full.iter().cloned().fold(0.0, f64::max));
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if full.iter().map(|&c| c.min(m)).sum::<f64>() > budget {
                hi = m;
            } else {
                lo = m;
            }
        }
        for &i in &active {
            out[i] = (0..none)
                .find(|&j| cost_from(steps, per_step[i], j) <= lo)
                .unwrap_or(none);
        }
        let before = active.len();
        active.retain(|&i| out[i] < none);
        if active.len() == before || active.is_empty() {
            return out;
        }
    }
}

impl SweepBudget {
    /// The budget for `methods` over the grid's `steps` from their modelled seconds per
    /// step.
    pub fn new(steps: &[u64], methods: &[String], seconds: f64, per_step: &[f64]) -> Self {
        let finest = allot(steps, per_step, seconds);
        SweepBudget {
            seconds,
            methods: methods
                .iter()
                .zip(per_step)
                .zip(finest)
                .map(|((n, &s), f)| MethodBudget {
                    method: n.clone(),
                    seconds_per_step: s,
                    projected_seconds: cost_from(steps, s, 0),
                    finest: f,
                })
                .collect(),
        }
    }
    /// The entry of method `name`.
    pub fn of(&self, name: &str) -> Option<&MethodBudget> {
        self.methods.iter().find(|m| m.method == name)
    }
    /// Why `m` runs no step below its allowed one, with the figures.
    pub fn sentence(&self, m: &MethodBudget) -> String {
        format!(
            "the sweep's budget of {} s: its {} candidate steps would take about {} s at {} ms per step by the cost model; `--budget` raises it",
            sig3(self.seconds),
            m.method,
            sig3(m.projected_seconds),
            sig3(m.seconds_per_step * 1e3)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: water-filling by hand. Steps 1000, 100, 10 (costs per step-second 1110, 110,
    // 10); method A at 1 ms/step costs 1.11 s in full, B at 100 ms/step 111 s. A budget of
    // 20 s lets A keep everything (1.11 s) and leaves B 18.89 s: all of 110 steps' 11 s fits,
    // 1110 steps' 111 s does not, so B starts at index 1.
    #[test]
    fn cheap_methods_keep_all_and_the_costliest_lose_their_finest_steps() {
        let steps = [1000, 100, 10];
        assert_eq!(allot(&steps, &[1e-3, 0.1], 20.0), vec![0, 1]);
        // A budget above the total cuts nothing; one below B's coarsest run (1 s) with A
        // taking its share leaves B out entirely.
        assert_eq!(allot(&steps, &[1e-3, 0.1], 200.0), vec![0, 0]);
        assert_eq!(allot(&steps, &[1e-3, 0.1], 1.5), vec![0, 3]);
    }
}
