//! Largest stable step per integrator: exactly from the spectral radius of each method's
//! one-step map on the scene's linearised modes, and empirically by bisection on the real
//! scene.
//!
//! Theory: for every mode q'' + c q' + ω² q = 0 (see [`super::modes`]) the integrator itself
//! is stepped on a one-particle system with exactly that linear force, and its one-step map
//! M(h) on (x, v) is identified from two consecutive steps of two independent trajectories
//! (M = Y₂ Y₁⁻¹, which also covers methods whose memory is a function of (x, v), such as
//! two-step Störmer); a genuinely multistep method (BDF2) has its k-step recurrence identified
//! instead, and its companion matrix decides (see [`step_radius`]). The method
//! is stable at h when the spectral radius ρ(M(h)) ≤ 1 + [`RHO_TOL`] for every mode. The
//! boundary is bracketed on a log grid hω ∈ [1e-2, 1e4] and bisected to machine precision.
//!
//! Empirical: a run is stable when the runner's one verdict ([`crate::run::verdict`]) calls
//! it ok over the horizon: finite states, and an energy balance that never rose by more than
//! `blowup_factor` × the scene's energy scale. The step is doubled or halved to a bracket,
//! then bisected to 0.1 %. Bisection assumes that stability is monotone in dt. A method just
//! inside its linear limit can swing its energy by more than the threshold without growing
//! (symplectic Euler from rest reaches 1/(1 − hω/2) times its energy): the empirical limit is
//! then below the theoretical one, never above it.
//!
//! The map ([`stability_map`]) runs each cell for at least [`MAP_MIN_STEPS`] steps, so a
//! spectral radius of [`RHO_SHOWN`] multiplies the energy of its mode by at least
//! [`GROWTH_SHOWN`] and shows as a blow-up, from the scene's initial state with every free
//! particle displaced by [`MAP_SEED`] × its characteristic length ([`seeded`]): a symmetric
//! scene (a spring hanging straight down) never excites its transverse modes, whose growth
//! would otherwise never show.

pub use super::modes::Mode;
use super::modes::{modes, Modes};
use crate::error::Result;
use crate::method::MethodOptions;
use crate::method::{Method, Registry, StabilityTheory};
use crate::model::{EnergyKind, ForceTerm, Jacobian, Springs, State, System, Vec3};
use crate::run::{run, NoObserver, RunPlan};
use crate::scenario::Scenario;
use nalgebra::Matrix3;
use rayon::prelude::*;
use serde::Serialize;

/// Tolerance on the spectral radius: ρ ≤ 1 + RHO_TOL counts as stable.
pub const RHO_TOL: f64 = 1e-12;
/// Smallest hω tried by the theory scan.
pub const SCAN_MIN: f64 = 1e-2;
/// Largest hω tried by the theory scan: stable up to here means unconditionally stable.
pub const SCAN_MAX: f64 = 1e3;

/// An isotropic linear force f = −k x − c v on every particle: one linearised mode.
#[derive(Debug, Clone, Copy)]
struct LinearMode {
    k: f64,
    c: f64,
}

impl ForceTerm for LinearMode {
    fn name(&self) -> &'static str {
        "linear_mode"
    }
    fn energy_kind(&self) -> EnergyKind {
        EnergyKind::Elastic
    }
    fn add_forces(&self, x: &[Vec3], v: &[Vec3], f: &mut [Vec3]) -> f64 {
        let mut p = 0.0;
        for i in 0..f.len() {
            f[i] -= x[i] * self.k + v[i] * self.c;
            p += self.c * v[i].norm_squared();
        }
        p
    }
    fn potential_energy(&self, x: &[Vec3]) -> f64 {
        x.iter().map(|x| 0.5 * self.k * x.norm_squared()).sum()
    }
    fn add_jacobian(&self, _x: &[Vec3], _v: &[Vec3], jac: &mut Jacobian) {
        for d in jac.diag_x.iter_mut() {
            *d -= Matrix3::identity() * self.k;
        }
        for d in jac.diag_v.iter_mut() {
            *d -= Matrix3::identity() * self.c;
        }
    }
}

fn mode_system(m: Mode) -> System {
    System {
        mass: vec![1.0],
        inv_mass: vec![1.0],
        free: vec![true],
        radius: vec![0.0],
        springs: Springs::default(),
        gravity: None,
        drag: None,
        constraints: vec![],
        impulses: vec![],
        events: Default::default(),
        post_step: None,
        terms: vec![Box::new(LinearMode {
            k: m.omega2,
            c: m.damping,
        })],
    }
}

/// The one-step map of `method` on mode `m` at step `h`, as a 2×2 matrix on (x, v);
/// None when the method fails or the identification is singular.
pub fn one_step_map(
    method: &Method,
    opts: &MethodOptions,
    m: Mode,
    h: f64,
) -> Option<[[f64; 2]; 2]> {
    let sys = mode_system(m);
    let traj = |x0: f64, v0: f64| -> Option<[(f64, f64); 2]> {
        let mut integ = method.create(opts);
        integ.check(&sys).ok()?;
        let mut s = State {
            t: 0.0,
            x: vec![Vec3::new(x0, 0.0, 0.0)],
            v: vec![Vec3::new(v0, 0.0, 0.0)],
        };
        integ.reset();
        integ.step(&sys, &mut s, h).ok()?;
        let y1 = (s.x[0].x, s.v[0].x);
        integ.step(&sys, &mut s, h).ok()?;
        Some([y1, (s.x[0].x, s.v[0].x)])
    };
    let a = traj(1.0, 0.0)?;
    let b = traj(0.0, 1.0)?;
    // Y1 = [a1 b1], Y2 = [a2 b2] (columns), M = Y2 Y1⁻¹.
    let (p, q, r, s) = (a[0].0, b[0].0, a[0].1, b[0].1);
    let det = p * s - q * r;
    if !(det.is_finite() && det != 0.0) {
        return None;
    }
    let inv = [[s / det, -q / det], [-r / det, p / det]];
    let y2 = [[a[1].0, b[1].0], [a[1].1, b[1].1]];
    let mut mm = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            mm[i][j] = y2[i][0] * inv[0][j] + y2[i][1] * inv[1][j];
        }
    }
    mm.iter().flatten().all(|v| v.is_finite()).then_some(mm)
}

/// Spectral radius of the step map of `method` on mode `m` at step `h`: of the 2×2 one-step
/// map ([`one_step_map`]) for one-step methods, and for a k-step method (say BDF2, k = 2) of
/// the 2k×2k companion matrix of its recurrence yₙ₊₁ = Σⱼ Aⱼ yₙ₋ⱼ, identified from two
/// independent trajectories of 2k − 1 steps (the first k − 1 of which are its start: k
/// recurrence steps give the k unknown 2×2 blocks). None when the method fails or the
/// identification is singular.
pub fn step_radius(method: &Method, opts: &MethodOptions, m: Mode, h: f64) -> Option<f64> {
    let k = method.info.recurrence_steps;
    if k <= 1 {
        return one_step_map(method, opts, m, h).map(spectral_radius);
    }
    let sys = mode_system(m);
    let traj = |x0: f64, v0: f64| -> Option<Vec<(f64, f64)>> {
        let mut integ = method.create(opts);
        integ.check(&sys).ok()?;
        let mut s = State {
            t: 0.0,
            x: vec![Vec3::new(x0, 0.0, 0.0)],
            v: vec![Vec3::new(v0, 0.0, 0.0)],
        };
        integ.reset();
        let mut ys = vec![(x0, v0)];
        for _ in 0..2 * k - 1 {
            integ.step(&sys, &mut s, h).ok()?;
            ys.push((s.x[0].x, s.v[0].x));
        }
        Some(ys)
    };
    let (a, b) = (traj(1.0, 0.0)?, traj(0.0, 1.0)?);
    // Y_n: columns are the two trajectories at step n.
    let y = |n: usize| nalgebra::Matrix2::new(a[n].0, b[n].0, a[n].1, b[n].1);
    let mut w = nalgebra::DMatrix::<f64>::zeros(2 * k, 2 * k);
    let mut r = nalgebra::DMatrix::<f64>::zeros(2, 2 * k);
    for (col, n) in (k - 1..2 * k - 1).enumerate() {
        r.view_mut((0, 2 * col), (2, 2)).copy_from(&y(n + 1));
        for j in 0..k {
            w.view_mut((2 * j, 2 * col), (2, 2)).copy_from(&y(n - j));
        }
    }
    // [A₀ … A_{k−1}] W = R.
    let blocks = w.transpose().lu().solve(&r.transpose())?.transpose();
    let mut c = nalgebra::DMatrix::<f64>::zeros(2 * k, 2 * k);
    c.view_mut((0, 0), (2, 2 * k)).copy_from(&blocks);
    for i in 2..2 * k {
        c[(i, i - 2)] = 1.0;
    }
    let radius = c
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    radius.is_finite().then_some(radius)
}

/// Spectral radius of a 2×2 matrix.
pub fn spectral_radius(m: [[f64; 2]; 2]) -> f64 {
    let tr = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let disc = 0.25 * tr * tr - det;
    if disc >= 0.0 {
        let s = disc.sqrt();
        (0.5 * tr + s).abs().max((0.5 * tr - s).abs())
    } else {
        det.abs().sqrt()
    }
}

fn rho(method: &Method, opts: &MethodOptions, m: Mode, h: f64) -> f64 {
    step_radius(method, opts, m, h).unwrap_or(f64::INFINITY)
}

/// A stability verdict.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Stable for every dt below `max_stable_dt`.
    StableBelow,
    /// Stable at every dt tried.
    UnconditionallyStable,
    /// Unstable at every dt tried.
    UnstableForAllDt,
    /// Neither theory nor the empirical search was run (say, an engine with `--theory-only`).
    NotAnalysed,
}

/// A verdict with its step limit (s) when `stable_below`.
pub type Limit = (Verdict, Option<f64>);

/// Largest stable step on one mode: (verdict, limit).
pub fn mode_limit(method: &Method, opts: &MethodOptions, m: Mode) -> (Verdict, Option<f64>) {
    let w = m.omega2.sqrt().max(m.damping);
    if w <= 0.0 {
        return (Verdict::UnconditionallyStable, None);
    }
    let n = 121;
    let hs: Vec<f64> = (0..n)
        .map(|i| SCAN_MIN * (SCAN_MAX / SCAN_MIN).powf(i as f64 / (n - 1) as f64) / w)
        .collect();
    // A step the method cannot take (say, Newton fails at enormous hω) ends the scan: it
    // says nothing about stability, so the verdict rests on the steps that ran.
    let state = |h: f64| step_radius(method, opts, m, h).map(|r| r <= 1.0 + RHO_TOL);
    let stable = |h: f64| state(h).unwrap_or(false);
    match state(hs[0]) {
        Some(true) => {}
        _ => return (Verdict::UnstableForAllDt, None),
    }
    let mut first_bad = None;
    for (i, &h) in hs.iter().enumerate() {
        match state(h) {
            Some(true) => {}
            Some(false) => {
                first_bad = Some(i);
                break;
            }
            None => break,
        }
    }
    let Some(first_bad) = first_bad else {
        return (Verdict::UnconditionallyStable, None);
    };
    let (mut lo, mut hi) = (hs[first_bad - 1], hs[first_bad]);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if stable(mid) {
            lo = mid
        } else {
            hi = mid
        }
    }
    (Verdict::StableBelow, Some(lo))
}

/// Theory for a method over all modes: the tightest mode decides.
pub fn theory_limit(method: &Method, opts: &MethodOptions, ms: &Modes) -> (Verdict, Option<f64>) {
    let mut best = (Verdict::UnconditionallyStable, None::<f64>);
    for &m in &ms.modes {
        match mode_limit(method, opts, m) {
            (Verdict::UnstableForAllDt, _) => return (Verdict::UnstableForAllDt, None),
            (Verdict::StableBelow, Some(h)) if best.1.is_none_or(|b| h < b) => {
                best = (Verdict::StableBelow, Some(h));
            }
            _ => {}
        }
    }
    best
}

/// The empirical criterion and search bounds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EmpiricalCriterion {
    /// Simulated time of each trial run (s).
    pub horizon: f64,
    /// A run is unstable once its energy balance rises by more than this multiple of the
    /// scene's energy scale, or a state is non-finite (the runner's verdict).
    pub blowup_factor: f64,
    /// Smallest step tried (s).
    pub dt_min: f64,
    /// Largest step tried (s).
    pub dt_max: f64,
}

/// Result of the empirical search.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Empirical {
    /// Verdict within the search bounds.
    pub verdict: Verdict,
    /// Largest stable step found (s).
    pub max_stable_dt: Option<f64>,
    /// Trial runs made.
    pub runs: usize,
}

/// Empirical search for the largest stable step of `method` on the real scene.
pub fn empirical_limit(
    sys: &System,
    s0: &State,
    method: &Method,
    opts: &MethodOptions,
    start: f64,
    crit: &EmpiricalCriterion,
) -> Result<Empirical> {
    let mut runs = 0;
    let mut stable = |h: f64| -> Result<bool> {
        runs += 1;
        let mut integ = method.create(opts);
        let plan = RunPlan {
            dt: h,
            steps: crate::model::covering_steps(crit.horizon, h),
            substeps: 1,
            blowup_factor: crit.blowup_factor,
            stop_at_verdict: true,
        };
        Ok(
            run(sys, integ.as_mut(), s0.clone(), &plan, &mut NoObserver)?
                .status
                .is_ok(),
        )
    };
    let mut h = start.clamp(crit.dt_min, crit.dt_max);
    let (mut lo, mut hi);
    if stable(h)? {
        lo = h;
        loop {
            h *= 2.0;
            if h > crit.dt_max {
                return Ok(Empirical {
                    verdict: Verdict::UnconditionallyStable,
                    max_stable_dt: None,
                    runs,
                });
            }
            if !stable(h)? {
                hi = h;
                break;
            }
            lo = h;
        }
    } else {
        hi = h;
        loop {
            h *= 0.5;
            if h < crit.dt_min {
                return Ok(Empirical {
                    verdict: Verdict::UnstableForAllDt,
                    max_stable_dt: None,
                    runs,
                });
            }
            if stable(h)? {
                lo = h;
                break;
            }
            hi = h;
        }
    }
    while hi / lo > 1.001 {
        let mid = (lo * hi).sqrt();
        if stable(mid)? {
            lo = mid
        } else {
            hi = mid
        }
    }
    Ok(Empirical {
        verdict: Verdict::StableBelow,
        max_stable_dt: Some(lo),
        runs,
    })
}

/// Per method, why its empirical search is left out (`None`: it runs): the searches that fit
/// `budget` (s, summed), cheapest first, run; each projected at [`SEARCH_TRIALS`] trials of
/// `horizon / start` steps at its probed time per step.
fn searches_over_budget(
    sys: &System,
    s0: &State,
    cfg: &StabilityConfig,
    names: &[String],
    starts: &[Option<f64>],
    horizon: f64,
    budget: f64,
) -> Result<Vec<Option<String>>> {
    use super::probe::{check_budget, seconds_per_step, split_by_budget, Cost};
    check_budget(budget)?;
    let costs: Vec<Cost> = names
        .iter()
        .zip(starts)
        .map(|(name, start)| match start {
            Some(h) => {
                let steps = (horizon / h).ceil().max(1.0);
                let per =
                    seconds_per_step(sys, s0, &cfg.methods, &cfg.options, name, *h, steps as u64)
                        .unwrap_or(0.0);
                Cost {
                    per_unit: per,
                    projected: per * steps * SEARCH_TRIALS,
                }
            }
            None => Cost {
                per_unit: 0.0,
                projected: 0.0,
            },
        })
        .collect();
    let what = format!("its empirical search (about {SEARCH_TRIALS} trials over the horizon)");
    let (_, left) = split_by_budget(names.to_vec(), &costs, budget, &what, "step");
    Ok(names
        .iter()
        .map(|n| left.iter().find(|l| l.0 == *n).map(|l| l.1.clone()))
        .collect())
}

/// Per-integrator stability.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IntegratorStability {
    /// Integrator name.
    pub integrator: String,
    /// The verdict (theory when available, else empirical).
    pub verdict: Verdict,
    /// Largest stable step (s) when `stable_below`.
    pub max_stable_dt: Option<f64>,
    /// max_stable_dt × omega_max.
    pub h_omega: Option<f64>,
    /// Which method decided: `spectral_radius` or `empirical_bisection`.
    pub method: String,
    /// The theory verdict (None for external backends).
    pub theory_verdict: Option<Verdict>,
    /// The theory limit (s).
    pub theory_max_stable_dt: Option<f64>,
    /// The empirical search.
    pub empirical: Option<Empirical>,
    /// Anything to know (skipped, approximations).
    pub note: Option<String>,
}

/// `stability.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilityReport {
    /// The command that re-creates this document (`--out DIR` is added where it is written).
    pub command: String,
    /// Scenario name.
    pub scenario: String,
    /// Highest natural frequency of the linearised scene (rad/s).
    pub omega_max: f64,
    /// The modal analysis.
    pub modes: Modes,
    /// Theory criterion in words.
    pub theory_criterion: String,
    /// Empirical criterion.
    pub empirical_criterion: EmpiricalCriterion,
    /// Per integrator.
    pub integrators: Vec<IntegratorStability>,
    /// Integrators that do not apply, with the reason.
    pub skipped: Vec<(String, String)>,
}

/// Options of [`analyse`].
#[derive(Debug, Clone)]
pub struct StabilityConfig {
    /// Integrators (empty: all applicable).
    pub integrators: Vec<String>,
    /// The methods to choose from (built-ins unless a library user added theirs).
    pub methods: Registry,
    /// Integrator options.
    pub options: MethodOptions,
    /// Empirical horizon (default: 100 periods of ω_max, else the scene's duration).
    pub horizon: Option<f64>,
    /// Empirical blow-up factor (default: every command's, [`crate::run::DEFAULT_BLOWUP_FACTOR`]).
    pub blowup_factor: f64,
    /// Skip the empirical search.
    pub theory_only: bool,
    /// Run the empirical search only for methods without linear theory (where the spectral
    /// radius decides the verdict, the search is a cross-check that costs many runs).
    pub empirical_where_no_theory: bool,
    /// Progress bar (one tick per method) on a terminal.
    pub progress: bool,
    /// Time budget of the empirical searches (s of runs, summed): each searching method's
    /// time per step is probed at its first trial step, its search projected at
    /// [`SEARCH_TRIALS`] trials, and the costliest searches that would exceed the budget are
    /// left out, named with the figure. `None`: no budget (the study bounds its engines itself).
    pub budget_seconds: Option<f64>,
}

/// Trials an empirical search typically takes, for its projected cost: bracketing by doubling
/// or halving (one to three), then bisection to a 0.1 % bracket (about ten).
pub const SEARCH_TRIALS: f64 = 14.0;

/// A one-step spectral radius the map must always show as a blow-up.
pub const RHO_SHOWN: f64 = 1.01;
/// The energy growth a radius of [`RHO_SHOWN`] reaches within [`MAP_MIN_STEPS`] steps.
pub const GROWTH_SHOWN: f64 = 1e12;
/// Fewest steps of a map cell: ρ²ⁿ ≥ [`GROWTH_SHOWN`] at ρ = [`RHO_SHOWN`] (n = 1389).
pub const MAP_MIN_STEPS: u64 = 1389;
/// Most steps of a map cell.
pub const MAP_MAX_STEPS: u64 = 20_000;
/// Displacement seeding every mode of a map cell, relative to the characteristic length: its
/// energy is ~1e-8 of the scene's, far below [`GROWTH_SHOWN`]'s reach.
pub const MAP_SEED: f64 = 1e-4;

/// `s0` with every free particle moved by `MAP_SEED` × the characteristic length along a
/// fixed direction that is oblique to every axis (deterministic: the same map every time).
pub fn seeded(sys: &System, s0: &State) -> State {
    let len = crate::run::characteristic_length(sys, s0);
    let len = if len > 0.0 { len } else { 1.0 };
    let mut s = s0.clone();
    for p in (0..sys.len()).filter(|&p| sys.free[p]) {
        let d = Vec3::new(
            1.0 + (p % 3) as f64,
            2.0 + (p % 5) as f64,
            3.0 + (p % 7) as f64,
        );
        s.x[p] += d * (MAP_SEED * len / d.norm());
    }
    s
}

impl Default for StabilityConfig {
    fn default() -> Self {
        StabilityConfig {
            integrators: vec![],
            methods: Registry::builtin(),
            options: MethodOptions::default(),
            horizon: None,
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
            theory_only: false,
            empirical_where_no_theory: false,
            progress: false,
            budget_seconds: None,
        }
    }
}

/// Analyses every applicable integrator on `scene`.
pub fn analyse(scene: &Scenario, cfg: &StabilityConfig) -> Result<StabilityReport> {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let ms = modes(&sys, &s0);
    let (names, skipped) =
        super::case::applicable(&cfg.methods, &sys, &cfg.integrators, &cfg.options)?;
    let horizon = match cfg.horizon {
        Some(h) => h,
        None if ms.omega_max > 0.0 => 100.0 * std::f64::consts::TAU / ms.omega_max,
        // Nothing oscillates: the scene's own duration (an error when it has none).
        None => crate::scenario::Timing::duration(scene, None)?,
    };
    // A horizon the trial runs cannot cover at a step that resolves the fastest mode
    // (hω_max = 1) is refused like any run past the step limit.
    if let Some(h) = cfg.horizon {
        let flag = "--horizon";
        if !(h.is_finite() && h > 0.0) {
            return Err(crate::error::Error::option(
                flag,
                format!("must be a finite number > 0, got {}", crate::error::num(h)),
            ));
        }
        if ms.omega_max > 0.0 {
            let step = 1.0 / ms.omega_max;
            crate::scenario::Timing::steps_within(flag, step, h).map_err(|e| {
                crate::error::Error::option(
                    flag,
                    format!(
                        "at the step that resolves the fastest mode (hω_max = 1), {}",
                        e.to_string().trim_start_matches("--horizon: ")
                    ),
                )
            })?;
        } else if let Some(dt) = scene.run.dt {
            crate::scenario::Timing::steps_within(flag, dt, h)?;
        }
    }
    let crit = EmpiricalCriterion {
        horizon,
        blowup_factor: cfg.blowup_factor,
        dt_min: horizon / 1e6,
        dt_max: horizon / 2.0,
    };
    // The linear theory per method (cheap), then where each empirical search would start and
    // which searches the budget allows.
    let theories: Vec<Option<(Verdict, Option<f64>)>> = names
        .iter()
        .map(|name| {
            let method = cfg.methods.get(name)?;
            Ok((method.info.linear_theory() && !ms.modes.is_empty())
                .then(|| theory_limit(method, &cfg.options, &ms)))
        })
        .collect::<Result<_>>()?;
    let starts: Vec<Option<f64>> = names
        .iter()
        .zip(&theories)
        .map(|(name, theory)| {
            let unconditional = cfg
                .methods
                .info(name)
                .is_ok_and(|m| m.stability == StabilityTheory::Unconditional);
            let skip = unconditional
                || cfg.theory_only
                || (cfg.empirical_where_no_theory && theory.is_some());
            (!skip).then(|| {
                theory
                    .and_then(|t| t.1)
                    .or(scene.run.dt)
                    .unwrap_or(horizon / 100.0)
                    .clamp(crit.dt_min, crit.dt_max)
            })
        })
        .collect();
    let left_out = match cfg.budget_seconds {
        Some(b) => searches_over_budget(&sys, &s0, cfg, &names, &starts, horizon, b)?,
        None => vec![None; names.len()],
    };
    let pb = crate::run::progress_bar(
        names.len() as u64,
        &format!("stability {}", scene.name),
        cfg.progress,
    );
    let results: Vec<Result<IntegratorStability>> = names
        .par_iter()
        .enumerate()
        .map(|(k, name)| {
            let method = cfg.methods.get(name)?;
            let exact = method.info.stability == StabilityTheory::Unconditional;
            let mut note = None;
            let theory = if let Some(t) = theories[k] {
                Some(t)
            } else {
                if ms.modes.is_empty() {
                    note = Some("the linearised scene has no stiffness or damping (constraints are projected, not linearised): empirical only".to_string());
                } else if exact {
                    note = Some("exact closed form: stable at any step".to_string());
                } else if !method.info.linear_theory() {
                    note = Some(format!(
                        "no linear one-step theory applies to {name} (registered stability: empirical; a constraint projection or an engine's solver, not a linear map of the ODE): empirical bisection on the scene only"
                    ));
                }
                None
            };
            if exact {
                return Ok(IntegratorStability {
                    integrator: name.clone(),
                    verdict: Verdict::UnconditionallyStable,
                    max_stable_dt: None,
                    h_omega: None,
                    method: "closed_form".into(),
                    theory_verdict: Some(Verdict::UnconditionallyStable),
                    theory_max_stable_dt: None,
                    empirical: None,
                    note,
                });
            }
            let empirical = match (starts[k], &left_out[k]) {
                (Some(start), None) => {
                    Some(empirical_limit(&sys, &s0, method, &cfg.options, start, &crit)?)
                }
                (Some(_), Some(why)) => {
                    note = Some(why.clone());
                    None
                }
                (None, _) => None,
            };
            let (verdict, dt, method) = match (&theory, &empirical) {
                (Some(t), _) => (t.0, t.1, "spectral_radius"),
                (None, Some(e)) => (e.verdict, e.max_stable_dt, "empirical_bisection"),
                (None, None) => {
                    if left_out[k].is_none() {
                        note = Some("no linear theory applies and the empirical search was skipped (--theory-only)".into());
                    }
                    (Verdict::NotAnalysed, None, "none")
                }
            };
            if ms.damping_coupling.is_some_and(|c| c > 1e-6) && theory.is_some() {
                note = Some(format!(
                    "modal damping is coupled (off-diagonal {:.1e} of the diagonal); the theory limit uses the diagonal",
                    ms.damping_coupling.unwrap_or(0.0)
                ));
            }
            Ok(IntegratorStability {
                integrator: name.clone(),
                verdict,
                max_stable_dt: dt,
                h_omega: dt.map(|d| d * ms.omega_max),
                method: method.into(),
                theory_verdict: theory.map(|t| t.0),
                theory_max_stable_dt: theory.and_then(|t| t.1),
                empirical,
                note,
            })
        })
        .inspect(|_| pb.inc(1))
        .collect();
    pb.finish_and_clear();
    let asked = super::case::asked_or_all(&cfg.methods, &cfg.integrators);
    let command = super::command::CommandLine::new("stability", &scene.source)
        .list("integrators", &asked)
        .flag("substeps", cfg.options.substeps)
        .method_options(&cfg.methods, &cfg.options)
        .flag("horizon", horizon)
        .flag("blowup-factor", cfg.blowup_factor)
        .flag_opt("budget", cfg.budget_seconds)
        .switch("theory-only", cfg.theory_only)
        .switch("empirical-where-no-theory", cfg.empirical_where_no_theory)
        .render();
    Ok(StabilityReport {
        command,
        scenario: scene.name.clone(),
        omega_max: ms.omega_max,
        theory_criterion: format!("spectral radius of the one-step map on every linearised mode ≤ 1 + {RHO_TOL:e}, scanned over hω ∈ [{SCAN_MIN:e}, {SCAN_MAX:e}] and bisected"),
        empirical_criterion: crit,
        integrators: results.into_iter().collect::<Result<_>>()?,
        skipped,
        modes: ms,
    })
}

/// Writes `stability.json` into `dir` (with `--out dir` in its command).
pub fn write_stability(dir: &std::path::Path, rep: &StabilityReport) -> Result<std::path::PathBuf> {
    let doc = StabilityReport {
        command: super::command::with_out(&rep.command, dir),
        ..rep.clone()
    };
    let mut json = serde_json::to_vec_pretty(&doc).expect("serialisable");
    json.push(b'\n');
    crate::output::write_atomic(dir.join("stability.json"), &json)
}

/// Options of [`stability_map`].
#[derive(Debug, Clone)]
pub struct MapConfig {
    /// Integrators (empty: all applicable).
    pub integrators: Vec<String>,
    /// The methods to choose from (built-ins unless a library user added theirs).
    pub methods: Registry,
    /// Integrator options.
    pub options: MethodOptions,
    /// Multipliers of every spring stiffness (default 1/16 … 16, 9 points).
    pub stiffness_scales: Vec<f64>,
    /// Multipliers of every damper and of drag (default [1]).
    pub damping_scales: Vec<f64>,
    /// Steps as multiples of 1/ω_max of the unscaled scene (default 16 points in [0.02, 20]).
    pub h_omega: Vec<f64>,
    /// Absolute steps (s); when non-empty they replace `h_omega` (for maps spanning many
    /// decades of stiffness, where one relative axis cannot cover every scale).
    pub dts: Vec<f64>,
    /// Periods of the scaled ω_max per empirical run (default 50; at least [`MAP_MIN_STEPS`]
    /// and at most [`MAP_MAX_STEPS`] steps).
    pub periods: f64,
    /// Blow-up factor of the empirical runs.
    pub blowup_factor: f64,
    /// Progress bar on a terminal.
    pub progress: bool,
}

fn logspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a * (b / a).powf(i as f64 / (n.max(2) - 1) as f64))
        .collect()
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            integrators: vec![],
            methods: Registry::builtin(),
            options: MethodOptions::default(),
            stiffness_scales: logspace(1.0 / 16.0, 16.0, 9),
            damping_scales: vec![1.0],
            h_omega: logspace(0.02, 20.0, 16),
            dts: vec![],
            periods: 50.0,
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
            progress: false,
        }
    }
}

/// One cell of `stability_map.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapRow {
    /// Integrator.
    pub integrator: String,
    /// Stiffness multiplier.
    pub stiffness_scale: f64,
    /// Damping multiplier.
    pub damping_scale: f64,
    /// Step (s).
    pub dt: f64,
    /// ω_max of the scaled scene (rad/s).
    pub omega_max: f64,
    /// dt × omega_max.
    pub h_omega: f64,
    /// Largest spectral radius over the linearised modes (None: no theory for this method).
    pub spectral_radius: Option<f64>,
    /// Theoretical largest stable step of the scaled scene (None: unconditional or unknown).
    pub theory_max_dt: Option<f64>,
    /// Theory verdict for the scaled scene.
    pub theory_verdict: Option<Verdict>,
    /// Did the empirical run stay stable?
    pub stable: bool,
}

/// The header of `stability_map.csv`.
pub const MAP_HEADER: &str = "integrator,stiffness_scale,damping_scale,dt,omega_max,h_omega,spectral_radius,theory_max_dt,theory_verdict,stable";

impl MapRow {
    /// The CSV line.
    pub fn csv_line(&self) -> String {
        let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
        let v = match self.theory_verdict {
            Some(Verdict::StableBelow) => "stable_below",
            Some(Verdict::UnconditionallyStable) => "unconditionally_stable",
            Some(Verdict::UnstableForAllDt) => "unstable_for_all_dt",
            Some(Verdict::NotAnalysed) | None => "",
        };
        format!(
            "{},{:e},{:e},{:e},{:e},{:e},{},{},{},{}",
            self.integrator,
            self.stiffness_scale,
            self.damping_scale,
            self.dt,
            self.omega_max,
            self.h_omega,
            o(self.spectral_radius),
            o(self.theory_max_dt),
            v,
            self.stable
        )
    }
}

fn scaled(scene: &Scenario, ks: f64, cs: f64) -> Scenario {
    let mut s = scene.clone();
    for sp in &mut s.springs {
        sp.stiffness *= ks;
        sp.damping *= cs;
    }
    s.drag = s.drag.map(|d| d * cs);
    s
}

/// Sweeps stiffness × damping × dt: empirical stability of each cell with the theoretical
/// spectral radius and boundary alongside. Cells run in parallel, collected in order.
pub fn stability_map(scene: &Scenario, cfg: &MapConfig) -> Result<Vec<MapRow>> {
    let sys0 = scene.build();
    let s0 = scene.initial_state();
    let w0 = modes(&sys0, &s0).omega_max;
    let w0 = if w0 > 0.0 { w0 } else { 1.0 };
    let (names, _) = super::case::applicable(&cfg.methods, &sys0, &cfg.integrators, &cfg.options)?;
    // Exact methods are stable everywhere by construction: nothing to map.
    let methods: Vec<&Method> = names
        .iter()
        .map(|n| cfg.methods.get(n))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .filter(|m| m.info.stability != StabilityTheory::Unconditional)
        .collect();
    let names: Vec<String> = methods.iter().map(|m| m.info.name.to_string()).collect();
    let mut cells = Vec::new();
    for name in &names {
        for &ks in &cfg.stiffness_scales {
            for &cs in &cfg.damping_scales {
                if cfg.dts.is_empty() {
                    for &hw in &cfg.h_omega {
                        cells.push((name.clone(), ks, cs, hw / w0));
                    }
                } else {
                    for &dt in &cfg.dts {
                        cells.push((name.clone(), ks, cs, dt));
                    }
                }
            }
        }
    }
    // Modal analysis once per (stiffness, damping) pair.
    let mut pairs: Vec<(f64, f64, Modes)> = Vec::new();
    for &ks in &cfg.stiffness_scales {
        for &cs in &cfg.damping_scales {
            let sc = scaled(scene, ks, cs);
            pairs.push((ks, cs, modes(&sc.build(), &s0)));
        }
    }
    let theory: Vec<Vec<Option<Limit>>> = methods
        .par_iter()
        .map(|method| {
            pairs
                .iter()
                .map(|(_, _, m)| {
                    (method.info.linear_theory() && !m.modes.is_empty())
                        .then(|| theory_limit(method, &cfg.options, m))
                })
                .collect()
        })
        .collect();
    let pb = crate::run::progress_bar(
        cells.len() as u64,
        &format!("stability map {}", scene.name),
        cfg.progress,
    );
    let rows: Vec<Result<MapRow>> = cells
        .par_iter()
        .map(|(name, ks, cs, dt)| {
            let pi = pairs
                .iter()
                .position(|p| p.0 == *ks && p.1 == *cs)
                .expect("pair");
            let ms = &pairs[pi].2;
            let ni = names.iter().position(|n| n == name).expect("name");
            let th = theory[ni][pi];
            let w = if ms.omega_max > 0.0 { ms.omega_max } else { w0 };
            let sc = scaled(scene, *ks, *cs);
            let sys = sc.build();
            let steps = ((cfg.periods * std::f64::consts::TAU / w / dt).ceil() as u64)
                .clamp(MAP_MIN_STEPS, MAP_MAX_STEPS);
            let method = methods[ni];
            let mut integ = method.create(&cfg.options);
            let plan = RunPlan {
                dt: *dt,
                steps,
                substeps: 1,
                blowup_factor: cfg.blowup_factor,
                stop_at_verdict: true,
            };
            let stable = run(
                &sys,
                integ.as_mut(),
                seeded(&sys, &s0),
                &plan,
                &mut NoObserver,
            )?
            .status
            .is_ok();
            let rho_max = th.map(|_| {
                ms.modes
                    .iter()
                    .map(|&m| rho(method, &cfg.options, m, *dt))
                    .fold(0.0, f64::max)
            });
            pb.inc(1);
            Ok(MapRow {
                integrator: name.clone(),
                stiffness_scale: *ks,
                damping_scale: *cs,
                dt: *dt,
                omega_max: ms.omega_max,
                h_omega: dt * ms.omega_max,
                spectral_radius: rho_max.map(|r| if r.is_finite() { r } else { f64::MAX }),
                theory_max_dt: th.and_then(|t| t.1),
                theory_verdict: th.map(|t| t.0),
                stable,
            })
        })
        .collect();
    pb.finish_and_clear();
    rows.into_iter().collect()
}
