//! The sweep's plan: the step grid (from the scene's dynamics unless the user fixes it), the
//! extension candidates below it, the cost cap and the methods.

use super::config::SweepConfig;
use crate::error::{Error, Result};
use crate::measure::grid::{max_samples_for, TimeGrid};
use crate::measure::modes::modes;
use crate::measure::stability::theory_limit;
use crate::scenario::Scenario;
use serde::{Deserialize, Serialize};

/// Default cost cap: particle-steps (steps × particles, summed over a method's runs) per
/// method.
pub const DEFAULT_COST_CAP: f64 = 4e6;
/// The default grid's largest step is this multiple of the widest theoretical stability
/// limit, so the sweep shows where each method blows up.
pub const BEYOND_LIMIT: f64 = 1.25;
/// The default grid's largest hω_max when no method has a finite linear stability limit.
pub const H_OMEGA_MAX: f64 = 3.0;
/// The default grid's smallest hω_max (before extension): the fastest mode resolved with
/// about 125 steps per period, where a first-order method's relative error per period is
/// about π·hω ≈ 15 % and a second-order one's about 1 %.
pub const H_OMEGA_MIN: f64 = 0.05;
/// The default grid's largest step never exceeds this fraction of the horizon.
pub const MAX_STEP_FRACTION: f64 = 0.25;
/// Fewest points of the default base grid.
pub const MIN_BASE_POINTS: usize = 6;
/// Most points of the default base grid.
pub const MAX_BASE_POINTS: usize = 14;
/// Most extension candidates (halvings below the base grid).
pub const MAX_EXTENSION: usize = 24;

/// How the step grid was chosen, for the summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridRule {
    /// Highest linearised natural frequency (rad/s), 0 without stiffness.
    pub omega_max: f64,
    /// Widest finite theoretical stability limit among the swept methods (s), if any.
    pub widest_stability_limit: Option<f64>,
    /// Largest step of the base grid (s) and why.
    pub dt_max: f64,
    /// Where `dt_max` comes from.
    pub dt_max_source: String,
    /// Smallest step of the base grid (s).
    pub dt_min: f64,
    /// Where `dt_min` comes from.
    pub dt_min_source: String,
    /// True when methods extend toward smaller steps until asymptotic, at the floor or capped.
    pub extend: bool,
    /// Cost cap per method: particle-steps summed over its runs.
    pub cost_cap_particle_steps: f64,
}

/// Everything that defines a sweep's cases; shards of one sweep share it exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepPlan {
    /// The command that re-creates the sweep (shards add `--shard`, writers `--out`).
    pub command: String,
    /// Scenario name.
    pub scenario: String,
    /// Simulated time (s).
    pub duration: f64,
    /// Every step a method may run (s), ascending, each dividing the duration into whole
    /// steps: the extension candidates (`dts[..base_from]`) then the base grid.
    pub dts: Vec<f64>,
    /// Steps per grid point.
    pub steps: Vec<u64>,
    /// Compare every stride-th step per grid point.
    pub strides: Vec<u64>,
    /// Index in `dts` of the base grid's smallest step: every method runs `dts[base_from..]`.
    pub base_from: usize,
    /// Particles of the scene (the cost cap counts steps × particles).
    pub particles: usize,
    /// How the grid was chosen, with the extension switch and the cost cap.
    pub rule: GridRule,
    /// Applicable methods, in case order.
    pub methods: Vec<String>,
    /// Their theoretical orders from the registry (None: exact, or an engine).
    pub orders: Vec<Option<u32>>,
    /// Methods skipped (name, reason).
    pub skipped: Vec<(String, String)>,
    /// Blow-up factor.
    pub blowup_factor: f64,
    /// Every method option's value, by flag (`iterations`, `xpbd-substeps`, ...).
    pub options: std::collections::BTreeMap<String, crate::method::options::OptionValue>,
    /// Substeps of engine methods.
    pub substeps: usize,
    /// The time budget and what it allowed each method, when one was set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<super::budget::SweepBudget>,
}

impl SweepPlan {
    /// Index in `dts` of the smallest step method `name` may run (the budget's; else 0).
    pub fn finest(&self, name: &str) -> usize {
        self.budget
            .as_ref()
            .and_then(|b| b.of(name))
            .map_or(0, |m| m.finest)
    }
    /// Index in `dts` of the smallest base-grid step method `name` runs.
    pub fn base_start(&self, name: &str) -> usize {
        self.base_from.max(self.finest(name))
    }
    /// Number of possible cases (methods × candidate steps); case k is method
    /// k / dts.len() at step k mod dts.len().
    pub fn case_count(&self) -> usize {
        self.methods.len() * self.dts.len()
    }
    /// The output grid of step `j`.
    pub fn grid(&self, j: usize) -> TimeGrid {
        TimeGrid {
            dt: self.dts[j],
            steps: self.steps[j],
            stride: self.strides[j],
        }
    }
    /// Particle-steps of one run at step `j`.
    pub fn cost(&self, j: usize) -> f64 {
        self.steps[j] as f64 * self.particles as f64
    }
}

/// Builds the step grid: `points` log-spaced steps in [dt_min, dt_max], each adjusted so a
/// whole number of steps spans `duration`; duplicates dropped.
pub fn step_grid(dt_min: f64, dt_max: f64, points: usize, duration: f64) -> Vec<(f64, u64)> {
    let mut out: Vec<(f64, u64)> = Vec::new();
    for k in 0..points {
        let f = if points > 1 {
            k as f64 / (points - 1) as f64
        } else {
            0.0
        };
        let dt = dt_min * (dt_max / dt_min).powf(f);
        let steps = crate::model::whole_steps(duration, dt);
        if out.last().is_none_or(|&(_, s)| s != steps) && !out.iter().any(|&(_, s)| s == steps) {
            out.push((duration / steps as f64, steps));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

fn positive(name: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::option(
            name,
            format!("must be a finite number > 0, got {}", crate::error::num(v)),
        ))
    }
}

/// The default base grid's bounds from the scene's dynamics (see the module doc of
/// [`super`]): (dt_max, its source, dt_min, its source, ω_max, widest limit).
fn dynamic_bounds(
    scene: &Scenario,
    names: &[String],
    cfg: &SweepConfig,
    duration: f64,
) -> (f64, String, f64, String, f64, Option<f64>) {
    let sys = scene.build();
    let ms = modes(&sys, &scene.initial_state());
    let w = ms.omega_max;
    let widest = if ms.modes.is_empty() {
        None
    } else {
        names
            .iter()
            .filter_map(|n| cfg.common.registry.get(n).ok())
            .filter(|m| m.info.linear_theory())
            .filter_map(|m| theory_limit(m, &cfg.common.options, &ms).1)
            .fold(None, |a: Option<f64>, h| Some(a.map_or(h, |a| a.max(h))))
    };
    let cap = MAX_STEP_FRACTION * duration;
    let (mut hi, mut hi_src) = match (widest, w > 0.0) {
        (Some(h), _) => (
            BEYOND_LIMIT * h,
            format!(
                "{BEYOND_LIMIT} × the widest theoretical stability limit {} s",
                crate::error::significant(h, 5)
            ),
        ),
        (None, true) => (
            H_OMEGA_MAX / w,
            format!("hω_max = {H_OMEGA_MAX} (no finite linear stability limit)"),
        ),
        (None, false) => (
            cap,
            format!(
                "{MAX_STEP_FRACTION} × the horizon (no stiffness: no time scale from the modes)"
            ),
        ),
    };
    if hi > cap {
        hi = cap;
        hi_src = format!("{MAX_STEP_FRACTION} × the horizon");
    }
    let halvings = |lo: f64| (hi / lo).log2().ceil().max(0.0) as usize;
    let (mut lo, mut lo_src) = if w > 0.0 {
        (H_OMEGA_MIN / w, format!("hω_max = {H_OMEGA_MIN}"))
    } else {
        (0.0, String::new())
    };
    if w <= 0.0 || halvings(lo) + 1 < MIN_BASE_POINTS {
        lo = hi / 2f64.powi(MIN_BASE_POINTS as i32 - 1);
        lo_src = format!("{MIN_BASE_POINTS} halving-spaced points below dt_max");
    } else if halvings(lo) + 1 > MAX_BASE_POINTS {
        lo = hi / 2f64.powi(MAX_BASE_POINTS as i32 - 1);
        lo_src = format!("{MAX_BASE_POINTS} halving-spaced points below dt_max (hω_max = {H_OMEGA_MIN} is further)");
    }
    (hi, hi_src, lo, lo_src, w, widest)
}

/// Resolves the configuration against the scene into a [`SweepPlan`].
pub fn plan_sweep(scene: &Scenario, cfg: &SweepConfig) -> Result<SweepPlan> {
    let mut plan = plan_grid(scene, cfg)?;
    plan.orders = plan
        .methods
        .iter()
        .map(|n| {
            cfg.common
                .registry
                .info(n)
                .ok()
                .filter(|m| !m.engine)
                .and_then(|m| m.order.finite())
        })
        .collect();
    let asked: Vec<String> = plan
        .methods
        .iter()
        .cloned()
        .chain(plan.skipped.iter().map(|s| s.0.clone()))
        .collect();
    plan.command = crate::measure::command::CommandLine::new("sweep", &scene.source)
        .flag_opt("dt-min", cfg.dt_min)
        .flag_opt("dt-max", cfg.dt_max)
        .flag_opt("points", cfg.points)
        .switch("extend", cfg.extend == Some(true))
        .switch("no-extend", cfg.extend == Some(false))
        .flag_opt("cost-cap", cfg.cost_cap)
        .flag("duration", plan.duration)
        .flag("substeps", cfg.common.options.substeps)
        .common(&cfg.common, &asked)
        .render();
    Ok(plan)
}

/// The plan's grid and methods (`plan_sweep` adds the orders and the command).
fn plan_grid(scene: &Scenario, cfg: &SweepConfig) -> Result<SweepPlan> {
    let sys = scene.build();
    let duration = crate::scenario::Timing::duration(scene, cfg.duration)?;
    crate::scenario::Timing::check_impulses(scene, duration)?;
    let cap = positive("--cost-cap", cfg.cost_cap.unwrap_or(DEFAULT_COST_CAP))?;
    if cfg.points == Some(0) {
        return Err(Error::option("--points", "must be at least 1"));
    }
    let (methods, skipped) = cfg.common.applicable(&sys)?;
    let fixed_grid = cfg.dt_min.is_some() && cfg.dt_max.is_some() && cfg.points.is_some();
    let (mut hi, mut hi_src, mut lo, mut lo_src, w, widest) = if fixed_grid {
        (0.0, String::new(), 0.0, String::new(), 0.0, None)
    } else {
        dynamic_bounds(scene, &methods, cfg, duration)
    };
    if fixed_grid {
        let ms = modes(&sys, &scene.initial_state());
        return finish(
            scene,
            cfg,
            duration,
            cap,
            methods,
            skipped,
            GridRule {
                omega_max: ms.omega_max,
                widest_stability_limit: None,
                dt_max: positive("--dt-max", cfg.dt_max.unwrap_or(0.0))?,
                dt_max_source: "--dt-max".into(),
                dt_min: positive("--dt-min", cfg.dt_min.unwrap_or(0.0))?,
                dt_min_source: "--dt-min".into(),
                extend: cfg.extend.unwrap_or(false),
                cost_cap_particle_steps: cap,
            },
        );
    }
    if let Some(v) = cfg.dt_max {
        hi = positive("--dt-max", v)?;
        hi_src = "--dt-max".into();
    }
    if let Some(v) = cfg.dt_min {
        lo = positive("--dt-min", v)?;
        lo_src = "--dt-min".into();
    } else if lo >= hi {
        lo = hi / 2f64.powi(MIN_BASE_POINTS as i32 - 1);
        lo_src = format!("{MIN_BASE_POINTS} halving-spaced points below dt_max");
    }
    let rule = GridRule {
        omega_max: w,
        widest_stability_limit: widest,
        dt_max: hi,
        dt_max_source: hi_src,
        dt_min: lo,
        dt_min_source: lo_src,
        extend: cfg.extend.unwrap_or(cfg.dt_min.is_none()),
        cost_cap_particle_steps: cap,
    };
    finish(scene, cfg, duration, cap, methods, skipped, rule)
}

fn finish(
    scene: &Scenario,
    cfg: &SweepConfig,
    duration: f64,
    cap: f64,
    methods: Vec<String>,
    skipped: Vec<(String, String)>,
    rule: GridRule,
) -> Result<SweepPlan> {
    let (lo, hi) = (rule.dt_min, rule.dt_max.min(duration));
    let num = crate::error::num;
    // The flag to blame: --dt-min when the user gave it, else the flag the small end was
    // derived from (--dt-max), else --dt-min as the flag that would fix it.
    let blamed = if cfg.dt_min.is_some() || cfg.dt_max.is_none() {
        "--dt-min"
    } else {
        "--dt-max"
    };
    if lo > hi {
        return Err(Error::option(
            blamed,
            format!(
                "{} exceeds the largest step {} ({})",
                num(lo),
                num(hi),
                rule.dt_max_source
            ),
        ));
    }
    if duration / lo > crate::scenario::MAX_STEPS as f64 {
        return Err(Error::option(
            blamed,
            format!(
                "the smallest step {} s over {} s exceeds the step limit of {}",
                num(lo),
                num(duration),
                crate::scenario::MAX_STEPS
            ),
        ));
    }
    // Halving spacing unless the user fixed the number of points.
    let points = cfg
        .points
        .unwrap_or_else(|| (hi / lo).log2().round().max(0.0) as usize + 1);
    let particles = scene.particles.len().max(1);
    let mut base = step_grid(lo, hi, points, duration);
    // The default base grid obeys the cost cap too: drop its smallest steps while one
    // method's runs over it would exceed the cap (keeping at least the largest step). A
    // user's --dt-min is honoured exactly.
    while cfg.dt_min.is_none()
        && base.len() > 1
        && base.iter().map(|g| g.1 as f64).sum::<f64>() * particles as f64 > cap
    {
        base.remove(0);
    }
    let mut ext: Vec<(f64, u64)> = Vec::new();
    if rule.extend {
        let mut spent: f64 = base.iter().map(|g| g.1 as f64 * particles as f64).sum();
        let mut n = base[0].1;
        while ext.len() < MAX_EXTENSION {
            n *= 2;
            spent += n as f64 * particles as f64;
            if spent > cap || n > crate::scenario::MAX_STEPS {
                break;
            }
            ext.push((duration / n as f64, n));
        }
        ext.reverse();
    }
    let base_from = ext.len();
    let grid: Vec<(f64, u64)> = ext.into_iter().chain(base).collect();
    let max_samples = max_samples_for(cfg.budget_bytes, grid.len(), particles);
    Ok(SweepPlan {
        command: String::new(),
        orders: Vec::new(),
        scenario: scene.name.clone(),
        duration,
        dts: grid.iter().map(|g| g.0).collect(),
        steps: grid.iter().map(|g| g.1).collect(),
        strides: grid
            .iter()
            .map(|g| TimeGrid::new(g.0, g.1, max_samples).stride)
            .collect(),
        base_from,
        particles,
        rule,
        methods,
        skipped,
        blowup_factor: cfg.common.blowup_factor,
        options: cfg.common.options.resolved(&cfg.common.registry),
        substeps: cfg.common.options.substeps,
        budget: None,
    })
}

/// Theoretical order of a method of the plan (None for exact methods and engines), as its
/// registry entry stated it when the sweep was planned.
pub fn theoretical_order(plan: &SweepPlan, name: &str) -> Option<u32> {
    let i = plan.methods.iter().position(|n| n == name)?;
    plan.orders.get(i).copied().flatten()
}
