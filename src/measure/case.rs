//! One measured case: an integrator at one step over a horizon, against a reference.

use super::contacts::{ContactMetrics, ContactReport};
use super::grid::TimeGrid;
use super::metrics::{Metrics, MetricsObserver, Series};
use super::reference::Reference;
use super::trace::{Trace, TraceObserver, TraceSpec};
use crate::error::Result;
use crate::integrate::IntegratorOptions;
use crate::method::Registry;
use crate::model::{State, System};
use crate::run::{run, NoObserver, RunPlan, Status};
use serde::Serialize;

/// Runs shorter than this (integrator wall time, s) are repeated and the minimum kept.
pub const SHORT_RUN_SECONDS: f64 = 0.05;
/// Repetitions of a short run (including the measured one).
pub const SHORT_RUN_REPEATS: usize = 5;

/// The outcome of one case: cost, status and metrics.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    /// Canonical integrator or backend name.
    pub integrator: String,
    /// Step (s).
    pub dt: f64,
    /// Steps planned.
    pub steps: u64,
    /// Steps completed.
    pub steps_done: u64,
    /// Force evaluations.
    pub force_evals: u64,
    /// Integrator wall time (s), the minimum over repetitions for short runs.
    pub wall_seconds: f64,
    /// `ok` or `unstable`.
    pub status: String,
    /// Time of the blow-up (s), for unstable runs.
    pub unstable_time: Option<f64>,
    /// Which measure tripped, for unstable runs.
    pub unstable_reason: Option<String>,
    /// Metrics over the accepted steps.
    pub metrics: Metrics,
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
    /// True when the run finished every step.
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }
}

/// How to run one case.
#[derive(Debug, Clone)]
pub struct CaseSettings {
    /// The methods cases are run with (built-ins unless a library user added theirs).
    pub methods: Registry,
    /// Integrator options.
    pub options: IntegratorOptions,
    /// Blow-up factor of the runner.
    pub blowup_factor: f64,
    /// Series points (0: none).
    pub series_points: u64,
    /// Repeat short runs to time them.
    pub repeat_short: bool,
    /// Record paths and snapshots.
    pub trace: Option<TraceSpec>,
}

impl Default for CaseSettings {
    fn default() -> Self {
        CaseSettings {
            methods: Registry::builtin(),
            options: IntegratorOptions::default(),
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
            series_points: 0,
            repeat_short: true,
            trace: None,
        }
    }
}

/// Runs `name` on grid `grid` of `reference` (the grid's dt and steps).
pub fn run_case(
    sys: &System,
    s0: &State,
    reference: &Reference,
    grid: usize,
    name: &str,
    set: &CaseSettings,
) -> Result<CaseResult> {
    let g: TimeGrid = reference.grids[grid];
    let mut integ = set.methods.create(name, &set.options)?;
    let plan = RunPlan {
        dt: g.dt,
        steps: g.steps,
        blowup_factor: set.blowup_factor,
    };
    let mut obs = MetricsObserver::new(sys, s0, reference, grid, set.series_points);
    let mut trace = set.trace.as_ref().map(|t| TraceObserver::new(t, g.dt));
    let mut contacts = ContactMetrics::new(sys, g.dt);
    let out = run(
        sys,
        integ.as_mut(),
        s0.clone(),
        &plan,
        &mut (&mut obs, (&mut trace, &mut contacts)),
    )?;
    let mut wall = out.wall_seconds;
    if set.repeat_short && out.wall_seconds < SHORT_RUN_SECONDS {
        for _ in 1..SHORT_RUN_REPEATS {
            let mut again = set.methods.create(name, &set.options)?;
            let o = run(sys, again.as_mut(), s0.clone(), &plan, &mut NoObserver)?;
            wall = wall.min(o.wall_seconds);
        }
    }
    let (unstable_time, unstable_reason) = match &out.status {
        Status::Ok => (None, None),
        Status::Unstable { time, reason, .. } => (Some(*time), Some(reason.clone())),
    };
    Ok(CaseResult {
        integrator: integ.name().to_string(),
        dt: g.dt,
        steps: g.steps,
        steps_done: out.steps_done,
        force_evals: out.force_evals,
        wall_seconds: wall,
        status: out.status.label().to_string(),
        unstable_time,
        unstable_reason,
        metrics: obs.metrics(),
        series: (set.series_points > 0).then(|| obs.series.clone()),
        trace: trace.map(|t| t.trace),
        contacts: contacts.map(|c| c.report()),
    })
}

/// The methods of `methods` that apply to `sys`: `asked` (or, when empty, every registered
/// method), canonical names split into (applicable, skipped with the reason).
#[allow(clippy::type_complexity)]
pub fn applicable(
    methods: &Registry,
    sys: &System,
    asked: &[String],
    opts: &IntegratorOptions,
) -> Result<(Vec<String>, Vec<(String, String)>)> {
    let names: Vec<String> = if asked.is_empty() {
        methods.names().into_iter().map(String::from).collect()
    } else {
        asked.to_vec()
    };
    let (mut ok, mut skipped) = (Vec::new(), Vec::new());
    for n in names {
        let integ = methods.create(&n, opts)?;
        let canon = integ.name().to_string();
        if ok.contains(&canon) || skipped.iter().any(|(s, _)| *s == canon) {
            continue;
        }
        match integ.check(sys) {
            Ok(()) => ok.push(canon),
            Err(why) => skipped.push((canon, why)),
        }
    }
    Ok((ok, skipped))
}
