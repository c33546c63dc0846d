//! One measured case: a method at one step over a horizon, against a reference.

use crate::error::Result;
use crate::measure::contacts::{ContactMetrics, ContactReport};
use crate::measure::grid::TimeGrid;
use crate::measure::metrics::{Metrics, MetricsObserver, Series};
use crate::measure::reference::Reference;
use crate::measure::trace::{Trace, TraceObserver, TraceSpec};
use crate::method::MethodOptions;
use crate::method::Registry;
use crate::model::{State, System};
use crate::run::{run, NoObserver, RunPlan, RunStatus, Status};
use serde::Serialize;

/// Runs shorter than this (stepping wall time, s) are repeated and the median kept.
pub const SHORT_RUN_SECONDS: f64 = 0.05;
/// Repetitions of a short run (including the measured one).
pub const SHORT_RUN_REPEATS: usize = 5;

/// When to stop repeating a timed run: once it has `min_repetitions` runs and
/// `min_total_seconds` of elapsed time, or once its elapsed time reaches `cap_seconds` with
/// at least `cap_repetitions` runs, or at `max_repetitions` runs, whichever comes first.
/// Elapsed time counts each repetition whole (stepper set-up included), so the rule bounds
/// what the timing costs; the sample kept is the stepping wall time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TimingRule {
    /// Repetitions wanted (≥ 1).
    pub min_repetitions: usize,
    /// Elapsed time wanted in total (s).
    pub min_total_seconds: f64,
    /// A run whose elapsed time reaches this total (s) stops early ...
    pub cap_seconds: f64,
    /// ... once it has at least this many repetitions.
    pub cap_repetitions: usize,
    /// Hard limit on repetitions.
    pub max_repetitions: usize,
}

/// The rule that times nothing again: each wall time shown is the measured run's own stepping
/// time (one run; its observers and metrics stay off the clock, as in [`time_interleaved`]).
/// A study uses it: its wall times decide nothing, and every run it shows has already run once.
pub const MEASURED_RUN: TimingRule = TimingRule {
    min_repetitions: 0,
    min_total_seconds: 0.0,
    cap_seconds: 0.0,
    cap_repetitions: 0,
    max_repetitions: 0,
};

impl TimingRule {
    /// True for [`MEASURED_RUN`]: no dedicated timing runs, the measured run's own time.
    pub fn reuses_measured_run(&self) -> bool {
        self.max_repetitions == 0
    }

    /// True when `reps` runs that took `total` seconds in all are enough.
    pub fn satisfied(&self, reps: usize, total: f64) -> bool {
        (reps >= self.min_repetitions && total >= self.min_total_seconds)
            || (reps >= self.cap_repetitions && total >= self.cap_seconds)
            || reps >= self.max_repetitions
    }
}

/// The rule of [`run_case`] for short runs: [`SHORT_RUN_REPEATS`] runs, no minimum time (a
/// sweep times hundreds of cases; its wall times are a side note, advice times its own).
pub const SHORT_RUN_RULE: TimingRule = TimingRule {
    min_repetitions: SHORT_RUN_REPEATS,
    min_total_seconds: 0.0,
    cap_seconds: f64::INFINITY,
    cap_repetitions: SHORT_RUN_REPEATS,
    max_repetitions: SHORT_RUN_REPEATS,
};

/// Repeated wall-time measurements of one run, summarised.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WallTimes {
    /// Runs timed.
    pub repetitions: usize,
    /// Median stepping wall time of one run (s): the kept statistic.
    pub median_seconds: f64,
    /// Fastest run (s).
    pub min_seconds: f64,
    /// Slowest run (s).
    pub max_seconds: f64,
    /// (max − min) / median: how much the runs disagreed.
    pub spread: f64,
}

impl WallTimes {
    /// Summarises `samples` (wall seconds of each run; not empty). The median of an even count
    /// is the mean of the two middle values.
    pub fn of(samples: &[f64]) -> WallTimes {
        assert!(
            !samples.is_empty(),
            "WallTimes::of needs at least one sample"
        );
        let mut v = samples.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        let (lo, hi) = (v[0], v[n - 1]);
        WallTimes {
            repetitions: n,
            median_seconds: median,
            min_seconds: lo,
            max_seconds: hi,
            spread: if median > 0.0 {
                (hi - lo) / median
            } else {
                f64::INFINITY
            },
        }
    }
}

/// One run to time: a method at a step for a number of steps.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedRun {
    /// Method name.
    pub method: String,
    /// Step (s): the frame step when `substeps` is set.
    pub dt: f64,
    /// Steps (frames).
    pub steps: u64,
    /// Substeps per frame for every method ([`CaseSettings::substeps`]); `None`: one step
    /// per frame for native methods, the options' substeps for engines.
    pub substeps: Option<u64>,
}

/// The run plan and method options of `steps` frames of `dt` with `substeps` per frame
/// (see [`CaseSettings::substeps`]): one place decides what a frame's substeps mean.
pub fn frame_setup(
    set: &CaseSettings,
    dt: f64,
    steps: u64,
    substeps: Option<u64>,
) -> (RunPlan, MethodOptions) {
    let plan = RunPlan {
        dt,
        steps,
        substeps: substeps.unwrap_or(1).max(1),
        blowup_factor: set.blowup_factor,
        stop_at_verdict: true,
    };
    let mut options = set.options.clone();
    if let Some(n) = substeps {
        options.substeps = n.max(1) as usize;
    }
    (plan, options)
}

/// Times every run in `runs` on this thread, interleaved round-robin (A, B, C, A, B, C, …)
/// so that a drift of the machine's speed touches all of them alike; a run leaves the rotation
/// once `rule` is satisfied. Each repetition uses a fresh stepper and no observer; the time
/// is the runner's stepping wall time. Returns one [`WallTimes`] per run, in input order.
/// [`MEASURED_RUN`] repeats nothing, so it is refused here: its callers take the accuracy
/// runs' own times instead.
pub fn time_interleaved(
    sys: &System,
    s0: &State,
    runs: &[TimedRun],
    set: &CaseSettings,
    rule: &TimingRule,
) -> Result<Vec<WallTimes>> {
    if rule.reuses_measured_run() {
        return Err(crate::error::Error::option(
            "timing",
            "MEASURED_RUN times no run again: take the accuracy run's own wall time".to_string(),
        ));
    }
    let mut samples: Vec<Vec<f64>> = vec![Vec::new(); runs.len()];
    let mut totals = vec![0.0; runs.len()];
    loop {
        let mut any = false;
        for (i, r) in runs.iter().enumerate() {
            if !samples[i].is_empty() && rule.satisfied(samples[i].len(), totals[i]) {
                continue;
            }
            any = true;
            let started = std::time::Instant::now();
            let (plan, options) = frame_setup(set, r.dt, r.steps, r.substeps);
            let mut stepper = set.registry.create(&r.method, &options)?;
            let o = run(sys, &mut stepper, s0.clone(), &plan, &mut NoObserver)?;
            samples[i].push(o.wall_seconds);
            totals[i] += started.elapsed().as_secs_f64();
        }
        if !any {
            break;
        }
    }
    Ok(samples.iter().map(|s| WallTimes::of(s)).collect())
}

/// The outcome of one case: cost, status and metrics.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    /// Canonical method name.
    pub method: String,
    /// Step (s).
    pub dt: f64,
    /// Steps planned.
    pub steps: u64,
    /// Steps completed.
    pub steps_done: u64,
    /// Force evaluations.
    pub force_evals: u64,
    /// Stepping wall time (s); for a short run the median of [`SHORT_RUN_RULE`]'s repetitions.
    pub wall_seconds: f64,
    /// The work the run counted.
    pub work: crate::run::Work,
    /// Modelled cost of that work (s, [`crate::run::CostModel`]): what decides on cost.
    pub modelled_seconds: f64,
    /// `ok` or `unstable`.
    pub status: RunStatus,
    /// Time of the blow-up (s), for unstable runs.
    pub unstable_time: Option<f64>,
    /// Which measure tripped, for unstable runs.
    pub unstable_reason: Option<String>,
    /// Accuracy metrics of the whole run; `None` (null) for a run that is not ok: an unstable
    /// run has no accuracy to report, and a stopped one did not cover its horizon.
    pub metrics: Option<Metrics>,
    /// Decimated series, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub series: Option<Series>,
    /// Paths and snapshots, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trace: Option<Trace>,
    /// Collision metrics, for scenes with obstacles (also written as `contacts.json`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<ContactReport>,
}

impl CaseResult {
    /// True when the run finished every step and was judged stable.
    pub fn ok(&self) -> bool {
        self.status.is_ok()
    }
    /// One metric of an ok run (`None` for a run that is not ok: no number where there is none).
    pub fn metric(&self, f: impl Fn(&Metrics) -> f64) -> Option<f64> {
        self.metrics.as_ref().map(f)
    }
}

/// How to run one case.
#[derive(Debug, Clone)]
pub struct CaseSettings {
    /// The methods cases are run with (built-ins unless a library user added theirs).
    pub registry: Registry,
    /// Method options.
    pub options: MethodOptions,
    /// Blow-up factor of the runner.
    pub blowup_factor: f64,
    /// Series points (0: none).
    pub series_points: u64,
    /// Repeat short runs to time them ([`SHORT_RUN_RULE`], median kept).
    pub repeat_short: bool,
    /// Record paths and snapshots.
    pub trace: Option<TraceSpec>,
    /// Measure collision metrics on scenes with obstacles (compare's `contacts.json`; sweeps
    /// and advice leave them off: they would pay the per-step obstacle queries for nothing).
    pub contacts: bool,
    /// Substeps per frame (a grid step is a frame) for every method: native methods take
    /// that many equal steps per frame, engines that many solver substeps. `None`: one step
    /// per frame for native methods, `options.substeps` for engines.
    pub substeps: Option<u64>,
    /// End a run early once it can no longer pass (`(divisor, bound)` of
    /// [`crate::measure::tolerance::Judge::position_stop`]): a search that needs only whether a run
    /// passes does not compute the rest of one that has failed. A run ended so has no metrics
    /// (it shows no number) and its `steps_done` says where it stopped. `None`: every run whole.
    pub stop: Option<(f64, f64)>,
}

impl Default for CaseSettings {
    fn default() -> Self {
        CaseSettings {
            registry: Registry::builtin(),
            options: MethodOptions::default(),
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
            series_points: 0,
            repeat_short: true,
            trace: None,
            contacts: false,
            substeps: None,
            stop: None,
        }
    }
}

impl CaseSettings {
    /// The settings of a measuring command's runs with these methods: no series, no repeats
    /// (the command times its chosen runs itself), no trace, no collision metrics, one step
    /// per frame, every run whole. Commands change the fields they measure differently.
    pub fn measuring(registry: Registry, options: MethodOptions, blowup_factor: f64) -> Self {
        CaseSettings {
            registry,
            options,
            blowup_factor,
            series_points: 0,
            repeat_short: false,
            trace: None,
            contacts: false,
            substeps: None,
            stop: None,
        }
    }
}

/// Runs `name` on grid `grid` of `reference` (the grid's dt and steps), ended early under
/// [`CaseSettings::stop`].
pub fn run_case(
    sys: &System,
    s0: &State,
    reference: &Reference,
    grid: usize,
    name: &str,
    set: &CaseSettings,
) -> Result<CaseResult> {
    let g: TimeGrid = reference.grids[grid];
    let (plan, options) = frame_setup(set, g.dt, g.steps, set.substeps);
    let mut stepper = set.registry.create(name, &options)?;
    let mut obs = MetricsObserver::new(sys, s0, reference, grid, set.series_points);
    if let Some(st) = set.stop {
        obs = obs.stop_past(st);
    }
    let mut trace = set.trace.as_ref().map(|t| TraceObserver::new(t, g.dt));
    let mut contacts = set
        .contacts
        .then(|| ContactMetrics::new(sys, g.dt))
        .flatten();
    let out = run(
        sys,
        &mut stepper,
        s0.clone(),
        &plan,
        &mut (&mut obs, (&mut trace, &mut contacts)),
    )?;
    let mut wall = out.wall_seconds;
    if set.repeat_short && out.wall_seconds < SHORT_RUN_SECONDS {
        let mut samples = vec![out.wall_seconds];
        while !SHORT_RUN_RULE.satisfied(samples.len(), samples.iter().sum()) {
            let mut again = set.registry.create(name, &options)?;
            let o = run(sys, &mut again, s0.clone(), &plan, &mut NoObserver)?;
            samples.push(o.wall_seconds);
        }
        wall = WallTimes::of(&samples).median_seconds;
    }
    let contacts = contacts.map(|c| c.report());
    let stopped = crate::run::Observer::seen_enough(&obs) && out.steps_done < g.steps;
    let (unstable_time, unstable_reason) = match &out.status {
        Status::Ok => (None, None),
        Status::Unstable { time, reason, .. } => (Some(*time), Some(reason.clone())),
    };
    Ok(CaseResult {
        method: stepper.name().to_string(),
        dt: g.dt,
        steps: g.steps,
        steps_done: out.steps_done,
        force_evals: out.force_evals,
        wall_seconds: wall,
        work: out.work,
        modelled_seconds: out.modelled_seconds,
        status: out.status.kind(),
        unstable_time,
        unstable_reason,
        metrics: (out.status.is_ok() && !stopped).then(|| Metrics {
            penetration_max: contacts.as_ref().map(ContactReport::penetration_max),
            ..obs.metrics()
        }),
        series: (set.series_points > 0).then(|| obs.series.clone()),
        trace: trace.map(|t| t.trace),
        contacts,
    })
}

/// The methods asked for, or every registered one when none was named: what a measuring
/// command runs, and what its `"command"` names.
pub fn asked_or_all(registry: &Registry, asked: &[String]) -> Vec<String> {
    if asked.is_empty() {
        registry.names().into_iter().map(String::from).collect()
    } else {
        asked.to_vec()
    }
}

/// The methods of `methods` that apply to `sys`: `asked` (or, when empty, every registered
/// method), canonical names split into (applicable, skipped with the reason).
#[allow(clippy::type_complexity)]
pub fn applicable(
    registry: &Registry,
    sys: &System,
    asked: &[String],
    opts: &MethodOptions,
) -> Result<(Vec<String>, Vec<(String, String)>)> {
    let (mut ok, mut skipped) = (Vec::new(), Vec::new());
    for n in asked_or_all(registry, asked) {
        let stepper = registry.create(&n, opts)?;
        let canon = stepper.name().to_string();
        if ok.contains(&canon) || skipped.iter().any(|(s, _)| *s == canon) {
            continue;
        }
        match stepper.check(sys) {
            Ok(()) => ok.push(canon),
            Err(why) => skipped.push((canon, why)),
        }
    }
    Ok((ok, skipped))
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the median's definition (middle value; mean of the two middle values for an
    // even count), worked by hand.
    #[test]
    fn timing_keeps_the_median_not_the_minimum() {
        let t = WallTimes::of(&[3.0, 1.0, 2.0, 10.0, 2.5]);
        assert_eq!(t.median_seconds, 2.5);
        assert_eq!(
            (t.min_seconds, t.max_seconds, t.repetitions),
            (1.0, 10.0, 5)
        );
        assert_eq!(t.spread, 9.0 / 2.5);
        assert_eq!(WallTimes::of(&[4.0, 1.0, 2.0, 3.0]).median_seconds, 2.5);
    }

    #[test]
    fn the_rule_wants_both_repetitions_and_time_unless_capped() {
        let r = crate::measure::advise::ADVICE_TIMING;
        assert!(!r.satisfied(4, 1e-3));
        assert!(!r.satisfied(5, 0.049));
        assert!(r.satisfied(5, 0.05));
        assert!(!r.satisfied(2, 0.6));
        assert!(r.satisfied(3, 0.6));
        assert!(r.satisfied(10_000, 0.0));
        assert!(SHORT_RUN_RULE.satisfied(5, 0.0) && !SHORT_RUN_RULE.satisfied(4, 0.0));
    }
}
