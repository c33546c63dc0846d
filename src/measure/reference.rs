//! Reference solutions: the closed form where the scene has one, otherwise DOP853 at
//! rtol = atol = 1e-12 with dense output; rigid constraints are honoured exactly by an
//! index-reduced formulation (Lagrange multipliers from the acceleration-level constraint)
//! with projection onto the constraint manifold after every accepted step. Impulses restart
//! the solver exactly at their times.
//!
//! A [`Reference`] is computed once per scene and set of output grids (a whole sweep at once)
//! and stores only positions at the requested times, so memory stays bounded.

use super::dop853::{Dop853, Dop853Stats, Rhs};
use super::grid::TimeGrid;
use crate::error::{Error, Result};
use crate::integrate::{Analytic, Integrator};
use crate::model::{State, System, Vec3};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Tolerance of the adaptive reference (relative and absolute).
pub const REFERENCE_TOL: f64 = 1e-12;

/// Which reference was used, recorded in every output.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ReferenceInfo {
    /// `analytic`, `dop853` or `dop853_constrained`.
    pub kind: String,
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
    /// An estimate of the reference's own position error (m): errors below ~10× this are the
    /// measurement floor, excluded from order fits.
    pub accuracy: f64,
}

/// How to compute the reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceMethod {
    /// The closed form when the scene has one, else the adaptive solver.
    Auto,
    /// Always the adaptive solver (DOP853, constrained where needed).
    Adaptive,
}

/// The velocity component tracked for period and phase: particle and axis (0 = x).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Tracked {
    /// Particle index.
    pub particle: usize,
    /// Axis 0, 1 or 2.
    pub axis: usize,
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
}

/// The velocity component whose sign changes mark the scene's oscillation: the free
/// particle and axis with the largest initial acceleration (rigid-constraint forces included),
/// preferring axes across gravity when any has one (a pendulum's swing, not its bob's
/// up-and-down at twice the frequency); without acceleration, the largest initial velocity.
pub fn tracked_component(sys: &System, s0: &State) -> Option<Tracked> {
    let n = sys.len();
    let rigid: Vec<usize> = (0..sys.constraints.len())
        .filter(|&c| sys.constraints[c].compliance == 0.0)
        .collect();
    let mut st = RhsState::new(sys, rigid);
    let y = pack(&s0.x, &s0.v);
    let mut dy = vec![0.0; 6 * n];
    st.eval(0.0, &y, &mut dy);
    let a: Vec<Vec3> = (0..n)
        .map(|p| {
            Vec3::new(
                dy[3 * n + 3 * p],
                dy[3 * n + 3 * p + 1],
                dy[3 * n + 3 * p + 2],
            )
        })
        .collect();
    let g_axis = sys
        .gravity
        .and_then(|g| (0..3).find(|&k| g[k] != 0.0 && g.norm() == g[k].abs()));
    let pick = |vals: &[Vec3], skip: Option<usize>| {
        let mut best: Option<(f64, Tracked)> = None;
        for p in (0..n).filter(|&p| sys.free[p]) {
            for axis in (0..3).filter(|&k| Some(k) != skip) {
                let m = vals[p][axis].abs();
                if m > 1e-12 * vals[p].norm() && m > 0.0 && best.is_none_or(|(b, _)| m > b) {
                    best = Some((m, Tracked { particle: p, axis }));
                }
            }
        }
        best.map(|b| b.1)
    };
    pick(&a, g_axis)
        .or_else(|| pick(&a, None))
        .or_else(|| pick(&s0.v, None))
}

/// True when the scene has a closed form (the `analytic` integrator accepts it).
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
        Self::compute_with(sys, s0, grids, horizon, ReferenceMethod::Auto)
    }

    /// As [`Reference::compute`], choosing the method explicitly.
    pub fn compute_with(
        sys: &System,
        s0: &State,
        grids: &[TimeGrid],
        horizon: f64,
        method: ReferenceMethod,
    ) -> Result<Self> {
        let horizon = entries(grids).last().map_or(horizon, |e| e.t.max(horizon));
        let tracked = tracked_component(sys, s0);
        let samples = grids
            .iter()
            .map(|g| vec![Vec::new(); g.sample_count()])
            .collect();
        let mut r = Reference {
            info: ReferenceInfo {
                kind: String::new(),
                description: String::new(),
                rtol: 0.0,
                atol: 0.0,
                solver_steps: 0,
                solver_rejected: 0,
                solver_evals: 0,
                restarts: 0,
                horizon,
                accuracy: 0.0,
            },
            grids: grids.to_vec(),
            samples,
            tracked,
            crossings: Vec::new(),
        };
        if method == ReferenceMethod::Auto
            && has_closed_form(sys)
            && r.fill_analytic(sys, s0).is_ok()
        {
            return Ok(r);
        }
        r.crossings.clear();
        r.fill_dop853(sys, s0)?;
        Ok(r)
    }

    /// Reference positions at step `n` of grid `g` (None when `n` is not a sample step).
    pub fn positions(&self, g: usize, n: u64) -> Option<&[Vec3]> {
        let i = self.grids[g].sample_index(n)?;
        self.samples[g].get(i).map(|v| v.as_slice())
    }

    /// Largest displacement of any particle from its initial position over the samples (m),
    /// or 1 when nothing moves: the scale errors are judged against.
    pub fn motion_scale(&self, s0: &State) -> f64 {
        let mut m: f64 = 0.0;
        for g in &self.samples {
            for x in g {
                for (a, b) in x.iter().zip(&s0.x) {
                    m = m.max((a - b).norm());
                }
            }
        }
        if m > 0.0 {
            m
        } else {
            1.0
        }
    }

    /// Period of the tracked component from its crossings (None with fewer than two).
    pub fn period(&self) -> Option<f64> {
        period_of(&self.crossings)
    }

    fn length_scale(s0: &State) -> f64 {
        let mut hi: f64 = 0.0;
        for x in &s0.x {
            hi = hi.max(x.amax());
        }
        hi.max(1.0)
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
                    if prev.1 < 0.0 && v >= 0.0 {
                        let (mut a, mut b) = (prev.0, t);
                        for _ in 0..60 {
                            let m = 0.5 * (a + b);
                            if vel(m)? < 0.0 {
                                a = m
                            } else {
                                b = m
                            }
                        }
                        self.crossings.push(0.5 * (a + b));
                    }
                    prev = (t, v);
                }
            }
        }
        self.info.kind = "analytic".into();
        self.info.description =
            "closed-form solution of independent damped linear oscillators (exact to round-off)"
                .into();
        self.info.accuracy = 1e-14 * Self::length_scale(s0);
        Ok(())
    }

    fn fill_dop853(&mut self, sys: &System, s0: &State) -> Result<()> {
        let n = sys.len();
        let rigid: Vec<usize> = (0..sys.constraints.len())
            .filter(|&c| sys.constraints[c].compliance == 0.0)
            .collect();
        let mut rhs_state = RhsState::new(sys, rigid.clone());
        let mut y = pack(&s0.x, &s0.v);
        let mut solver = Dop853::new(6 * n, REFERENCE_TOL, REFERENCE_TOL);
        let horizon = self.info.horizon;
        let ents = entries(&self.grids);
        let mut next = 0;
        let mut out = vec![0.0; 6 * n];
        let mut rhs = |t: f64, y: &[f64], dy: &mut [f64]| rhs_state.eval(t, y, dy);
        let rhs: &mut Rhs<'_> = &mut rhs;
        let mut t0 = 0.0;
        let mut imp = sys
            .impulses
            .iter()
            .filter(|im| im.time < horizon)
            .peekable();
        let tracked = self.tracked;
        let vel_index = |tr: Tracked| 3 * n + 3 * tr.particle + tr.axis;
        loop {
            let t_end = imp.peek().map_or(horizon, |im| im.time);
            // Samples at the segment start (t = 0 or exactly at an impulse: pre-impulse below).
            solver.start(rhs, t0, &y, t_end);
            while next < ents.len() && ents[next].t <= t0 {
                self.samples[ents[next].grid][ents[next].idx] = unpack_x(&y, n);
                next += 1;
            }
            while solver.t < t_end {
                solver
                    .step(rhs, t_end)
                    .map_err(|e| Error::Step(format!("reference (DOP853): {e}")))?;
                let need_dense = (next < ents.len() && ents[next].t <= solver.t)
                    || tracked.is_some_and(|tr| {
                        let i = vel_index(tr);
                        solver.y_old[i] < 0.0 && solver.y[i] >= 0.0
                    });
                if need_dense {
                    solver.prepare_dense(rhs);
                }
                while next < ents.len() && ents[next].t <= solver.t {
                    solver.dense(ents[next].t, &mut out);
                    self.samples[ents[next].grid][ents[next].idx] = unpack_x(&out, n);
                    next += 1;
                }
                if let Some(tr) = tracked {
                    let i = vel_index(tr);
                    if solver.y_old[i] < 0.0 && solver.y[i] >= 0.0 {
                        let (mut a, mut b) = (solver.t_old, solver.t);
                        for _ in 0..60 {
                            let m = 0.5 * (a + b);
                            solver.dense(m, &mut out);
                            if out[i] < 0.0 {
                                a = m
                            } else {
                                b = m
                            }
                        }
                        self.crossings.push(0.5 * (a + b));
                    }
                }
                if !rigid.is_empty() {
                    let mut yp = solver.y.clone();
                    project(sys, &rigid, &mut yp);
                    solver.set_y(rhs, &yp);
                }
            }
            y.copy_from_slice(&solver.y);
            match imp.next() {
                Some(im) => {
                    let i = 3 * n + 3 * im.particle;
                    for k in 0..3 {
                        y[i + k] += im.delta_v[k];
                    }
                    t0 = im.time;
                    self.info.restarts += 1;
                }
                None => break,
            }
        }
        let st: Dop853Stats = solver.stats;
        self.info.solver_steps = st.steps;
        self.info.solver_rejected = st.rejected;
        self.info.solver_evals = st.evals;
        self.info.rtol = REFERENCE_TOL;
        self.info.atol = REFERENCE_TOL;
        self.info.accuracy = 1e-9 * Self::length_scale(s0);
        if rigid.is_empty() {
            self.info.kind = "dop853".into();
            self.info.description = "adaptive Dormand-Prince 8(5,3) (DOP853) at rtol = atol = 1e-12 with 7th-order dense output, restarted at each impulse".into();
        } else {
            self.info.kind = "dop853_constrained".into();
            self.info.description = format!("DOP853 at rtol = atol = 1e-12 on the index-reduced equations of motion ({} rigid constraint(s) enforced at acceleration level by Lagrange multipliers), positions and velocities projected onto the constraint manifold after every step", rigid.len());
        }
        Ok(())
    }
}

/// Period from a list of upward crossing times: mean spacing first to last.
pub fn period_of(c: &[f64]) -> Option<f64> {
    (c.len() >= 2).then(|| (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64)
}

fn pack(x: &[Vec3], v: &[Vec3]) -> Vec<f64> {
    x.iter().chain(v).flat_map(|p| [p.x, p.y, p.z]).collect()
}

fn unpack_x(y: &[f64], n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|p| Vec3::new(y[3 * p], y[3 * p + 1], y[3 * p + 2]))
        .collect()
}

/// Scratch for the reference right-hand side.
struct RhsState<'a> {
    sys: &'a System,
    rigid: Vec<usize>,
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    a: Vec<Vec3>,
}

impl<'a> RhsState<'a> {
    fn new(sys: &'a System, rigid: Vec<usize>) -> Self {
        let n = sys.len();
        RhsState {
            sys,
            rigid,
            x: vec![Vec3::zeros(); n],
            v: vec![Vec3::zeros(); n],
            a: vec![Vec3::zeros(); n],
        }
    }

    fn eval(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.sys.len();
        for p in 0..n {
            self.x[p] = Vec3::new(y[3 * p], y[3 * p + 1], y[3 * p + 2]);
            let q = 3 * n + 3 * p;
            self.v[p] = Vec3::new(y[q], y[q + 1], y[q + 2]);
        }
        self.sys.accelerations(&self.x, &self.v, &mut self.a);
        let sys = self.sys;
        // Compliant constraints act as stiff springs of stiffness 1/compliance.
        for c in sys.constraints.iter().filter(|c| c.compliance > 0.0) {
            let d = self.x[c.j] - self.x[c.i];
            let len = d.norm();
            if len > 0.0 {
                let f = d / len * ((len - c.length) / c.compliance);
                self.a[c.i] += f * sys.inv_mass[c.i];
                self.a[c.j] -= f * sys.inv_mass[c.j];
            }
        }
        if !self.rigid.is_empty() {
            constraint_accelerations(sys, &self.rigid, &self.x, &self.v, &mut self.a);
        }
        for p in 0..n {
            dy[3 * p..3 * p + 3].copy_from_slice(self.v[p].as_slice());
            dy[3 * n + 3 * p..3 * n + 3 * p + 3].copy_from_slice(self.a[p].as_slice());
        }
    }
}

/// Unit direction of each rigid constraint and the Gram matrix J M⁻¹ Jᵀ.
fn gram(sys: &System, rigid: &[usize], x: &[Vec3]) -> (Vec<Vec3>, DMatrix<f64>) {
    let m = rigid.len();
    let dirs: Vec<Vec3> = rigid
        .iter()
        .map(|&k| {
            let c = &sys.constraints[k];
            (x[c.j] - x[c.i]).try_normalize(0.0).unwrap_or_else(Vec3::x)
        })
        .collect();
    let mut g = DMatrix::zeros(m, m);
    for a in 0..m {
        let ca = &sys.constraints[rigid[a]];
        for b in 0..m {
            let cb = &sys.constraints[rigid[b]];
            // ∇_p C = -n for p = i, +n for p = j.
            let grad = |c: &crate::model::DistanceConstraint, n: Vec3, p: usize| {
                let mut gp = Vec3::zeros();
                if c.i == p {
                    gp -= n;
                }
                if c.j == p {
                    gp += n;
                }
                gp
            };
            let mut s = 0.0;
            for p in [ca.i, ca.j] {
                if (p == cb.i || p == cb.j) && !(p == ca.j && ca.i == ca.j) {
                    s += sys.inv_mass[p] * grad(ca, dirs[a], p).dot(&grad(cb, dirs[b], p));
                }
            }
            g[(a, b)] = s;
        }
    }
    (dirs, g)
}

/// Adds M⁻¹ Jᵀ λ with λ solving J M⁻¹ Jᵀ λ = -(J a + J̇ v): the accelerations that keep
/// C̈ = 0 for every rigid distance constraint.
fn constraint_accelerations(sys: &System, rigid: &[usize], x: &[Vec3], v: &[Vec3], a: &mut [Vec3]) {
    let (dirs, g) = gram(sys, rigid, x);
    let m = rigid.len();
    let mut rhs = DVector::zeros(m);
    for (r, &k) in rigid.iter().enumerate() {
        let c = &sys.constraints[k];
        let n = dirs[r];
        let len = (x[c.j] - x[c.i]).norm().max(f64::MIN_POSITIVE);
        let vr = v[c.j] - v[c.i];
        let jdot_v = (vr.norm_squared() - n.dot(&vr).powi(2)) / len;
        rhs[r] = -(n.dot(&(a[c.j] - a[c.i])) + jdot_v);
    }
    if let Some(lambda) = g.lu().solve(&rhs) {
        for (r, &k) in rigid.iter().enumerate() {
            let c = &sys.constraints[k];
            let f = dirs[r] * lambda[r];
            a[c.j] += f * sys.inv_mass[c.j];
            a[c.i] -= f * sys.inv_mass[c.i];
        }
    }
}

/// Projects positions (Gauss-Newton, a few sweeps) and velocities onto the rigid constraints.
fn project(sys: &System, rigid: &[usize], y: &mut [f64]) {
    let n = sys.len();
    let mut x = unpack_x(y, n);
    for _ in 0..4 {
        let (dirs, g) = gram(sys, rigid, &x);
        let viol = DVector::from_iterator(
            rigid.len(),
            rigid.iter().map(|&k| {
                let c = &sys.constraints[k];
                (x[c.j] - x[c.i]).norm() - c.length
            }),
        );
        if viol.amax() < 1e-15 {
            break;
        }
        let Some(mu) = g.lu().solve(&(-viol)) else {
            break;
        };
        for (r, &k) in rigid.iter().enumerate() {
            let c = &sys.constraints[k];
            let d = dirs[r] * mu[r];
            x[c.j] += d * sys.inv_mass[c.j];
            x[c.i] -= d * sys.inv_mass[c.i];
        }
    }
    let mut v: Vec<Vec3> = (0..n)
        .map(|p| {
            let q = 3 * n + 3 * p;
            Vec3::new(y[q], y[q + 1], y[q + 2])
        })
        .collect();
    let (dirs, g) = gram(sys, rigid, &x);
    let jv = DVector::from_iterator(
        rigid.len(),
        rigid.iter().enumerate().map(|(r, &k)| {
            let c = &sys.constraints[k];
            dirs[r].dot(&(v[c.j] - v[c.i]))
        }),
    );
    if let Some(mu) = g.lu().solve(&(-jv)) {
        for (r, &k) in rigid.iter().enumerate() {
            let c = &sys.constraints[k];
            let d = dirs[r] * mu[r];
            v[c.j] += d * sys.inv_mass[c.j];
            v[c.i] -= d * sys.inv_mass[c.i];
        }
    }
    y.copy_from_slice(&pack(&x, &v));
}
