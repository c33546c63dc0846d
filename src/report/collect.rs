//! The report's data source: runs a scene through every applicable integrator (compare), a
//! step-size sweep and a stability scan, using the core runner alone.
//!
//! This is the seam for `measure`: when its sweep/stability/compare API lands, the three
//! functions below delegate to it and keep returning [`SceneResults`]; nothing downstream
//! (charts, pages) changes. Until then the reference is `analytic` where it applies, else a
//! run of rk4 (or verlet_constraints for rigid rods) at a 16× smaller step, labelled a stand-in.

use super::results::*;
use super::sampler::{rms_error, Sampler};
use crate::error::{Error, Result};
use crate::integrate::{Integrator, IntegratorOptions};
use crate::model::{State, System, Vec3};
use crate::run::{energy_scale, run, RunPlan, Status};
use crate::scenario::Scenario;
use rayon::prelude::*;

/// How thorough a report pass is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollectOptions {
    /// Coarse pass (short runs, few sweep points) for tests and previews.
    pub quick: bool,
}

impl CollectOptions {
    fn samples(&self) -> u64 {
        if self.quick {
            120
        } else {
            250
        }
    }
    /// Particle-steps allowed for the finest run of a sweep (bounds the cost of big scenes).
    fn sweep_budget(&self) -> f64 {
        if self.quick {
            1e5
        } else {
            5e5
        }
    }
    /// Particle-steps allowed for the fine reference run of the comparison.
    fn reference_budget(&self) -> f64 {
        if self.quick {
            5e5
        } else {
            4e6
        }
    }
    fn sweep_factors(&self) -> Vec<f64> {
        if self.quick {
            vec![2.0, 1.0, 0.5]
        } else {
            vec![4.0, 2.0, 1.0, 0.5, 0.25, 0.125]
        }
    }
    /// The h·ω grid: geometric, finer for small scenes where runs are cheap.
    fn scan_thetas(&self, particles: usize) -> Vec<f64> {
        let (n, lo, hi): (usize, f64, f64) = if self.quick {
            (7, 0.1, 10.0)
        } else if particles < 100 {
            (29, 0.05, 20.0)
        } else {
            (13, 0.05, 20.0)
        };
        (0..n)
            .map(|k| lo * (hi / lo).powf(k as f64 / (n - 1) as f64))
            .collect()
    }
    /// Particle-steps allowed per stability-scan run.
    fn scan_budget(&self) -> u64 {
        if self.quick {
            2e4 as u64
        } else {
            1e5 as u64
        }
    }
}

/// Refinement of the stand-in reference relative to the compared step.
pub const REFERENCE_REFINEMENT: u64 = 16;

/// Textbook limit on h·ω for the undamped linear oscillator x'' = −ω²x: the largest step with
/// a non-growing amplification factor (Hairer, Lubich & Wanner, Geometric Numerical
/// Integration, §I.5; RK4's 2√2 from |R(iθ)| ≤ 1). `INFINITY`: A-stable; 0: never stable.
pub fn theory_limit(integrator: &str) -> Option<f64> {
    match integrator {
        "explicit_euler" | "rk2" => Some(0.0),
        "symplectic_euler" | "velocity_verlet" | "position_verlet" | "verlet_constraints" => {
            Some(2.0)
        }
        "rk4" => Some(2.0 * 2f64.sqrt()),
        "implicit_euler" | "analytic" => Some(f64::INFINITY),
        _ => None,
    }
}

/// Largest scene (particles) the report runs through the Rapier backends.
pub const RAPIER_MAX_PARTICLES: usize = 64;

/// The integrators a scene asks for (its `[run].integrators`, else every native one) plus the
/// Rapier backends on small scenes, each
/// created and checked; the ones that refuse are returned with their reason.
fn applicable(
    scene: &Scenario,
    sys: &System,
    opts: &IntegratorOptions,
) -> (Vec<String>, Vec<Skipped>) {
    let mut names: Vec<String> = if scene.run.integrators.is_empty() {
        crate::method::Registry::builtin()
            .native_names()
            .into_iter()
            .map(String::from)
            .collect()
    } else {
        scene.run.integrators.clone()
    };
    // Rapier joins every scene small enough for the report's time budget (a Rapier run of the
    // 32×32 cloth takes minutes); larger scenes list it as skipped, with the reason.
    let mut skipped = Vec::new();
    for ext in crate::method::Registry::builtin().engine_names() {
        if names.iter().any(|n| n == ext) {
            continue;
        }
        if scene.particles.len() <= RAPIER_MAX_PARTICLES {
            names.push(ext.to_string());
        } else {
            skipped.push(Skipped {
                backend: ext.to_string(),
                reason: format!(
                    "left out of the report: {} particles > {RAPIER_MAX_PARTICLES} (too slow for the report's budget); `springlab compare` runs it",
                    scene.particles.len()
                ),
            });
        }
    }
    // Creating and checking each backend is measure's `applicable`; one place decides.
    match crate::measure::case::applicable(&crate::method::Registry::builtin(), sys, &names, opts) {
        Ok((ok, refused)) => {
            skipped.extend(
                refused
                    .into_iter()
                    .map(|(backend, reason)| Skipped { backend, reason }),
            );
            (ok, skipped)
        }
        Err(e) => {
            skipped.extend(names.into_iter().map(|backend| Skipped {
                backend,
                reason: e.to_string(),
            }));
            (Vec::new(), skipped)
        }
    }
}

/// The registry's order as the report's interim integer (`u32::MAX`: exact).
fn order_of(name: &str) -> u32 {
    crate::method::Registry::builtin()
        .info(name)
        .ok()
        .and_then(|m| m.order.finite())
        .unwrap_or(u32::MAX)
}

fn make(name: &str, opts: &IntegratorOptions) -> Result<Box<dyn Integrator>> {
    crate::method::create(name, opts)
}

/// Reference methods for a scene in order of preference, with their refinement: analytic
/// when it applies (exact at any step), then rk4, then verlet_constraints run
/// `REFERENCE_REFINEMENT`× finer. The first whose run completes is used.
fn reference_candidates(sys: &System, opts: &IntegratorOptions) -> Result<Vec<(String, u64)>> {
    let mut out = Vec::new();
    for (name, sub) in [
        ("analytic", 1),
        ("rk4", REFERENCE_REFINEMENT),
        ("verlet_constraints", REFERENCE_REFINEMENT),
    ] {
        if make(name, opts)?.check(sys).is_ok() {
            out.push((name.to_string(), sub));
        }
    }
    if out.is_empty() {
        return Err(Error::Unsupported {
            integrator: "reference".into(),
            scenario: "?".into(),
            reason: "no reference method applies".into(),
        });
    }
    Ok(out)
}

fn reference_label(name: &str, sub: u64, what: &str) -> String {
    if sub == 1 {
        format!("{name} (exact closed form)")
    } else {
        format!("{name} at {what}/{sub}, a stand-in reference")
    }
}

/// Positions of every particle on a grid of `stride` steps of `dt`, from `name` run `sub`×
/// finer, and whether the run completed (samples stop where it blew up).
#[allow(clippy::too_many_arguments)]
fn reference_samples(
    sys: &System,
    s0: &State,
    name: &str,
    sub: u64,
    dt: f64,
    steps: u64,
    stride: u64,
    blowup_factor: f64,
    opts: &IntegratorOptions,
) -> Result<(Vec<Vec<Vec3>>, bool)> {
    let mut integ = make(name, opts)?;
    let mut plan = RunPlan::new(dt / sub as f64, steps * sub);
    plan.blowup_factor = blowup_factor;
    let mut obs = Sampler::new(stride * sub, plan.dt, None, &sys.free, &[], &[], true);
    let out = run(sys, integ.as_mut(), s0.clone(), &plan, &mut obs)?;
    Ok((obs.all, out.status.is_ok()))
}

/// The plane trajectories are drawn in, as [horizontal, vertical] axis indices: with gravity,
/// the vertical is the axis gravity points along and the horizontal the other axis the
/// reference spreads over most; without, the two axes of largest spread in x, y, z order.
fn main_plane(samples: &[Vec<Vec3>], gravity: Option<Vec3>) -> [usize; 2] {
    let mut var = [0.0f64; 3];
    for (a, v) in var.iter_mut().enumerate() {
        let vals = samples.iter().flatten().map(|x| x[a]);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for x in vals.filter(|x| x.is_finite()) {
            lo = lo.min(x);
            hi = hi.max(x);
        }
        *v = if hi >= lo { hi - lo } else { 0.0 };
    }
    if let Some(g) = gravity.filter(|g| g.norm() > 0.0) {
        let v = g.iamax();
        let h = (0..3)
            .filter(|&a| a != v)
            .max_by(|&a, &b| var[a].total_cmp(&var[b]).then(b.cmp(&a)))
            .unwrap_or(0);
        return [h, v];
    }
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| var[b].total_cmp(&var[a]).then(a.cmp(&b)));
    let mut p = [idx[0], idx[1]];
    p.sort();
    p
}

/// Up to two free particles with the longest reference paths.
fn tracked(samples: &[Vec<Vec3>], free: &[bool], blocks: bool) -> Vec<usize> {
    let n = free.len();
    let mut len = vec![0.0; n];
    for w in samples.windows(2) {
        for (p, l) in len.iter_mut().enumerate() {
            let d = (w[1][p] - w[0][p]).norm();
            if d.is_finite() {
                *l += d;
            }
        }
    }
    let mut idx: Vec<usize> = (0..n).filter(|&p| free[p]).collect();
    idx.sort_by(|&a, &b| len[b].total_cmp(&len[a]).then(a.cmp(&b)));
    idx.truncate(if blocks { 1 } else { 2 });
    idx.sort();
    idx
}

/// Collects compare, sweep and stability results for a scene (runs in parallel with rayon;
/// results are gathered in a fixed order, so every number but wall time is reproducible).
pub fn collect_scene(
    scene: &Scenario,
    dt: f64,
    steps: u64,
    opts: &CollectOptions,
) -> Result<SceneResults> {
    let iopts = IntegratorOptions::default();
    let sys = scene.build();
    let s0 = scene.initial_state();
    let plan = RunPlan::new(dt, steps);
    let (names, skipped) = applicable(scene, &sys, &iopts);
    let candidates = reference_candidates(&sys, &iopts)?;
    let stride = (steps / opts.samples()).max(1);
    let mut chosen = None;
    for (name, mut sub) in candidates.iter().cloned() {
        // Refine less on big scenes: the largest power of two within the reference budget.
        while sub > 2 && (sub * steps) as f64 * sys.len() as f64 > opts.reference_budget() {
            sub /= 2;
        }
        let (samples, ok) = reference_samples(
            &sys,
            &s0,
            &name,
            sub,
            dt,
            steps,
            stride,
            plan.blowup_factor,
            &iopts,
        )?;
        chosen = Some((name, sub, samples));
        if ok {
            break;
        }
    }
    let (ref_name, sub, refs) = chosen.expect("at least one reference candidate");
    let plane = main_plane(&refs, sys.gravity);
    let tracked = tracked(&refs, &sys.free, !scene.blocks.is_empty());
    let snapshot_steps: Vec<u64> = if scene.blocks.is_empty() {
        Vec::new()
    } else {
        vec![0, steps / 3, 2 * steps / 3, steps]
    };
    let runs: Vec<Result<RunRecord>> = names
        .par_iter()
        .map(|name| {
            let mut integ = make(name, &iopts)?;
            let mut obs = Sampler::new(
                stride,
                dt,
                Some(&refs),
                &sys.free,
                &tracked,
                &snapshot_steps,
                false,
            );
            let mut metrics = crate::measure::contacts::ContactMetrics::new(&sys, dt);
            let out = match metrics.as_mut() {
                Some(m) => run(&sys, integ.as_mut(), s0.clone(), &plan, &mut (&mut obs, m))?,
                None => run(&sys, integ.as_mut(), s0.clone(), &plan, &mut obs)?,
            };
            Ok(RunRecord {
                backend: integ.name().to_string(),
                order: order_of(integ.name()),
                status: out.status,
                steps_done: out.steps_done,
                force_evals: out.force_evals,
                wall_seconds: out.wall_seconds,
                samples: obs.samples,
                paths: obs.paths,
                snapshots: obs.snapshots,
                contacts: metrics.map(|m| m.report()),
            })
        })
        .collect();
    let runs = runs.into_iter().collect::<Result<Vec<_>>>()?;
    // Sweeps and scans cover the native integrators; external engines (Rapier) appear in the
    // comparison only, as their cost per run is far higher.
    let sweep_names: Vec<String> = names
        .iter()
        .filter(|n| {
            crate::method::Registry::builtin()
                .info(n)
                .is_ok_and(|m| !m.engine && m.order.finite().is_some())
        })
        .cloned()
        .collect();
    let sweep = if sweep_names.is_empty() {
        None
    } else {
        Some(sweep(
            &sys,
            &s0,
            dt,
            steps,
            &sweep_names,
            &candidates,
            opts,
            &iopts,
        )?)
    };
    let scan = scan(&sys, &s0, dt, steps, &sweep_names, opts, &iopts)?;
    Ok(SceneResults {
        scene: scene.name.clone(),
        description: scene.description.clone(),
        dt,
        steps,
        reference: reference_label(&ref_name, sub, "dt"),
        energy_scale: energy_scale(&sys, &s0),
        runs,
        skipped,
        sweep,
        scan,
        plane,
        tracked,
        blocks: scene.blocks.clone(),
    })
}

/// Runs every integrator at dt·f for each sweep factor f over a common duration and measures
/// the RMS position error at the end against the reference.
#[allow(clippy::too_many_arguments)]
fn sweep(
    sys: &System,
    s0: &State,
    dt: f64,
    steps: u64,
    names: &[String],
    candidates: &[(String, u64)],
    opts: &CollectOptions,
    iopts: &IntegratorOptions,
) -> Result<Sweep> {
    let factors = opts.sweep_factors();
    let coarse = dt * factors[0];
    let fine = dt * factors[factors.len() - 1];
    let n_part = sys.len().max(1) as f64;
    let wanted = (steps as f64 * dt).min(opts.sweep_budget() / n_part * fine);
    let n_coarse = ((wanted / coarse).round() as u64).max(1);
    let duration = n_coarse as f64 * coarse;
    // The reference: exact, or the reference method 4× finer than the finest sweep step;
    // the first candidate whose run completes.
    let ref_steps = (duration / fine).round() as u64;
    let mut chosen = None;
    for (name, sub) in candidates {
        let ref_sub = (*sub).min(4);
        let mut integ = make(name, iopts)?;
        let rplan = RunPlan::new(fine / ref_sub as f64, ref_steps * ref_sub);
        let rout = run(
            sys,
            integ.as_mut(),
            s0.clone(),
            &rplan,
            &mut crate::run::NoObserver,
        )?;
        let ok = rout.status.is_ok();
        chosen = Some((name.as_str(), ref_sub, rout.final_state.x, ok));
        if ok {
            break;
        }
    }
    let (ref_name, ref_sub, xref, ref_ok) = chosen.expect("at least one reference candidate");
    let jobs: Vec<(usize, usize)> = (0..names.len())
        .flat_map(|i| (0..factors.len()).map(move |k| (i, k)))
        .collect();
    let pts: Vec<Result<SweepPoint>> = jobs
        .par_iter()
        .map(|&(i, k)| {
            let h = dt * factors[k];
            let n = (duration / h).round() as u64;
            let mut integ = make(&names[i], iopts)?;
            let out = run(
                sys,
                integ.as_mut(),
                s0.clone(),
                &RunPlan::new(h, n),
                &mut crate::run::NoObserver,
            )?;
            let (error, blowup_time) = match &out.status {
                Status::Ok if ref_ok => {
                    (Some(rms_error(&out.final_state.x, &xref, &sys.free)), None)
                }
                Status::Ok => (None, None),
                Status::Unstable { time, .. } => (None, Some(*time)),
            };
            Ok(SweepPoint {
                dt: h,
                error,
                blowup_time,
                wall_seconds: out.wall_seconds,
                force_evals: out.force_evals,
            })
        })
        .collect();
    let mut pts = pts.into_iter();
    let mut lines = Vec::new();
    for name in names {
        let points = pts
            .by_ref()
            .take(factors.len())
            .collect::<Result<Vec<_>>>()?;
        lines.push(SweepLine {
            integrator: name.clone(),
            order: order_of(name),
            points,
        });
    }
    Ok(Sweep {
        duration,
        reference: reference_label(ref_name, ref_sub, "dt_min"),
        lines,
    })
}

/// An upper bound on the highest angular frequency of the linearised spring network
/// (Gershgorin's theorem on M⁻¹K): max over free i of Σ_{springs at i} k (1 + [other end free]) / m_i.
/// Exact for one anchored spring, two free masses and the long-chain limit.
pub fn omega_bound(sys: &System) -> Option<f64> {
    let n = sys.len();
    let mut row = vec![0.0; n];
    let sp = &sys.springs;
    for s in 0..sp.len() {
        let (i, j) = (sp.i[s] as usize, sp.j[s] as usize);
        let k = sp.k[s];
        let w = |other: usize| if sys.free[other] { 2.0 } else { 1.0 };
        row[i] += k * w(j);
        row[j] += k * w(i);
    }
    let w2 = (0..n)
        .filter(|&p| sys.free[p] && sys.inv_mass[p] > 0.0)
        .map(|p| row[p] * sys.inv_mass[p])
        .fold(0.0, f64::max);
    (w2 > 0.0 && w2.is_finite()).then(|| w2.sqrt())
}

/// Fewest steps of a stability-scan run (enough to tell growth from oscillation).
pub const MIN_SCAN_STEPS: u64 = 30;

/// Energy gain (fraction of the energy scale) below which growth is not called unstable.
pub const GROWTH_FLOOR: f64 = 0.01;

/// Watches the energy gain E(t) − E(0) in the first and last thirds of a run: a bounded
/// method's gain oscillates with a steady amplitude or decays (numerical damping is a loss,
/// not a gain); an unstable one's grows.
struct Growth {
    n: u64,
    e0: Option<f64>,
    first: f64,
    last: f64,
}

impl Growth {
    fn new(n: u64) -> Self {
        Growth {
            n,
            e0: None,
            first: 0.0,
            last: 0.0,
        }
    }
    /// True when the largest gain of the last third is more than twice that of the first
    /// third and more than [`GROWTH_FLOOR`] of the energy scale (growth of an energy error
    /// that stays small, as when a falling chain speeds up, is not called unstable).
    fn grows(&self, scale: f64) -> bool {
        self.last > 2.0 * self.first && self.last > GROWTH_FLOOR * scale
    }
}

impl crate::run::Observer for Growth {
    fn observe(&mut self, step: u64, _s: &State, e: &crate::run::EnergyRecord) -> Result<()> {
        let e0 = *self.e0.get_or_insert(e.total);
        let gain = e.total - e0;
        if 3 * step <= self.n {
            self.first = self.first.max(gain);
        } else if 3 * step >= 2 * self.n {
            self.last = self.last.max(gain);
        }
        Ok(())
    }
}

/// Runs every integrator at steps h = θ/ω over a θ grid (at least [`MIN_SCAN_STEPS`] steps,
/// else the scene's duration, capped by the budget); a cell is stable when the run did not
/// blow up and its energy gain did not grow (see `Growth`).
fn scan(
    sys: &System,
    s0: &State,
    dt: f64,
    steps: u64,
    names: &[String],
    opts: &CollectOptions,
    iopts: &IntegratorOptions,
) -> Result<Option<Scan>> {
    let Some(omega) = omega_bound(sys) else {
        return Ok(None);
    };
    if names.is_empty() {
        return Ok(None);
    }
    let thetas = opts.scan_thetas(sys.len());
    let duration = dt * steps as f64;
    let max_steps =
        (opts.scan_budget() / sys.len().max(1) as u64).max(if opts.quick { 40 } else { 100 });
    let jobs: Vec<(usize, usize)> = (0..names.len())
        .flat_map(|i| (0..thetas.len()).map(move |k| (i, k)))
        .collect();
    let cells: Vec<Result<(f64, f64, bool)>> = jobs
        .par_iter()
        .map(|&(i, k)| {
            let h = thetas[k] / omega;
            let n = ((duration / h).round() as u64).clamp(MIN_SCAN_STEPS, max_steps);
            let plan = RunPlan::new(h, n);
            let mut integ = make(&names[i], iopts)?;
            let mut growth = Growth::new(n);
            let out = run(sys, integ.as_mut(), s0.clone(), &plan, &mut growth)?;
            let scale = energy_scale(sys, s0);
            Ok((thetas[k], h, out.status.is_ok() && !growth.grows(scale)))
        })
        .collect();
    let mut cells = cells.into_iter();
    let mut rows = Vec::new();
    for name in names {
        rows.push(ScanRow {
            integrator: name.clone(),
            cells: cells
                .by_ref()
                .take(thetas.len())
                .collect::<Result<Vec<_>>>()?,
            theory: theory_limit(name),
        });
    }
    Ok(Some(Scan {
        omega,
        omega_note: "Gershgorin bound of the stiffest spring mode".into(),
        max_steps,
        rows,
    }))
}
