//! The stability map: every method over a grid of stiffness scales, damping scales and steps,
//! each cell a seeded run long enough that a spectral radius of [`RHO_SHOWN`] shows.

use super::theory::{rho, theory_limit, Limit, RHO_TOL};
use super::Verdict;
use crate::error::Result;
use crate::measure::modes::{modes, Modes};
use crate::method::{Method, StabilityTheory};
use crate::model::{State, System, Vec3};
use crate::run::{run, NoObserver, RunPlan};
use crate::scenario::Scenario;
use rayon::prelude::*;
use serde::Serialize;

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

/// Options of [`stability_map`].
#[derive(Debug, Clone)]
pub struct MapConfig {
    /// Methods, registry, options, blow-up factor, progress and budget: what every
    /// measuring command shares.
    pub common: crate::measure::Common,
    /// Multipliers of every spring stiffness (default 1/16 … 16, 9 points).
    pub stiffness_scales: Vec<f64>,
    /// Multipliers of every damper and of drag (default `[1]`).
    pub damping_scales: Vec<f64>,
    /// Steps as multiples of 1/ω_max of the unscaled scene (default 16 points in [0.02, 20]).
    pub h_omega: Vec<f64>,
    /// Absolute steps (s); when non-empty they replace `h_omega` (for maps spanning many
    /// decades of stiffness, where one relative axis cannot cover every scale).
    pub dts: Vec<f64>,
    /// Periods of the scaled ω_max per empirical run (default 50; at least [`MAP_MIN_STEPS`]
    /// and at most [`MAP_MAX_STEPS`] steps).
    pub periods: f64,
}

fn logspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a * (b / a).powf(i as f64 / (n.max(2) - 1) as f64))
        .collect()
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            stiffness_scales: logspace(1.0 / 16.0, 16.0, 9),
            damping_scales: vec![1.0],
            h_omega: logspace(0.02, 20.0, 16),
            dts: vec![],
            periods: 50.0,
            common: crate::measure::Common::default(),
        }
    }
}

/// One cell of `stability_map.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapRow {
    /// Method.
    pub method: String,
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
    /// The cell's verdict: the theory's at this step (its limit from the spectral radius)
    /// where linear theory applies and holds along the run, else the run's (see [`decide`]).
    pub stable: bool,
    /// Did the seeded run read ok?
    pub run_stable: bool,
    /// Which measure decided `stable`.
    pub decided_by: CellDecidedBy,
    /// Where the spectral radius and the run differ: why, and which one `stable` follows.
    pub note: String,
}

/// Which measure decided a map cell's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CellDecidedBy {
    /// The spectral radius of the linearised one-step map.
    SpectralRadius,
    /// The cell's seeded run.
    Run,
}

impl CellDecidedBy {
    /// `spectral_radius` or `run`, as the CSV spells it.
    pub fn name(self) -> &'static str {
        match self {
            CellDecidedBy::SpectralRadius => "spectral_radius",
            CellDecidedBy::Run => "run",
        }
    }
}

/// The header of `stability_map.csv`.
pub const MAP_HEADER: &str = "method,stiffness_scale,damping_scale,dt,omega_max,h_omega,spectral_radius,theory_max_dt,theory_verdict,stable,run_stable,decided_by,note";

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
            "{},{:e},{:e},{:e},{:e},{:e},{},{},{},{},{},{},\"{}\"",
            self.method,
            self.stiffness_scale,
            self.damping_scale,
            self.dt,
            self.omega_max,
            self.h_omega,
            o(self.spectral_radius),
            o(self.theory_max_dt),
            v,
            self.stable,
            self.run_stable,
            self.decided_by.name(),
            self.note.replace('"', "'")
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

/// The cells of the map, method by method, stiffness scale by stiffness scale, damping
/// scale by damping scale, step by step: (method, stiffness scale, damping scale, step).
/// Steps given as hω are divided by `w0`, the unscaled scene's ω_max.
fn cells_of(cfg: &MapConfig, names: &[String], w0: f64) -> Vec<(String, f64, f64, f64)> {
    let mut cells = Vec::new();
    for name in names {
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
    cells
}

/// What every cell of the map shares: the unscaled scene, the modes of each scaled one and
/// each method's theory there.
struct MapCells<'a> {
    /// The unscaled scene.
    scene: &'a Scenario,
    /// The map's options.
    cfg: &'a MapConfig,
    /// The unscaled scene's initial state, seeded per cell.
    s0: &'a State,
    /// The unscaled scene's ω_max (1 where it has none): the fallback of a scaled one.
    w0: f64,
    /// The methods mapped, by name.
    names: &'a [String],
    /// The methods mapped.
    methods: &'a [&'a Method],
    /// Each (stiffness scale, damping scale) pair with the modes of its scaled scene.
    pairs: &'a [(f64, f64, Modes)],
    /// Per method, per pair: the theory's verdict and limit, where linear theory applies.
    theory: &'a [Vec<Option<Limit>>],
}

impl MapCells<'_> {
    /// The cell of method `name` at stiffness scale `ks`, damping scale `cs` and step `dt`:
    /// its seeded run and, where linear theory applies, its spectral radius, then the verdict.
    fn row(&self, name: &str, ks: f64, cs: f64, dt: f64) -> Result<MapRow> {
        let cfg = self.cfg;
        let pi = self
            .pairs
            .iter()
            .position(|p| p.0 == ks && p.1 == cs)
            .expect("pair");
        let ms = &self.pairs[pi].2;
        let ni = self.names.iter().position(|n| n == name).expect("name");
        let th = self.theory[ni][pi];
        let w = if ms.omega_max > 0.0 {
            ms.omega_max
        } else {
            self.w0
        };
        let sc = scaled(self.scene, ks, cs);
        let sys = sc.build();
        let steps = ((cfg.periods * std::f64::consts::TAU / w / dt).ceil() as u64)
            .clamp(MAP_MIN_STEPS, MAP_MAX_STEPS);
        let method = self.methods[ni];
        let mut stepper = method.create(&cfg.common.options);
        let plan = RunPlan {
            dt,
            steps,
            substeps: 1,
            blowup_factor: cfg.common.blowup_factor,
            stop_at_verdict: true,
        };
        let out = run(
            &sys,
            &mut stepper,
            seeded(&sys, self.s0),
            &plan,
            &mut NoObserver,
        )?;
        let run_stable = out.status.is_ok();
        let radius = |ms: &Modes| {
            ms.modes
                .iter()
                .map(|&m| rho(method, &cfg.common.options, m, dt))
                .fold(0.0, f64::max)
        };
        let rho_max = th.map(|_| radius(ms));
        let theory_stable = th.map(|t| match t {
            (Verdict::UnconditionallyStable, _) => true,
            (Verdict::StableBelow, Some(limit)) => dt <= limit,
            _ => false,
        });
        let rho_end = || radius(&modes(&sys, &out.final_state));
        let (stable, decided_by, note) =
            decide(theory_stable.zip(rho_max), run_stable, steps, rho_end);
        Ok(MapRow {
            method: name.to_string(),
            stiffness_scale: ks,
            damping_scale: cs,
            dt,
            omega_max: ms.omega_max,
            h_omega: dt * ms.omega_max,
            spectral_radius: rho_max.map(|r| if r.is_finite() { r } else { f64::MAX }),
            theory_max_dt: th.and_then(|t| t.1),
            theory_verdict: th.map(|t| t.0),
            stable,
            run_stable,
            decided_by,
            note,
        })
    }
}

/// Sweeps stiffness × damping × dt: empirical stability of each cell with the theoretical
/// spectral radius and boundary alongside. Cells run in parallel, collected in order.
pub fn stability_map(scene: &Scenario, cfg: &MapConfig) -> Result<Vec<MapRow>> {
    let sys0 = scene.build();
    let s0 = scene.initial_state();
    let w0 = modes(&sys0, &s0).omega_max;
    let w0 = if w0 > 0.0 { w0 } else { 1.0 };
    let (names, _) = cfg.common.applicable(&sys0)?;
    // Exact methods are stable everywhere by construction: nothing to map.
    let methods: Vec<&Method> = names
        .iter()
        .map(|n| cfg.common.registry.get(n))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .filter(|m| m.info.stability != StabilityTheory::Unconditional)
        .collect();
    let names: Vec<String> = methods.iter().map(|m| m.info.name.to_string()).collect();
    let cells = cells_of(cfg, &names, w0);
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
                        .then(|| theory_limit(method, &cfg.common.options, m))
                })
                .collect()
        })
        .collect();
    let shared = MapCells {
        scene,
        cfg,
        s0: &s0,
        w0,
        names: &names,
        methods: &methods,
        pairs: &pairs,
        theory: &theory,
    };
    let pb = crate::run::progress_bar(
        cells.len() as u64,
        &format!("stability map {}", scene.name),
        cfg.common.progress,
    );
    let rows: Vec<Result<MapRow>> = cells
        .par_iter()
        .map(|(name, ks, cs, dt)| {
            let row = shared.row(name, *ks, *cs, *dt)?;
            pb.inc(1);
            Ok(row)
        })
        .collect();
    pb.finish_and_clear();
    rows.into_iter().collect()
}

/// A cell's verdict from its theory at t = 0 (`theory`: whether the step is within the theory
/// limit, and the spectral radius there; `None` without linear theory),
/// its seeded run's verdict over `steps` steps, and the radius on the linearisation at the
/// run's last state (`rho_end`, computed only where needed): (stable, decided by, note).
///
/// Where they agree, or without theory, there is nothing to say. Where the radius says growth
/// and the run stayed bounded, the radius decides if the scene still has it at the run's end
/// (the growth was too slow, or seeded too small, to show in the run: the mode grows without
/// bound all the same), and the run decides if it does not (the scene moved to where its
/// linearisation is stable: the radius at t = 0 did not hold along the run). Where the radius
/// says bounded and the run grew, the run decides: growth was seen, so the linearisation at
/// t = 0 did not hold along the run (a nonlinear scene).
pub fn decide(
    theory: Option<(bool, f64)>,
    run_stable: bool,
    steps: u64,
    rho_end: impl FnOnce() -> f64,
) -> (bool, CellDecidedBy, String) {
    let Some((theory_stable, r0)) = theory else {
        return (run_stable, CellDecidedBy::Run, String::new());
    };
    if theory_stable == run_stable {
        return (theory_stable, CellDecidedBy::SpectralRadius, String::new());
    }
    if theory_stable {
        return (
            false,
            CellDecidedBy::Run,
            format!("the run grew although ρ = {r0:.6} ≤ 1 at t = 0: the linearisation at t = 0 does not hold along the run"),
        );
    }
    let r1 = rho_end();
    if r1 > 1.0 + RHO_TOL {
        let growth = r0.powf(2.0 * steps as f64);
        (
            false,
            CellDecidedBy::SpectralRadius,
            format!("the run stayed bounded over {steps} steps but ρ = {r0:.6} at t = 0 and {r1:.6} at its end: a mode grows without bound (×{growth:.3e} in energy over the run at ρ(t = 0), from a seed too small or a growth too slow to pass the verdict's thresholds)"),
        )
    } else {
        (
            true,
            CellDecidedBy::Run,
            format!("ρ = {r0:.6} at t = 0 but {r1:.6} at the run's end, which stayed bounded: the scene moved away from the linearisation at t = 0"),
        )
    }
}
