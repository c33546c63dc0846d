//! One adaptive solve of a scene: DOP853 with dense output from an initial state to a horizon,
//! restarted at the scene's impulses and at contact events ([`super::contacts`]), with rigid
//! constraints projected after every accepted step. The positions at the requested times go
//! to a sink, so the main solve stores them and the companion solves only compare.

use super::contact_events::{apply_event, find_event};
use super::contacts::{ContactModel, Event};
use super::dense::DenseTrack;
use super::rhs::{pack, project, unpack_x, RhsState};
use super::tracked::Tracked;
use crate::collide::Response;
use crate::error::{Error, Result};
use crate::measure::dop853::{Dop853, Dop853Stats};
use crate::model::{State, System, Vec3};

/// Tolerance of the adaptive reference (relative and absolute).
pub const REFERENCE_TOL: f64 = 1e-12;

/// Longest step of a solve with obstacles, as a fraction of its horizon: keeps the impact
/// checks inside a step closer together than any shipped obstacle is thick.
pub const CONTACT_MAX_STEP_FRACTION: f64 = 1e-3;

/// Contact events at one instant before the solve gives up (an event that does not resolve).
const MAX_EVENTS_AT_ONE_TIME: usize = 1000;

/// What a solve did besides sampling.
#[derive(Debug, Clone, Default)]
pub(super) struct SolveOut {
    /// Upward zero crossings of the tracked velocity component.
    pub crossings: Vec<f64>,
    /// Its downward zero crossings.
    pub down_crossings: Vec<f64>,
    /// Largest displacement from the initial positions seen at step ends (m).
    pub motion: f64,
    /// Solver work.
    pub stats: Dop853Stats,
    /// Restarts (impulses and contact events).
    pub restarts: usize,
    /// Impacts applied.
    pub impacts: u64,
    /// Times a particle went into held (resting or sliding) contact.
    pub holds: u64,
}

/// Largest |coordinate| of the initial positions, at least 1 m: the length scale of
/// tolerance-derived lengths.
pub(super) fn length_scale(s0: &State) -> f64 {
    s0.x.iter().map(|x| x.amax()).fold(1.0, f64::max)
}

/// What one adaptive solve is asked: the scene and its start, the sorted sample times, the
/// horizon, the tolerance (rtol = atol), the velocity component whose zero crossings are timed
/// and the step budget. Bundled because the main solve, its companions, the kept solves and the
/// ensemble members all ask with the same figures.
#[derive(Debug, Clone, Copy)]
pub(super) struct SolveSpec<'a> {
    /// The scene.
    pub sys: &'a System,
    /// Its initial state.
    pub s0: &'a State,
    /// Sorted times at which the sink receives the state.
    pub times: &'a [f64],
    /// End of the solve (s).
    pub horizon: f64,
    /// Relative and absolute tolerance.
    pub rtol: f64,
    /// Velocity component whose zero crossings are timed.
    pub tracked: Option<Tracked>,
    /// Attempted steps after which the solve gives up (None: no limit).
    pub max_steps: Option<u64>,
}

/// How one stretch of steps between restarts ended.
enum Segment {
    /// At its end time (an impulse or the horizon).
    End,
    /// At a contact event: the time just before it and the event.
    Event(f64, Event),
    /// Over the step budget, or out of the dense track's memory.
    GaveUp,
}

/// A solve in progress: the solver with its right-hand side and contact model, the dense
/// output buffer, the next sample to deliver and what the solve did so far.
struct Run<'a> {
    spec: SolveSpec<'a>,
    n: usize,
    rigid: Vec<usize>,
    st: RhsState<'a>,
    h_max: f64,
    solver: Dop853,
    dense: Vec<f64>,
    next: usize,
    out: SolveOut,
}

/// Solves `spec.sys` from `spec.s0` to `spec.horizon`; calls `sink(i, y)` with the state at
/// each of `spec.times` (the pre-event state at an event's own time). With `spec.max_steps`,
/// gives up (None) once the solver has attempted more steps than that; with `track`, once the
/// dense track is over its memory budget.
pub(super) fn solve(
    spec: &SolveSpec<'_>,
    sink: &mut dyn FnMut(usize, &[f64]),
    mut track: Option<&mut DenseTrack>,
) -> Result<Option<SolveOut>> {
    let n = spec.sys.len();
    let mut run = Run::new(*spec);
    let mut y = pack(&spec.s0.x, &spec.s0.v);
    let mut t0 = 0.0;
    let mut imp = spec
        .sys
        .impulses
        .iter()
        .filter(|im| im.time < spec.horizon)
        .peekable();
    let mut same_time = 0;
    loop {
        let t_end = imp.peek().map_or(spec.horizon, |im| im.time);
        run.start(t0, &y, t_end, sink);
        match run.advance(t_end, sink, track.as_deref_mut())? {
            Segment::GaveUp => return Ok(None),
            Segment::Event(te, ev) => {
                same_time = if te <= t0 { same_time + 1 } else { 0 };
                if same_time > MAX_EVENTS_AT_ONE_TIME {
                    return Err(Error::Step(format!(
                        "reference (DOP853): contact events do not resolve at t = {te}"
                    )));
                }
                run.restart_at_event(te, ev, &mut y);
                t0 = te;
                run.out.restarts += 1;
                continue;
            }
            Segment::End => {}
        }
        y.copy_from_slice(&run.solver.y);
        match imp.next() {
            Some(im) => {
                let i = 3 * n + 3 * im.particle;
                for k in 0..3 {
                    y[i + k] += im.delta_v[k];
                }
                t0 = im.time;
                run.out.restarts += 1;
            }
            None => break,
        }
    }
    Ok(Some(run.finish()))
}

impl SolveOut {
    /// Raises [`SolveOut::motion`] to the displacement of the `n` positions of `y` from `x0`.
    fn note_motion(&mut self, y: &[f64], n: usize, x0: &[Vec3]) {
        for (a, b) in unpack_x(y, n).iter().zip(x0) {
            self.motion = self.motion.max((a - b).norm());
        }
    }
}

impl<'a> Run<'a> {
    /// A solve of `spec` not yet started: its rigid constraints, contact model and step cap.
    fn new(spec: SolveSpec<'a>) -> Self {
        let sys = spec.sys;
        let n = sys.len();
        let rigid: Vec<usize> = (0..sys.constraints.len())
            .filter(|&c| sys.constraints[c].compliance == 0.0)
            .collect();
        let mut st = RhsState::new(sys, rigid.clone());
        if let Some(c) = crate::collide::of(sys).filter(|c| c.response == Response::Impulse) {
            st.contact = Some(ContactModel::new(sys, c, spec.rtol, length_scale(spec.s0)));
        }
        let h_max = if st.contact.is_some() {
            CONTACT_MAX_STEP_FRACTION * spec.horizon
        } else {
            f64::INFINITY
        };
        Run {
            spec,
            n,
            rigid,
            st,
            h_max,
            solver: Dop853::new(6 * n, spec.rtol, spec.rtol),
            dense: vec![0.0; 6 * n],
            next: 0,
            out: SolveOut::default(),
        }
    }

    /// Index of tracked component `tr`'s velocity in the state vector.
    fn vel_index(&self, tr: Tracked) -> usize {
        3 * self.n + 3 * tr.particle + tr.axis
    }

    /// (Re)starts the solver at `t0` from `y` towards `t_end`, delivering the samples due by
    /// `t0` from `y` itself.
    fn start(&mut self, t0: f64, y: &[f64], t_end: f64, sink: &mut dyn FnMut(usize, &[f64])) {
        let st = &mut self.st;
        self.solver
            .start(&mut |t, y, dy| st.eval(t, y, dy), t0, y, t_end);
        let times = self.spec.times;
        while self.next < times.len() && times[self.next] <= t0 {
            sink(self.next, y);
            self.next += 1;
        }
    }

    /// Steps towards `t_end` until it, a contact event or a reason to give up.
    fn advance(
        &mut self,
        t_end: f64,
        sink: &mut dyn FnMut(usize, &[f64]),
        mut track: Option<&mut DenseTrack>,
    ) -> Result<Segment> {
        while self.solver.t < t_end {
            self.step(t_end)?;
            let attempted = self.solver.stats.steps + self.solver.stats.rejected;
            if self.spec.max_steps.is_some_and(|m| attempted > m) {
                return Ok(Segment::GaveUp);
            }
            let event = if self.st.contact.is_some() {
                find_event(&mut self.st, &mut self.solver)
            } else {
                None
            };
            let t_stop = event.map_or(self.solver.t, |(te, _)| te);
            if !self.sample_step(t_stop, sink, track.as_deref_mut()) {
                return Ok(Segment::GaveUp);
            }
            self.time_crossings(t_stop);
            if let Some((te, ev)) = event {
                return Ok(Segment::Event(te, ev));
            }
            self.out
                .note_motion(&self.solver.y, self.n, &self.spec.s0.x);
            self.project_step();
        }
        Ok(Segment::End)
    }

    /// One accepted step towards `t_end`, no longer than the step cap and the contact model's
    /// stop bound allow.
    fn step(&mut self, t_end: f64) -> Result<()> {
        let mut bound = t_end.min(self.solver.t + self.h_max);
        if let Some(ts) = self
            .st
            .contact
            .as_ref()
            .and_then(|c| c.stop_bound(&self.solver.y, self.solver.derivative()))
        {
            bound = bound.min(self.solver.t + ts.max(1e-6 * self.h_max));
        }
        let st = &mut self.st;
        let sys = self.spec.sys;
        self.solver
            .step(&mut |t, y, dy| st.eval(t, y, dy), bound)
            .map_err(|e| {
                Error::Step(format!(
                    "reference (DOP853): {e}{}",
                    dominant(sys, &self.solver.y)
                ))
            })
    }

    /// Records the last step up to `t_stop` in the dense track and delivers the samples due by
    /// then; false when the dense track is over its memory budget.
    fn sample_step(
        &mut self,
        t_stop: f64,
        sink: &mut dyn FnMut(usize, &[f64]),
        track: Option<&mut DenseTrack>,
    ) -> bool {
        let times = self.spec.times;
        let need_dense = (self.next < times.len() && times[self.next] <= t_stop)
            || self.spec.tracked.is_some_and(|tr| {
                let i = self.vel_index(tr);
                (self.solver.y_old[i] < 0.0) != (self.solver.y[i] < 0.0)
            });
        if need_dense || track.is_some() {
            let st = &mut self.st;
            self.solver.prepare_dense(&mut |t, y, dy| st.eval(t, y, dy));
        }
        if let Some(tr) = track {
            tr.record(&self.solver, t_stop);
            if !tr.complete() {
                return false;
            }
        }
        while self.next < times.len() && times[self.next] <= t_stop {
            self.solver.dense(times[self.next], &mut self.dense);
            sink(self.next, &self.dense);
            self.next += 1;
        }
        true
    }

    /// Times a zero crossing of the tracked velocity in the last step, bisected on the dense
    /// output, when it falls by `t_stop`.
    fn time_crossings(&mut self, t_stop: f64) {
        let Some(tr) = self.spec.tracked else {
            return;
        };
        let i = self.vel_index(tr);
        let solver = &self.solver;
        let up = solver.y_old[i] < 0.0 && solver.y[i] >= 0.0;
        if up || (solver.y_old[i] >= 0.0 && solver.y[i] < 0.0) {
            // Bisect on the sign the crossing leaves behind.
            let (mut a, mut b) = (solver.t_old, solver.t);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                solver.dense(m, &mut self.dense);
                if (self.dense[i] < 0.0) == up {
                    a = m
                } else {
                    b = m
                }
            }
            let c = 0.5 * (a + b);
            if c <= t_stop && up {
                self.out.crossings.push(c);
            } else if c <= t_stop {
                self.out.down_crossings.push(c);
            }
        }
    }

    /// Projects the accepted state onto the rigid constraints and the held contacts.
    fn project_step(&mut self) {
        let mut yp = self.solver.y.clone();
        let mut changed = false;
        if !self.rigid.is_empty() {
            project(self.spec.sys, &self.rigid, &mut yp);
            changed = true;
        }
        if let Some(c) = &self.st.contact {
            changed |= c.project(&mut yp);
        }
        if changed {
            let st = &mut self.st;
            self.solver.set_y(&mut |t, y, dy| st.eval(t, y, dy), &yp);
        }
    }

    /// Sets `y` to the state just before the event `ev` at `te`, applies the event and
    /// projects the result: the state the solve restarts from.
    fn restart_at_event(&mut self, te: f64, ev: Event, y: &mut [f64]) {
        let st = &mut self.st;
        self.solver.prepare_dense(&mut |t, y, dy| st.eval(t, y, dy));
        self.solver.dense(te, y);
        self.out.note_motion(y, self.n, &self.spec.s0.x);
        apply_event(&mut self.st, y, ev);
        if !self.rigid.is_empty() {
            project(self.spec.sys, &self.rigid, y);
        }
        if let Some(c) = &self.st.contact {
            c.project(y);
        }
    }

    /// What the solve did: its counts with the solver's and the contact model's.
    fn finish(mut self) -> SolveOut {
        self.out.stats = self.solver.stats;
        if let Some(c) = &self.st.contact {
            self.out.impacts = c.impacts;
            self.out.holds = c.holds;
        }
        self.out
    }
}

/// Positions of the state vector `y`.
pub(super) fn positions(y: &[f64], n: usize) -> Vec<Vec3> {
    unpack_x(y, n)
}

/// What drives the motion at state `y` (packed positions, velocities), for a failed solve's
/// message: the force term with the largest acceleration and the scene field that sets it.
fn dominant(sys: &System, y: &[f64]) -> String {
    let n = sys.len();
    let x = super::rhs::unpack_x(y, n);
    let v = super::rhs::unpack_x(&y[3 * n..], n);
    match sys.dominant_term(&x, &v) {
        Some((name, field, a)) => format!(
            "; there the largest acceleration is {name}'s, {} m/s² (set by {field})",
            crate::error::significant(a, 3)
        ),
        None => String::new(),
    }
}
