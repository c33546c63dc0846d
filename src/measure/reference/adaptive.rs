//! One adaptive solve of a scene: DOP853 with dense output from an initial state to a horizon,
//! restarted at the scene's impulses and at contact events ([`super::contacts`]), with rigid
//! constraints projected after every accepted step. The positions at the requested times go
//! to a sink, so the main solve stores them and the companion solves only compare.

use super::contact_events::{apply_event, find_event};
use super::contacts::ContactModel;
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

/// Solves `sys` from `s0` to `horizon` at rtol = atol = `rtol`; calls `sink(i, y)` with the
/// state at each of the sorted `times` (the pre-event state at an event's own time). With
/// `max_steps`, gives up (None) once the solver has attempted more steps than that.
// One function because the step loop carries the solver, the dense output, the event search and the sample cursor together; the event search and the contact model live in their own modules.
#[allow(clippy::too_many_arguments)]
pub(super) fn solve(
    sys: &System,
    s0: &State,
    times: &[f64],
    horizon: f64,
    rtol: f64,
    tracked: Option<Tracked>,
    max_steps: Option<u64>,
    sink: &mut dyn FnMut(usize, &[f64]),
    mut track: Option<&mut DenseTrack>,
) -> Result<Option<SolveOut>> {
    let n = sys.len();
    let rigid: Vec<usize> = (0..sys.constraints.len())
        .filter(|&c| sys.constraints[c].compliance == 0.0)
        .collect();
    let mut st = RhsState::new(sys, rigid.clone());
    if let Some(c) = crate::collide::of(sys).filter(|c| c.response == Response::Impulse) {
        st.contact = Some(ContactModel::new(sys, c, rtol, length_scale(s0)));
    }
    let h_max = if st.contact.is_some() {
        CONTACT_MAX_STEP_FRACTION * horizon
    } else {
        f64::INFINITY
    };
    let mut out = SolveOut::default();
    let mut y = pack(&s0.x, &s0.v);
    let mut solver = Dop853::new(6 * n, rtol, rtol);
    let mut dense = vec![0.0; 6 * n];
    let mut next = 0;
    let mut t0 = 0.0;
    let mut imp = sys
        .impulses
        .iter()
        .filter(|im| im.time < horizon)
        .peekable();
    let vel_index = |tr: Tracked| 3 * n + 3 * tr.particle + tr.axis;
    let note_motion = |out: &mut SolveOut, y: &[f64]| {
        for (a, b) in unpack_x(y, n).iter().zip(&s0.x) {
            out.motion = out.motion.max((a - b).norm());
        }
    };
    let mut same_time = 0;
    loop {
        let t_end = imp.peek().map_or(horizon, |im| im.time);
        solver.start(&mut |t, y, dy| st.eval(t, y, dy), t0, &y, t_end);
        while next < times.len() && times[next] <= t0 {
            sink(next, &y);
            next += 1;
        }
        let mut event = None;
        while solver.t < t_end {
            let mut bound = t_end.min(solver.t + h_max);
            if let Some(ts) = st
                .contact
                .as_ref()
                .and_then(|c| c.stop_bound(&solver.y, solver.derivative()))
            {
                bound = bound.min(solver.t + ts.max(1e-6 * h_max));
            }
            solver
                .step(&mut |t, y, dy| st.eval(t, y, dy), bound)
                .map_err(|e| {
                    Error::Step(format!(
                        "reference (DOP853): {e}{}",
                        dominant(sys, &solver.y)
                    ))
                })?;
            if max_steps.is_some_and(|m| solver.stats.steps + solver.stats.rejected > m) {
                return Ok(None);
            }
            if st.contact.is_some() {
                event = find_event(&mut st, &mut solver);
            }
            let t_stop = event.map_or(solver.t, |(te, _)| te);
            let need_dense = (next < times.len() && times[next] <= t_stop)
                || tracked.is_some_and(|tr| {
                    let i = vel_index(tr);
                    (solver.y_old[i] < 0.0) != (solver.y[i] < 0.0)
                });
            if need_dense || track.is_some() {
                solver.prepare_dense(&mut |t, y, dy| st.eval(t, y, dy));
            }
            if let Some(tr) = track.as_deref_mut() {
                tr.record(&solver, t_stop);
                if !tr.complete() {
                    return Ok(None);
                }
            }
            while next < times.len() && times[next] <= t_stop {
                solver.dense(times[next], &mut dense);
                sink(next, &dense);
                next += 1;
            }
            if let Some(tr) = tracked {
                let i = vel_index(tr);
                let up = solver.y_old[i] < 0.0 && solver.y[i] >= 0.0;
                if up || (solver.y_old[i] >= 0.0 && solver.y[i] < 0.0) {
                    // Bisect on the sign the crossing leaves behind.
                    let (mut a, mut b) = (solver.t_old, solver.t);
                    for _ in 0..60 {
                        let m = 0.5 * (a + b);
                        solver.dense(m, &mut dense);
                        if (dense[i] < 0.0) == up {
                            a = m
                        } else {
                            b = m
                        }
                    }
                    let c = 0.5 * (a + b);
                    if c <= t_stop && up {
                        out.crossings.push(c);
                    } else if c <= t_stop {
                        out.down_crossings.push(c);
                    }
                }
            }
            if event.is_some() {
                break;
            }
            note_motion(&mut out, &solver.y);
            let mut yp = solver.y.clone();
            let mut changed = false;
            if !rigid.is_empty() {
                project(sys, &rigid, &mut yp);
                changed = true;
            }
            if let Some(c) = &st.contact {
                changed |= c.project(&mut yp);
            }
            if changed {
                solver.set_y(&mut |t, y, dy| st.eval(t, y, dy), &yp);
            }
        }
        if let Some((te, ev)) = event {
            same_time = if te <= t0 { same_time + 1 } else { 0 };
            if same_time > MAX_EVENTS_AT_ONE_TIME {
                return Err(Error::Step(format!(
                    "reference (DOP853): contact events do not resolve at t = {te}"
                )));
            }
            solver.prepare_dense(&mut |t, y, dy| st.eval(t, y, dy));
            solver.dense(te, &mut y);
            note_motion(&mut out, &y);
            apply_event(&mut st, &mut y, ev);
            if !rigid.is_empty() {
                project(sys, &rigid, &mut y);
            }
            if let Some(c) = &st.contact {
                c.project(&mut y);
            }
            t0 = te;
            out.restarts += 1;
            continue;
        }
        y.copy_from_slice(&solver.y);
        match imp.next() {
            Some(im) => {
                let i = 3 * n + 3 * im.particle;
                for k in 0..3 {
                    y[i + k] += im.delta_v[k];
                }
                t0 = im.time;
                out.restarts += 1;
            }
            None => break,
        }
    }
    out.stats = solver.stats;
    if let Some(c) = &st.contact {
        out.impacts = c.impacts;
        out.holds = c.holds;
    }
    Ok(Some(out))
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
