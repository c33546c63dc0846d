//! Reference solutions, each knowing its own error.
//!
//! Which reference a scene gets:
//! - **closed form** (`analytic`) when the scene has one (independent damped linear
//!   oscillators, no obstacles): exact to round-off, uncertainty at the round-off level, no
//!   predictability horizon;
//! - **DOP853** (`dop853`, `dop853_constrained`) at rtol = atol = 1e-12 with dense output
//!   otherwise: rigid constraints by index reduction and projection (`rhs.rs`); impulses restart
//!   the solver at their times; obstacles as the scene defines them ([`contacts`]): `impulse`
//!   contacts as impacts located on the dense output and resolved by the scene's own impulse
//!   law, Zeno sequences and resting or sliding contact as a unilateral constraint with
//!   Coulomb friction; `penalty` contacts are a force term the right-hand side already
//!   contains, integrated like any stiff force (the step-size control resolves each contact);
//! - **converged fine steps** (`fine_step`) for the `projection` response, which has no
//!   continuous counterpart ([`finestep`]).
//!
//! Every reference measures its own error ([`uncertainty`]): a looser and a perturbed
//! companion solve give a per-sample [`Reference::uncertainty_at`], its maximum
//! ([`ReferenceInfo::uncertainty`]) and the [`ReferenceInfo::predictability_horizon`]. An
//! error at or below [`Reference::floor_at`] is at the reference floor: the reference cannot
//! tell it from zero.
//!
//! The adaptive solve is made once per scene and horizon and kept with its dense output
//! (`solution`, within a memory budget), and so is the fine-step hierarchy (`fine_kept`, its
//! last two levels whole); a [`Reference`] samples it at the times of its grids (a whole sweep
//! at once) and stores only positions there, so a new grid costs no new solve.
//!
//! Between commands, a computed reference and ensemble are kept in the reference store
//! ([`store`], when in use): a later command asking for the same reference reads it back,
//! the same bits, instead of solving.

mod adaptive;
mod contact_events;
pub mod contacts;
pub mod cost;
mod dense;
mod ensemble;
mod fine_kept;
mod fine_level;
pub mod finestep;
pub mod period;
mod rhs;
mod solution;
pub mod store;
mod stored;
mod tracked;
pub mod uncertainty;

use crate::collide::Response;
use crate::error::{Error, Result};
use crate::integrate::{Analytic, Stepper};
use crate::measure::grid::TimeGrid;
use crate::measure::observables::position_error;
use crate::model::{State, System, Vec3};
use adaptive::{length_scale, solve, SolveSpec};
use rhs::unpack_x;
use serde::Serialize;

pub use period::{dominant_period, period_of, DOMINANT_MODE_UNCLEAR};

pub use adaptive::REFERENCE_TOL;
pub use tracked::{tracked_component, Tracked};

/// Which solution a reference is (documents spell it in snake case).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReferenceKind {
    /// The closed form of independent damped linear oscillators.
    Analytic,
    /// DOP853 on the scene's ODE.
    Dop853,
    /// DOP853 on the index-1 DAE of a scene with rods.
    Dop853Constrained,
    /// rk4 with the scene's contact stage at successively halved fixed steps.
    FineStep,
}

impl ReferenceKind {
    /// `analytic`, `dop853`, `dop853_constrained` or `fine_step`.
    pub fn name(self) -> &'static str {
        match self {
            ReferenceKind::Analytic => "analytic",
            ReferenceKind::Dop853 => "dop853",
            ReferenceKind::Dop853Constrained => "dop853_constrained",
            ReferenceKind::FineStep => "fine_step",
        }
    }
}

impl std::fmt::Display for ReferenceKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// Which reference was used, recorded in every output.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ReferenceInfo {
    /// Which solution it is.
    pub kind: ReferenceKind,
    /// One sentence: what it is and how accurate it is.
    pub description: String,
    /// Relative tolerance (adaptive kinds), else 0.
    pub rtol: f64,
    /// Absolute tolerance (adaptive kinds), else 0.
    pub atol: f64,
    /// Accepted steps of the adaptive solver (0 for analytic).
    pub solver_steps: u64,
    /// Rejected steps.
    pub solver_rejected: u64,
    /// Right-hand side evaluations.
    pub solver_evals: u64,
    /// Restarts at impulses.
    pub restarts: usize,
    /// End time of the reference (s).
    pub horizon: f64,
    /// The reference's own position error (m), kept for callers of the single-number floor:
    /// equal to [`ReferenceInfo::uncertainty`]. Errors below ~10× this are the measurement
    /// floor, excluded from order fits.
    pub accuracy: f64,
    /// Measured uncertainty of the reference positions (m): the largest over the sample times
    /// of max(|main − looser solve|, |main − perturbed solve|), at least the solver's
    /// tolerance × the length scale (round-off for the closed form); infinite (null in JSON)
    /// only when both companion solves were abandoned over their work budget.
    #[serde(default)]
    pub uncertainty: f64,
    /// First sample time (s) at which a round-off-sized perturbation of the initial positions
    /// has grown past `predictability_threshold`; null when the whole horizon is predictable.
    #[serde(default)]
    pub predictability_horizon: Option<f64>,
    /// The departure that ends the predictable range (m): 1e-6 × the motion scale.
    #[serde(default)]
    pub predictability_threshold: f64,
    /// How the uncertainty was measured, in one sentence.
    #[serde(default)]
    pub uncertainty_measured_by: String,
    /// Obstacle impacts located and applied (adaptive reference with impulse contacts).
    #[serde(default)]
    pub impacts: u64,
    /// Times a particle went into held (resting or sliding) contact.
    #[serde(default)]
    pub holds: u64,
    /// Largest displacement of any particle from its initial position over the horizon (m):
    /// the scene's motion scale ([`Reference::motion_scale`]), which default tolerances are
    /// relative to.
    #[serde(default)]
    pub motion_scale: f64,
    /// How the ensemble past the predictability horizon was made, or why there is none; null
    /// when none was asked for or the whole horizon is predictable.
    #[serde(default)]
    pub ensemble: Option<String>,
}

/// How to compute the reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceSolver {
    /// The closed form when the scene has one, else the adaptive solver.
    Auto,
    /// Always the adaptive solver (DOP853, constrained where needed).
    Adaptive,
}

/// Reference positions at the sample times of a set of grids, plus the upward zero
/// crossings of one velocity component (for period and phase).
#[derive(Debug, Clone)]
pub struct Reference {
    /// Which reference this is.
    pub info: ReferenceInfo,
    /// The grids it was sampled on.
    pub grids: Vec<TimeGrid>,
    samples: Vec<Vec<Vec<Vec3>>>,
    /// Tracked velocity component (None when nothing moves).
    pub tracked: Option<Tracked>,
    /// Times where the tracked velocity crosses zero upwards.
    pub crossings: Vec<f64>,
    /// Times where it crosses zero downwards: with `crossings`, they show whether one mode
    /// dominates even over two periods ([`period`]).
    pub down_crossings: Vec<f64>,
    motion: f64,
    /// Per grid, per compared step: the measured uncertainty (m).
    unc: Vec<Vec<f64>>,
    /// The ensemble past the predictability horizon, once [`Reference::add_ensemble`] made it.
    pub ensemble: Option<crate::measure::statistics::Ensemble>,
    /// How an ensemble member is solved: the reference's own solver.
    member_solver: Option<ensemble::MemberSolver>,
    /// Per grid, per sample: the largest strain of the reference's states up to that sample,
    /// computed once for every run compared on the grid ([`Reference::strain_max_until`]).
    strain_until: Vec<std::sync::OnceLock<Vec<f64>>>,
    /// The kept adaptive solve this reference was sampled from ([`Reference::solve_id`]).
    solve_id: Option<u64>,
    /// Modelled seconds its solves may take ([`Reference::compute_within`]); None: no limit.
    limit: Option<f64>,
}

/// True when the scene has a closed form (the `analytic` method accepts it).
pub fn has_closed_form(sys: &System) -> bool {
    Analytic::default().check(sys).is_ok()
}

struct Entry {
    t: f64,
    grid: usize,
    idx: usize,
}

fn entries(grids: &[TimeGrid]) -> Vec<Entry> {
    let mut e = Vec::new();
    for (g, grid) in grids.iter().enumerate() {
        for (idx, n) in grid.sample_steps().enumerate() {
            e.push(Entry {
                t: grid.time(n),
                grid: g,
                idx,
            });
        }
    }
    e.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.grid.cmp(&b.grid)));
    e
}

impl Reference {
    /// Computes the reference of `sys` from `s0` at every sample time of `grids`, integrating
    /// to `horizon` (≥ every sample time; pass the same horizon for every shard of a sweep so
    /// the solver takes the same steps).
    pub fn compute(sys: &System, s0: &State, grids: &[TimeGrid], horizon: f64) -> Result<Self> {
        Self::compute_with(sys, s0, grids, horizon, ReferenceSolver::Auto)
    }

    /// As [`Reference::compute`], its solves held to `limit` modelled seconds ([`cost`]): an
    /// adaptive solve that needs more stops with an error naming `--budget`. `None`: no limit.
    pub fn compute_within(
        sys: &System,
        s0: &State,
        grids: &[TimeGrid],
        horizon: f64,
        limit: Option<f64>,
    ) -> Result<Self> {
        Self::compute_limited(sys, s0, grids, horizon, ReferenceSolver::Auto, limit)
    }

    /// As [`Reference::compute`], choosing the method explicitly.
    pub fn compute_with(
        sys: &System,
        s0: &State,
        grids: &[TimeGrid],
        horizon: f64,
        solver: ReferenceSolver,
    ) -> Result<Self> {
        Self::compute_limited(sys, s0, grids, horizon, solver, None)
    }

    /// The reference of `sys` from `s0` on `grids`: read from the reference store when it
    /// holds it ([`store`]), else computed, and then written there unless a closed form.
    fn compute_limited(
        sys: &System,
        s0: &State,
        grids: &[TimeGrid],
        horizon: f64,
        solver: ReferenceSolver,
        limit: Option<f64>,
    ) -> Result<Self> {
        let horizon = entries(grids).last().map_or(horizon, |e| e.t.max(horizon));
        let key =
            store::dir().map(|_| stored::reference_key(sys, s0, grids, horizon, solver, limit));
        if let Some(r) = key
            .as_deref()
            .and_then(|k| stored::load_reference(k, limit))
        {
            return Ok(r);
        }
        let tracked = tracked_component(sys, s0);
        let samples = grids
            .iter()
            .map(|g| vec![Vec::new(); g.sample_count()])
            .collect();
        let mut r = Reference {
            info: ReferenceInfo {
                // Set by the solve that fills the samples.
                kind: ReferenceKind::Dop853,
                description: String::new(),
                rtol: 0.0,
                atol: 0.0,
                solver_steps: 0,
                solver_rejected: 0,
                solver_evals: 0,
                restarts: 0,
                horizon,
                accuracy: 0.0,
                uncertainty: 0.0,
                predictability_horizon: None,
                predictability_threshold: 0.0,
                uncertainty_measured_by: String::new(),
                impacts: 0,
                holds: 0,
                motion_scale: 0.0,
                ensemble: None,
            },
            grids: grids.to_vec(),
            strain_until: grids.iter().map(|_| std::sync::OnceLock::new()).collect(),
            samples,
            tracked,
            crossings: Vec::new(),
            down_crossings: Vec::new(),
            motion: 0.0,
            unc: grids.iter().map(|g| vec![0.0; g.sample_count()]).collect(),
            ensemble: None,
            member_solver: None,
            solve_id: None,
            limit,
        };
        if solver == ReferenceSolver::Auto
            && has_closed_form(sys)
            && r.fill_analytic(sys, s0).is_ok()
        {
            r.info.motion_scale = r.motion_scale();
            return Ok(r);
        }
        r.crossings.clear();
        r.down_crossings.clear();
        r.motion = 0.0;
        let projection =
            crate::collide::of(sys).is_some_and(|c| c.response == Response::Projection);
        if projection {
            r.fill_fine_step(sys, s0)?;
        } else {
            r.fill_dop853(sys, s0)?;
        }
        r.info.accuracy = r.info.uncertainty;
        r.info.motion_scale = r.motion_scale();
        if let Some(k) = &key {
            stored::save_reference(k, &r);
        }
        Ok(r)
    }

    /// Takes `e`, an ensemble already made for this scene over the same run, judged at position
    /// tolerance `tolerance` (m): how one study or advice pays for its ensemble once.
    pub fn use_ensemble(&mut self, e: &crate::measure::statistics::Ensemble, tolerance: f64) {
        let mut e = e.clone();
        e.tolerance = tolerance;
        e.relative_tolerance = tolerance / self.motion_scale();
        self.info.ensemble = Some(e.made_by.clone());
        self.ensemble = Some(e);
    }

    /// Adds the scene's ensemble ([`crate::measure::statistics`]) when this reference has a
    /// predictability horizon before its end, its floors from the position tolerance
    /// `tolerance` (m). The members are the scene's, made on `scene_grid` (the scene's own step
    /// over the horizon, [`crate::measure::grid::scene_grid`]): by this reference when it was
    /// sampled on exactly that grid, else by a reference computed on it. So every command that
    /// judges a scene by statistics judges against the same members, whatever steps it
    /// compares, and a document's command re-creates them. Where the members cannot finish,
    /// [`ReferenceInfo::ensemble`] says why and there is no ensemble.
    pub fn add_ensemble(
        &mut self,
        sys: &System,
        s0: &State,
        tolerance: f64,
        scene_grid: TimeGrid,
    ) -> Result<()> {
        if self.ensemble_window().is_none() {
            return Ok(());
        }
        if self.grids == [scene_grid] {
            return self.add_own_ensemble(sys, s0, tolerance, scene_grid);
        }
        let horizon = scene_grid.time(scene_grid.steps);
        let mut scene = Reference::compute_within(sys, s0, &[scene_grid], horizon, self.limit)?;
        scene.add_own_ensemble(sys, s0, tolerance, scene_grid)?;
        match scene.ensemble {
            Some(e) => self.use_ensemble(&e, tolerance),
            None => {
                self.info.ensemble = Some(scene.info.ensemble.unwrap_or_else(|| {
                    "no ensemble: the reference at the scene's own step is predictable over the whole run".into()
                }))
            }
        }
        Ok(())
    }

    /// The ensemble's window start and member solver, when positions are predictable only up
    /// to a horizon before the end and the reference knows how to make members.
    fn ensemble_window(&self) -> Option<(f64, ensemble::MemberSolver)> {
        let (Some(start), Some(solver)) = (self.info.predictability_horizon, self.member_solver)
        else {
            return None;
        };
        (start < self.info.horizon).then_some((start, solver))
    }

    /// The ensemble from this reference's own predictability horizon to its end, made with
    /// its member solver; `grid` is the scene grid this reference was sampled on.
    fn add_own_ensemble(
        &mut self,
        sys: &System,
        s0: &State,
        tolerance: f64,
        grid: TimeGrid,
    ) -> Result<()> {
        let Some((start, solver)) = self.ensemble_window() else {
            return Ok(());
        };
        let end = self.info.horizon;
        let relative = tolerance / self.motion_scale();
        if let (Some(limit), ensemble::MemberSolver::FineStep { h }) = (self.limit, solver) {
            // Each member runs from the start, not from the window.
            let each = cost::fine_run_seconds(sys, s0, h, end);
            let all = each * crate::measure::statistics::ENSEMBLE_SIZE as f64;
            if all > limit {
                self.info.ensemble = Some(format!(
                    "no ensemble: its {} fine-step members would take about {} s of modelled work, beyond the {} s the budget leaves the reference; `--budget` raises it",
                    crate::measure::statistics::ENSEMBLE_SIZE,
                    crate::measure::probe::sig3(all),
                    crate::measure::probe::sig3(limit)
                ));
                return Ok(());
            }
        }
        match ensemble::ensemble(sys, s0, start, end, solver, tolerance, relative)? {
            Ok(mut e) => {
                e.grid = Some(grid);
                self.info.ensemble = Some(e.made_by.clone());
                self.ensemble = Some(e);
            }
            Err(why) => self.info.ensemble = Some(format!("no ensemble: {why}")),
        }
        Ok(())
    }

    /// Measured uncertainty of the reference positions at step `n` of grid `g` (m); between
    /// compared steps, the larger of the two neighbouring samples'.
    pub fn uncertainty_at(&self, g: usize, n: u64) -> f64 {
        let grid = &self.grids[g];
        let u = &self.unc[g];
        if let Some(i) = grid.sample_index(n) {
            return u[i];
        }
        let i = (n / grid.stride) as usize;
        let lo = u.get(i).copied().unwrap_or(0.0);
        let hi = u.get(i + 1).copied().unwrap_or(lo);
        lo.max(hi)
    }

    /// The reference floor at step `n` of grid `g` (m): a measured error at or below it cannot
    /// be told from zero (it is the reference's measured uncertainty there). Callers report
    /// such an error as "at the reference floor" and keep it out of order fits.
    pub fn floor_at(&self, g: usize, n: u64) -> f64 {
        self.uncertainty_at(g, n)
    }

    /// True when `error` (m) at step `n` of grid `g` is at the reference floor.
    pub fn at_floor(&self, g: usize, n: u64, error: f64) -> bool {
        error <= self.floor_at(g, n)
    }

    /// Which kept solve (adaptive, or fine-step hierarchy) this reference was sampled from:
    /// references of one scene and horizon on any grids share one; None when it solved on its
    /// own grids (closed form, or a solve too big to keep).
    pub fn solve_id(&self) -> Option<u64> {
        self.solve_id
    }

    /// True when time `t` (s) lies within the predictable range.
    pub fn predictable_at(&self, t: f64) -> bool {
        self.info.predictability_horizon.is_none_or(|h| t < h)
    }

    /// Stores per-entry values (entry order of [`entries`]) into the per-grid layout.
    fn set_uncertainty(&mut self, ents: &[Entry], per_entry: &[f64]) {
        for (e, &u) in ents.iter().zip(per_entry) {
            self.unc[e.grid][e.idx] = u;
        }
        self.info.uncertainty = per_entry.iter().copied().fold(0.0, f64::max);
    }

    /// Reference positions at step `n` of grid `g` (None when `n` is not a sample step).
    pub fn positions(&self, g: usize, n: u64) -> Option<&[Vec3]> {
        let i = self.grids[g].sample_index(n)?;
        self.samples[g].get(i).map(|v| v.as_slice())
    }

    /// The largest strain ([`crate::measure::observables::strain_max`]) of the reference's
    /// states on grid `g` from its first sample up to the one of step `n` (None off the
    /// samples), for `sys`, the system the reference solves. Every run compared on the grid
    /// reads the same running maximum, so it is computed once per grid.
    pub fn strain_max_until(&self, sys: &System, g: usize, n: u64) -> Option<f64> {
        let i = self.grids[g].sample_index(n)?;
        let running = self.strain_until[g].get_or_init(|| {
            let mut m = 0.0_f64;
            self.samples[g]
                .iter()
                .map(|x| {
                    if x.len() == sys.len() {
                        m = m.max(crate::measure::observables::strain_max(sys, x));
                    }
                    m
                })
                .collect()
        });
        running.get(i).copied()
    }

    /// Largest displacement of any particle from its initial position over the horizon (m),
    /// or 1 when nothing moves: the scale errors are judged against. It is measured on the
    /// solver's own steps (or a fixed grid for the closed form), so it does not depend on the
    /// requested sample times (shards of one sweep agree).
    pub fn motion_scale(&self) -> f64 {
        if self.motion > 0.0 {
            self.motion
        } else {
            1.0
        }
    }

    /// Period of the tracked component from its crossings (None with fewer than two).
    pub fn period(&self) -> Option<f64> {
        period_of(&self.crossings)
    }

    /// The tracked component's period when its crossings show one dominant mode, else why not
    /// ([`period`] module docs): what run periods and phases are measured against.
    pub fn dominant_period(&self) -> std::result::Result<f64, &'static str> {
        dominant_period(&self.crossings, &self.down_crossings)
    }

    fn fill_analytic(&mut self, sys: &System, s0: &State) -> std::result::Result<(), String> {
        // State at time t from a segment start, exactly (a fresh closed form from there).
        let eval = |start: &State, t: f64| -> std::result::Result<State, String> {
            let mut s = start.clone();
            if t > start.t {
                let mut a = Analytic::default();
                a.step(sys, &mut s, t - start.t)
                    .map_err(|e| e.to_string())?;
            }
            s.t = t;
            Ok(s)
        };
        let horizon = self.info.horizon;
        // Segment starts: the initial state, then the state just after each impulse.
        let mut starts = vec![s0.clone()];
        let mut ends = Vec::new();
        for im in sys.impulses.iter().filter(|im| im.time < horizon) {
            let prev = starts.last().expect("one start");
            let mut s = eval(prev, im.time)?;
            s.v[im.particle] += im.delta_v;
            ends.push(im.time);
            starts.push(s);
        }
        ends.push(horizon);
        // The motion scale on a fixed grid of each segment (independent of the sample times).
        for (seg, start) in starts.iter().enumerate() {
            let (t0, t1) = (start.t, ends[seg]);
            let n = ((t1 - t0) / horizon * ANALYTIC_MOTION_POINTS)
                .ceil()
                .max(16.0) as u64;
            for k in 0..=n {
                let s = eval(start, t0 + (t1 - t0) * k as f64 / n as f64)?;
                for (a, b) in s.x.iter().zip(&s0.x) {
                    self.motion = self.motion.max((a - b).norm());
                }
            }
        }
        for e in entries(&self.grids) {
            // Impulse at τ acts on times > τ (the runner samples the pre-impulse state at τ).
            let seg = ends
                .iter()
                .position(|&end| e.t <= end)
                .unwrap_or(ends.len() - 1);
            let s = eval(&starts[seg], e.t)?;
            self.samples[e.grid][e.idx] = s.x;
        }
        if let Some(tr) = self.tracked {
            // Scan each segment finely for sign changes, then bisect on the closed form.
            for (seg, start) in starts.iter().enumerate() {
                let (t0, t1) = (start.t, ends[seg]);
                let n = ((t1 - t0) / horizon * 200_000.0).ceil().max(16.0) as u64;
                let vel = |t: f64| eval(start, t).map(|s| s.v[tr.particle][tr.axis]);
                let mut prev = (t0, vel(t0)?);
                for k in 1..=n {
                    let t = t0 + (t1 - t0) * k as f64 / n as f64;
                    let v = vel(t)?;
                    let up = prev.1 < 0.0 && v >= 0.0;
                    if up || (prev.1 >= 0.0 && v < 0.0) {
                        // Bisect on the sign the crossing leaves behind.
                        let (mut a, mut b) = (prev.0, t);
                        for _ in 0..60 {
                            let m = 0.5 * (a + b);
                            if (vel(m)? < 0.0) == up {
                                a = m
                            } else {
                                b = m
                            }
                        }
                        let c = 0.5 * (a + b);
                        if up {
                            self.crossings.push(c);
                        } else {
                            self.down_crossings.push(c);
                        }
                    }
                    prev = (t, v);
                }
            }
        }
        self.info.kind = ReferenceKind::Analytic;
        self.info.description =
            "closed-form solution of independent damped linear oscillators (exact to round-off)"
                .into();
        let floor = ROUND_OFF * length_scale(s0);
        for u in &mut self.unc {
            u.fill(floor);
        }
        self.info.uncertainty = floor;
        self.info.uncertainty_measured_by =
            "round-off of the closed form (1e-14 x the length scale); no chaos: linear".into();
        Ok(())
    }

    fn fill_dop853(&mut self, sys: &System, s0: &State) -> Result<()> {
        let ents = entries(&self.grids);
        let times: Vec<f64> = ents.iter().map(|e| e.t).collect();
        let horizon = self.info.horizon;
        // Never below the tolerance the solver was asked for.
        let floor = REFERENCE_TOL * length_scale(s0);
        let limit = self.limit.map(|s| cost::dop853_step_limit(sys, s));
        let kept = solution::shared(sys, s0, horizon, REFERENCE_TOL, self.tracked, limit)?;
        let (main, out, comp) = match &kept {
            Some(sol) => {
                self.solve_id = Some(sol.id);
                self.motion = sol.out.motion;
                let (main, interp): (Vec<Vec<Vec3>>, Vec<f64>) =
                    times.iter().map(|&t| sol.main.sample(t)).unzip();
                let distances = |track: &Option<dense::DenseTrack>| {
                    track.as_ref().map(|tr| {
                        times
                            .iter()
                            .zip(&main)
                            .map(|(&t, x)| position_error(&tr.positions(t), x))
                            .collect::<Vec<f64>>()
                    })
                };
                let mut comp = uncertainty::judge(
                    &times,
                    distances(&sol.loose),
                    distances(&sol.perturbed),
                    floor,
                    self.motion_scale(),
                );
                // A sample inside a step carries the interpolant's error estimate (`dense`).
                for (u, e) in comp.uncertainty.iter_mut().zip(&interp) {
                    *u += e;
                }
                (main, sol.out.clone(), comp)
            }
            None => self.solve_on_grids(sys, s0, &times, floor, limit)?,
        };
        self.crossings = out.crossings;
        self.down_crossings = out.down_crossings;
        self.member_solver = Some(ensemble::dop853_members(
            out.stats.steps + out.stats.rejected,
        ));
        for (e, x) in ents.iter().zip(main) {
            self.samples[e.grid][e.idx] = x;
        }
        self.set_uncertainty(&ents, &comp.uncertainty);
        self.info.predictability_horizon = comp.horizon;
        self.info.predictability_threshold = comp.threshold;
        self.info.uncertainty_measured_by = format!(
            "larger of the distances to a solve at {:e} x the tolerance and to a solve from initial positions moved by {:e} x the length scale{}{}",
            uncertainty::LOOSE_FACTOR,
            uncertainty::PERTURBATION,
            if kept.is_some() { ", plus the dense output's own error estimate at samples inside a solver step" } else { "" },
            comp.note
        );
        self.info.solver_steps = out.stats.steps;
        self.info.solver_rejected = out.stats.rejected;
        self.info.solver_evals = out.stats.evals;
        self.info.restarts = out.restarts;
        self.info.impacts = out.impacts;
        self.info.holds = out.holds;
        self.info.rtol = REFERENCE_TOL;
        self.info.atol = REFERENCE_TOL;
        let rigid = sys
            .constraints
            .iter()
            .filter(|c| c.compliance == 0.0)
            .count();
        let contacts = match crate::collide::of(sys).map(|c| c.response) {
            Some(Response::Impulse) => ", impulse contacts as impacts located on the dense output (scene restitution and Coulomb friction impulse) and as held unilateral contact with Coulomb friction once bounces fall below the tolerance",
            Some(Response::Penalty { .. }) => ", penalty contact forces integrated as a force term",
            _ => "",
        };
        if rigid == 0 {
            self.info.kind = ReferenceKind::Dop853;
            self.info.description = format!("adaptive Dormand-Prince 8(5,3) (DOP853) at rtol = atol = 1e-12 with 7th-order dense output, restarted at each impulse{contacts}");
        } else {
            self.info.kind = ReferenceKind::Dop853Constrained;
            self.info.description = format!("DOP853 at rtol = atol = 1e-12 on the index-reduced equations of motion ({rigid} rigid constraint(s) enforced at acceleration level by Lagrange multipliers), positions and velocities projected onto the constraint manifold after every step{contacts}");
        }
        Ok(())
    }

    /// The main solve and its companions run on the sample `times` (a scene whose kept solve
    /// would not fit in memory): positions, what the solve did, the companions' verdict.
    fn solve_on_grids(
        &mut self,
        sys: &System,
        s0: &State,
        times: &[f64],
        floor: f64,
        limit: Option<cost::StepLimit>,
    ) -> Result<(Vec<Vec<Vec3>>, adaptive::SolveOut, uncertainty::Companions)> {
        let n = sys.len();
        let horizon = self.info.horizon;
        let mut main: Vec<Vec<Vec3>> = vec![Vec::new(); times.len()];
        let spec = SolveSpec {
            sys,
            s0,
            times,
            horizon,
            rtol: REFERENCE_TOL,
            tracked: self.tracked,
            max_steps: limit.map(|l| l.steps),
        };
        let out = solve(&spec, &mut |i, y| main[i] = unpack_x(y, n), None)?;
        let Some(out) = out else {
            return Err(limit.map_or_else(
                || Error::Step("reference (DOP853): stopped without a step limit".into()),
                |l| l.error(horizon),
            ));
        };
        self.motion = out.motion;
        let companion = SolveSpec {
            tracked: None,
            max_steps: Some(
                uncertainty::COMPANION_WORK_FACTOR
                    * (out.stats.steps + out.stats.rejected).max(100),
            ),
            ..spec
        };
        let comp = uncertainty::companions(&companion, &main, floor, self.motion_scale())?;
        Ok((main, out, comp))
    }

    fn fill_fine_step(&mut self, sys: &System, s0: &State) -> Result<()> {
        let ents = entries(&self.grids);
        let times: Vec<f64> = ents.iter().map(|e| e.t).collect();
        let floor = ROUND_OFF * length_scale(s0);
        let kept = fine_kept::shared(sys, s0, self.info.horizon)?;
        let fine = match &kept {
            Some(h) => {
                self.solve_id = Some(h.id);
                h.sample(sys, &times, floor)?
            }
            None => {
                let h0 = 0.5
                    * self
                        .grids
                        .iter()
                        .map(|g| g.dt)
                        .fold(f64::INFINITY, f64::min);
                finestep::fine_step(sys, s0, &times, self.info.horizon, h0, floor)?
            }
        };
        self.motion = fine.motion;
        self.member_solver = Some(ensemble::MemberSolver::FineStep { h: fine.step });
        for (e, x) in ents.iter().zip(fine.samples) {
            self.samples[e.grid][e.idx] = x;
        }
        self.set_uncertainty(&ents, &fine.uncertainty);
        self.info.predictability_horizon = fine.horizon;
        self.info.predictability_threshold =
            uncertainty::PREDICTABILITY_THRESHOLD * self.motion_scale();
        let (sampled, how) = match fine.between {
            Some((interpolated, landed)) => (
                format!(", both sampled the same way, plus the cubic Hermite interpolant's error estimate at samples interpolated inside a fine step ({interpolated} of {} samples interpolated, {landed} landed on by a partial fine step)", times.len()),
                "; one run of levels per scene, sampled between its steps by cubic Hermite interpolation of positions and velocities, or by a partial fine step from the step's start where the step holds a contact",
            ),
            None => (String::new(), "; every level landing on the sample times"),
        };
        self.info.uncertainty_measured_by = format!(
            "distance between the last two of {} halvings of the step (finest {:e} s){sampled}",
            fine.levels, fine.step
        );
        self.info.solver_evals = fine.evals;
        self.info.kind = ReferenceKind::FineStep;
        self.info.description = format!(
            "the scene's projection contacts have no continuous counterpart: {} with the scene's contact stage at successively halved steps until two levels agree to {:e} x the motion scale (finest step {:e} s, {} levels){how}",
            finestep::FINE_METHOD, finestep::FINE_AGREEMENT, fine.step, fine.levels
        );
        Ok(())
    }
}

/// Points over the horizon at which the closed form's motion scale is read.
const ANALYTIC_MOTION_POINTS: f64 = 4000.0;

/// Round-off level of positions relative to the length scale.
const ROUND_OFF: f64 = 1e-14;
