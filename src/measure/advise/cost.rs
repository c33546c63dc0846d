//! The cost advice ranks by: modelled seconds per simulated second ([`crate::run::cost`]: the
//! run's counted work priced per item), a unit every method shares (a Rapier method has no
//! force-evaluation count, so counting force evaluations would make it look free; its frames
//! are priced by its own model). Being counted, not clocked, it ranks the same on every re-run
//! and every machine. Force evaluations per simulated second stay beside it for the native
//! methods and break ties; the measured wall time stays beside it too, and decides nothing.
//!
//! Wall time: after every accuracy run, each candidate's chosen run is timed on one thread,
//! interleaved round-robin with the others (A, B, A, B, …, so a drift of the machine's speed
//! touches all alike), repeated under [`ADVICE_TIMING`] and summarised by the median.
//!
//! Ranking ([`rank`]): sort by modelled seconds per simulated second; the cheapest remaining
//! candidate and every other within [`TIE_BAND`] (20 %) of it form a tie group, ordered by
//! force evaluations per simulated second (a method with a count before one without: a known
//! cost before an unknown one), then by name; repeat with the rest. Why 20 %: the model's
//! per-item costs are fitted, and on the shipped scenes its figure for one method against
//! another's moves by that much against their measured ratio; within the band the model
//! cannot tell them apart, and fewer force evaluations is the sounder tie-break.
//! A modelled cost of 0 or one not finite is a failed count and an error, never the cheapest.

use crate::error::{Error, Result};
use crate::measure::case::{time_interleaved, CaseSettings, TimedRun, TimingRule, WallTimes};
use crate::method::{CostUnit, Registry};
use crate::model::{State, System};
use serde::Serialize;

/// Relative band within which two modelled costs are a tie (0.20: 20 %).
pub const TIE_BAND: f64 = 0.20;

/// Advice's timing rule for the wall times it shows: at least 5 runs and 0.05 s elapsed in total; a run whose total
/// passes 0.5 s stops once it has 3; never more than 10 000 runs.
pub const ADVICE_TIMING: TimingRule = TimingRule {
    min_repetitions: 5,
    min_total_seconds: 0.05,
    cap_seconds: 0.5,
    cap_repetitions: 3,
    max_repetitions: 10_000,
};

/// The name of the ranking measure, as written to `advice.json`.
pub const MEASURE: &str = "modelled_seconds_per_simulated_second";

/// The cost measure stated at the top of `advice.json`.
#[derive(Debug, Clone, Serialize)]
pub struct CostMeasure {
    /// What ranks candidates: [`MEASURE`].
    pub measure: &'static str,
    /// How the ranking measure is made.
    pub model: &'static str,
    /// How the wall times shown beside it were measured (kept with them, in `timing.json`).
    pub timing: WallTiming,
    /// Relative tie band.
    pub tie_band: f64,
    /// How ties are broken.
    pub tie_rule: String,
    /// The number beside the ranking measure.
    pub secondary: &'static str,
}

/// How advice's wall times were measured.
#[derive(Debug, Clone, Serialize)]
pub struct WallTiming {
    /// What the wall times are: the median over repetitions.
    pub wall_time: &'static str,
    /// Repetitions each timed run gets at least (unless its total passes `cap_seconds`).
    pub repetitions: usize,
    /// The full repetition rule.
    pub rule: TimingRule,
    /// How repetitions are scheduled.
    pub schedule: &'static str,
}

impl CostMeasure {
    /// The statement for `rule`.
    pub fn new(rule: &TimingRule) -> Self {
        CostMeasure {
            measure: MEASURE,
            model: "the run's counted work (steps, force evaluations, Newton and linear iterations, link updates, contact passes; an engine's frames priced from the scene) times fixed per-item costs: the same on every re-run",
            timing: WallTiming {
                wall_time: if rule.reuses_measured_run() {
                    "the accuracy run's own stepping wall time (one run), shown beside the ranking measure; it decides nothing"
                } else {
                    "median over repetitions, shown beside the ranking measure; it decides nothing"
                },
                repetitions: rule.min_repetitions.max(1),
                rule: *rule,
                schedule: if rule.reuses_measured_run() {
                    "no timing runs: each wall time is the runner's stepping wall time of the run that measured the error (observers off the clock), taken while other runs may share the machine"
                } else {
                    "one thread, after every accuracy run; candidates' repetitions interleaved round-robin (A, B, A, B, …); each repetition a fresh stepper, no observer, the runner's stepping wall time"
                },
            },
            tie_band: TIE_BAND,
            tie_rule: format!(
                "modelled costs within {:.0} % of the cheapest remaining candidate tie; a tie is broken by force evaluations per simulated second (a method with a count before one without), then by name",
                TIE_BAND * 100.0
            ),
            secondary: "force evaluations per simulated second (cost_per_second), null for a method without that count (Rapier methods, closed forms)",
        }
    }
}

/// Force evaluations per simulated second of `method` over `simulated` seconds, or null
/// with the reason for a method whose registered cost unit is the modelled cost only (a physics
/// engine, a closed form): it has no force-evaluation count, and 0 would read as free.
pub fn force_evals_per_second(
    registry: &Registry,
    method: &str,
    force_evals: u64,
    simulated: f64,
) -> Result<(Option<f64>, Option<String>)> {
    let info = registry.info(method)?;
    Ok(match info.cost {
        CostUnit::ForceEvaluations => (Some(force_evals as f64 / simulated), None),
        CostUnit::ModelledOnly => (
            None,
            Some(format!(
                "{} has no force-evaluation count: it never evaluates springlab's force model{}; its modelled cost stands alone",
                info.name,
                if info.engine { " (a physics engine steps its own dynamics)" } else { "" }
            )),
        ),
    })
}

/// Whether `a` and `b` are the same run for the clock: one method, as many steps, and steps
/// equal but for round-off (a frame of 1/60 s in 12 substeps and one of 1/240 s in 3 are the
/// same 1/720 s step, computed two ways): timed once, its wall time shown for both.
fn same_run(a: &TimedRun, b: &TimedRun) -> bool {
    a.method == b.method
        && a.steps == b.steps
        && a.substeps == b.substeps
        && (a.dt - b.dt).abs() <= 1e-12 * a.dt.abs().max(b.dt.abs())
}

/// The wall times of a set of runs, each timed once ([`time_once`]).
pub(super) struct Timed {
    runs: Vec<TimedRun>,
    times: Vec<WallTimes>,
}

impl Timed {
    /// The wall times of `r`, one of the runs asked for.
    pub(super) fn of(&self, r: &TimedRun) -> WallTimes {
        let k = self
            .runs
            .iter()
            .position(|x| same_run(x, r))
            .expect("every run was timed");
        self.times[k].clone()
    }
}

/// Times every run of `wanted` once ([`same_run`]), interleaved on this thread under `rule`
/// ([`time_interleaved`]); under [`crate::measure::case::MEASURED_RUN`] each run's wall time is
/// the one its accuracy run measured (given beside it, in seconds), and nothing runs again.
pub(super) fn time_once(
    sys: &System,
    s0: &State,
    wanted: &[(TimedRun, f64)],
    set: &CaseSettings,
    rule: &TimingRule,
) -> Result<Timed> {
    let mut runs: Vec<TimedRun> = Vec::new();
    let mut measured: Vec<f64> = Vec::new();
    for (r, wall) in wanted {
        if !runs.iter().any(|x| same_run(x, r)) {
            runs.push(r.clone());
            measured.push(*wall);
        }
    }
    let times = if rule.reuses_measured_run() {
        measured.iter().map(|&w| WallTimes::of(&[w])).collect()
    } else {
        time_interleaved(sys, s0, &runs, set, rule)?
    };
    Ok(Timed { runs, times })
}

/// What [`rank`] compares for one candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct CostKey {
    /// Method name.
    pub method: String,
    /// Modelled seconds per simulated second (s/s).
    pub modelled_per_second: f64,
    /// Force evaluations per simulated second (None: no count).
    pub force_evals_per_second: Option<f64>,
}

/// Which rule put the first candidate first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PickedBy {
    /// The only candidate.
    Only,
    /// The lowest modelled seconds per simulated second, outside any tie.
    ModelledCost,
    /// A modelled-cost tie, broken by force evaluations per simulated second.
    TieForceEvaluations,
    /// A modelled-cost tie with equal force evaluations, broken by name.
    TieName,
}

impl PickedBy {
    /// A phrase for the CLI.
    pub fn describe(self) -> String {
        let band = TIE_BAND * 100.0;
        match self {
            PickedBy::Only => "the only candidate meeting the tolerance".into(),
            PickedBy::ModelledCost => "lowest modelled seconds per simulated second".into(),
            PickedBy::TieForceEvaluations => format!(
                "modelled seconds per simulated second tied within {band:.0} %, broken by force evaluations"
            ),
            PickedBy::TieName => format!(
                "modelled seconds per simulated second tied within {band:.0} % with equal force evaluations, broken by name"
            ),
        }
    }
}

fn tie_order(a: &CostKey, b: &CostKey) -> std::cmp::Ordering {
    use std::cmp::Ordering::*;
    let by_evals = match (a.force_evals_per_second, b.force_evals_per_second) {
        (Some(x), Some(y)) => x.total_cmp(&y),
        (Some(_), None) => Less,
        (None, Some(_)) => Greater,
        (None, None) => Equal,
    };
    by_evals.then_with(|| a.method.cmp(&b.method))
}

/// Orders `keys` cheapest first (indices into `keys`) by the rule in the module docs, and says
/// which rule decided the first place (None when `keys` is empty). `scenario` names the scene
/// in the error for a modelled cost that is 0 or not finite.
pub fn rank(keys: &[CostKey], scenario: &str) -> Result<(Vec<usize>, Option<PickedBy>)> {
    if let Some(k) = keys
        .iter()
        .find(|k| !(k.modelled_per_second.is_finite() && k.modelled_per_second > 0.0))
    {
        return Err(Error::Unsupported {
            method: k.method.clone(),
            scenario: scenario.to_string(),
            reason: format!(
                "modelled seconds per simulated second is {}: a failed count, not a cost (no method is free)",
                k.modelled_per_second
            ),
        });
    }
    let mut rest: Vec<usize> = (0..keys.len()).collect();
    rest.sort_by(|&a, &b| {
        keys[a]
            .modelled_per_second
            .total_cmp(&keys[b].modelled_per_second)
            .then_with(|| keys[a].method.cmp(&keys[b].method))
    });
    let mut order = Vec::with_capacity(keys.len());
    let mut picked_by = None;
    while let Some(&lead) = rest.first() {
        let limit = keys[lead].modelled_per_second * (1.0 + TIE_BAND);
        let (mut group, others): (Vec<usize>, Vec<usize>) = rest
            .iter()
            .partition(|&&i| keys[i].modelled_per_second <= limit);
        group.sort_by(|&a, &b| tie_order(&keys[a], &keys[b]));
        if picked_by.is_none() {
            picked_by = Some(if keys.len() == 1 {
                PickedBy::Only
            } else if group.len() == 1 {
                PickedBy::ModelledCost
            } else {
                let (a, b) = (&keys[group[0]], &keys[group[1]]);
                let evals_differ = match (a.force_evals_per_second, b.force_evals_per_second) {
                    (Some(x), Some(y)) => x != y,
                    (None, None) => false,
                    _ => true,
                };
                if evals_differ {
                    PickedBy::TieForceEvaluations
                } else {
                    PickedBy::TieName
                }
            });
        }
        order.extend(group);
        rest = others;
    }
    Ok((order, picked_by))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(name: &str, cost: f64, evals: Option<f64>) -> CostKey {
        CostKey {
            method: name.into(),
            modelled_per_second: cost,
            force_evals_per_second: evals,
        }
    }

    fn names(keys: &[CostKey]) -> Vec<String> {
        let (order, _) = rank(keys, "test").unwrap();
        order.iter().map(|&i| keys[i].method.clone()).collect()
    }

    // Oracle: the rule as stated in the module docs, applied by hand to each input.

    #[test]
    fn clear_cost_differences_decide_whatever_the_force_evaluations() {
        // Rapier has no count and is 300× slower: it is last, not free.
        let keys = [
            key("rapier_impulse", 3e-1, None),
            key("rk4", 4e-3, Some(4000.0)),
            key("velocity_verlet", 1e-3, Some(1000.0)),
        ];
        assert_eq!(names(&keys), ["velocity_verlet", "rk4", "rapier_impulse"]);
        assert_eq!(rank(&keys, "t").unwrap().1, Some(PickedBy::ModelledCost));
    }

    #[test]
    fn ties_within_the_band_go_to_fewer_force_evaluations_then_to_the_name() {
        assert_eq!(TIE_BAND, 0.20, "the cases below are worked for a 20 % band");
        // b is 10 % slower than a (a tie) but needs half the force evaluations: b first.
        let keys = [
            key("a", 1.00e-3, Some(2000.0)),
            key("b", 1.10e-3, Some(1000.0)),
        ];
        assert_eq!(names(&keys), ["b", "a"]);
        assert_eq!(
            rank(&keys, "t").unwrap().1,
            Some(PickedBy::TieForceEvaluations)
        );
        // Equal force evaluations: the name decides, whichever median is lower.
        let keys = [
            key("zeta", 1.00e-3, Some(1000.0)),
            key("alpha", 1.15e-3, Some(1000.0)),
        ];
        assert_eq!(names(&keys), ["alpha", "zeta"]);
        assert_eq!(rank(&keys, "t").unwrap().1, Some(PickedBy::TieName));
        // A method with a count goes before a tied one without.
        let keys = [
            key("rapier_impulse", 1.00e-3, None),
            key("velocity_verlet", 1.19e-3, Some(1000.0)),
        ];
        assert_eq!(names(&keys), ["velocity_verlet", "rapier_impulse"]);
        // Outside the band (21 % dearer) the modelled cost decides.
        let keys = [
            key("a", 1.00e-3, Some(2000.0)),
            key("b", 1.21e-3, Some(1000.0)),
        ];
        assert_eq!(names(&keys), ["a", "b"]);
    }

    #[test]
    fn groups_are_formed_from_the_cheapest_remaining_candidate() {
        // a and b tie (b within 20 % of a); c is within 20 % of b but not of a, so it starts
        // the next group, with d (within 20 % of c).
        let keys = [
            key("d", 1.50e-3, Some(1.0)),
            key("c", 1.30e-3, Some(9.0)),
            key("b", 1.15e-3, Some(1.0)),
            key("a", 1.00e-3, Some(5.0)),
        ];
        assert_eq!(names(&keys), ["b", "a", "d", "c"]);
    }

    #[test]
    fn zero_or_non_finite_cost_is_refused() {
        for bad in [0.0, -1e-9, f64::NAN, f64::INFINITY] {
            let keys = [
                key("velocity_verlet", 1e-3, Some(1000.0)),
                key("rapier_multibody", bad, None),
            ];
            let e = rank(&keys, "free_fall").unwrap_err().to_string();
            assert!(
                e.contains("rapier_multibody") && e.contains("free_fall") && e.contains("free"),
                "{e}"
            );
        }
    }

    #[test]
    fn empty_and_single() {
        assert_eq!(rank(&[], "t").unwrap(), (vec![], None));
        let keys = [key("rk4", 1e-3, Some(4.0))];
        assert_eq!(rank(&keys, "t").unwrap(), (vec![0], Some(PickedBy::Only)));
    }

    #[test]
    fn rapier_has_no_force_count_and_natives_do() {
        let reg = Registry::builtin();
        let (v, why) = force_evals_per_second(&reg, "rapier_impulse", 0, 2.0).unwrap();
        assert!(v.is_none() && why.is_some_and(|w| w.contains("rapier_impulse")));
        let (v, why) = force_evals_per_second(&reg, "velocity_verlet", 400, 2.0).unwrap();
        assert_eq!((v, why), (Some(200.0), None));
        assert!(force_evals_per_second(&reg, "no_such_method", 1, 1.0).is_err());
    }
}
