//! Locating and applying the reference's contact events: the earliest change of contact mode
//! inside an accepted step, bisected to round-off on the dense output, and the new mode.

use super::contacts::{get, put, Event, Mode, BISECTIONS, IMPACT_CHECKS, STICK_SLIP_HYSTERESIS};
use super::rhs::RhsState;
use crate::measure::dop853::Dop853;
use crate::model::Vec3;

/// A scalar per candidate whose sign flips at the event: ≥ 0 before, < 0 after.
fn indicator(st: &mut RhsState<'_>, y: &[f64], ev: Event, d0: &[Vec3]) -> f64 {
    let sys = st.sys();
    let n = sys.len();
    let model = st.contact.as_ref().expect("contact model");
    match ev {
        Event::Impact(p, k) => {
            let (x, _) = get(y, n, p);
            model.contacts.set.query(k, &x, sys.radius[p]).gap + model.delta
        }
        Event::Stop(p) => {
            let (x, v) = get(y, n, p);
            let k = model.held_on(p).expect("held");
            let nrm = model.contacts.set.query(k, &x, sys.radius[p]).normal;
            (v - nrm * v.dot(&nrm)).dot(&d0[p])
        }
        Event::Release(p) | Event::Slip(p) => {
            let k = model.held_on(p).expect("held");
            let a = st.free_accelerations(y);
            let model = st.contact.as_ref().expect("contact model");
            let (x, v) = get(y, n, p);
            let h = model.held(p, k, &x, &v, &a[p]);
            if matches!(ev, Event::Release(_)) {
                h.push
            } else {
                h.mu * h.push * (1.0 + STICK_SLIP_HYSTERESIS) - h.a_t.norm()
            }
        }
    }
}

/// A candidate event: the bracket (start, end) it lies in and the event.
type Candidate = (f64, f64, Event);

/// The earliest contact event in the solver's last accepted step, with the time just before
/// it (bisected to round-off on the dense output); None when the step is event-free.
pub(super) fn find_event(st: &mut RhsState<'_>, solver: &mut Dop853) -> Option<(f64, Event)> {
    let n = st.sys().len();
    let mut y = vec![0.0; 6 * n];
    let d0 = slide_directions(st, solver)?;
    solver.prepare_dense(&mut |t, yy, dy| st.eval(t, yy, dy));
    let mut cands = impact_candidates(st, solver, &mut y)?;
    held_candidates(st, solver, &d0, &mut cands)?;
    earliest(st, solver, cands, &d0, &mut y)
}

/// Sliding directions at the step start (zero for particles not sliding, or slower than the
/// speed floor).
fn slide_directions(st: &RhsState<'_>, solver: &Dop853) -> Option<Vec<Vec3>> {
    let sys = st.sys();
    let n = sys.len();
    let model = st.contact.as_ref()?;
    Some(
        (0..n)
            .map(|p| match model.modes[p] {
                Mode::Slide(k) => {
                    let (x, v) = get(&solver.y_old, n, p);
                    let nrm = model.contacts.set.query(k, &x, sys.radius[p]).normal;
                    let v_t = v - nrm * v.dot(&nrm);
                    if v_t.norm() >= model.speed_floor {
                        v_t.normalize()
                    } else {
                        Vec3::zeros()
                    }
                }
                _ => Vec3::zeros(),
            })
            .collect(),
    )
}

/// Impacts: gaps at interior checks of the step (and its end) on the dense output, the first
/// bracket per particle; `y` is scratch space for the dense output.
fn impact_candidates(st: &RhsState<'_>, solver: &Dop853, y: &mut [f64]) -> Option<Vec<Candidate>> {
    let sys = st.sys();
    let n = sys.len();
    let (t0, t1) = (solver.t_old, solver.t);
    let model = st.contact.as_ref()?;
    let mut cands = Vec::new();
    let mut done = vec![false; n];
    for m in 1..=IMPACT_CHECKS {
        let tb = t0 + (t1 - t0) * m as f64 / IMPACT_CHECKS as f64;
        let ta = t0 + (t1 - t0) * (m - 1) as f64 / IMPACT_CHECKS as f64;
        solver.dense(tb, y);
        for p in 0..n {
            if !sys.free[p] || done[p] {
                continue;
            }
            let (x, _) = get(y, n, p);
            let held = model.held_on(p);
            let mut hit = None;
            model
                .contacts
                .set
                .for_each_near(&x, sys.radius[p], -model.delta, |c| {
                    if Some(c.obstacle) != held && hit.is_none() {
                        hit = Some(c.obstacle);
                    }
                });
            if let Some(k) = hit {
                done[p] = true;
                cands.push((ta, tb, Event::Impact(p, k)));
            }
        }
    }
    Some(cands)
}

/// Held particles: release, stop and slip, judged at the step end; `d0` are the sliding
/// directions at the step start.
fn held_candidates(
    st: &mut RhsState<'_>,
    solver: &Dop853,
    d0: &[Vec3],
    cands: &mut Vec<Candidate>,
) -> Option<()> {
    let (t0, t1) = (solver.t_old, solver.t);
    let modes = st.contact.as_ref()?.modes.clone();
    if modes.iter().any(|m| *m != Mode::Free) {
        let y1 = solver.y.clone();
        for (p, mode) in modes.iter().enumerate() {
            match mode {
                Mode::Free => continue,
                Mode::Slide(_) => {
                    if let Some(c) = slide_stop(st, solver, &y1, p, d0[p])? {
                        cands.push(c);
                    }
                }
                Mode::Stick(_) => {
                    if indicator(st, &y1, Event::Slip(p), d0) < 0.0 {
                        cands.push((t0, t1, Event::Slip(p)));
                    }
                }
            }
            if indicator(st, &y1, Event::Release(p), d0) < 0.0 {
                cands.push((t0, t1, Event::Release(p)));
            }
        }
    }
    Some(())
}

/// A stop of sliding particle `p` in the step ending at state `y1` (Some(None): none);
/// `d0` is its sliding direction at the step start. Marks the particle moving once it has.
fn slide_stop(
    st: &mut RhsState<'_>,
    solver: &Dop853,
    y1: &[f64],
    p: usize,
    d0: Vec3,
) -> Option<Option<Candidate>> {
    let sys = st.sys();
    let n = sys.len();
    let (t0, t1) = (solver.t_old, solver.t);
    let model = st.contact.as_ref()?;
    let floor = model.speed_floor;
    let (x, v) = get(y1, n, p);
    let k = model.held_on(p)?;
    let nrm = model.contacts.set.query(k, &x, sys.radius[p]).normal;
    let v_t = v - nrm * v.dot(&nrm);
    let q = 3 * n + 3 * p;
    let f = solver.derivative();
    let a = Vec3::new(f[q], f[q + 1], f[q + 2]);
    let moving = model.moving[p];
    if v_t.norm() >= floor {
        st.contact.as_mut()?.moving[p] = true;
    }
    if v_t.dot(&d0) < 0.0 {
        return Some(Some((t0, t1, Event::Stop(p))));
    }
    if v_t.norm() < floor
        && a.dot(&v_t) < 0.0
        && (moving || {
            let a_free = st.free_accelerations(y1);
            let m = st.contact.as_ref()?;
            let h = m.held(p, k, &x, &v, &a_free[p]);
            h.a_t.norm() <= h.mu * h.push * (1.0 + STICK_SLIP_HYSTERESIS)
        })
    {
        // Decelerated to rest at the step end (the step was landed there). A particle set
        // sliding from rest is not stopped before it has moved (at the slip threshold it
        // would stop and slip again forever).
        return Some(Some((t1, t1, Event::Stop(p))));
    }
    Some(None)
}

/// The earliest of the candidate events, each bisected on the dense output to the time just
/// before it; `y` is scratch space for the dense output.
fn earliest(
    st: &mut RhsState<'_>,
    solver: &Dop853,
    cands: Vec<Candidate>,
    d0: &[Vec3],
    y: &mut [f64],
) -> Option<(f64, Event)> {
    let mut best: Option<(f64, Event)> = None;
    for (mut a, mut b, ev) in cands {
        if best.is_some_and(|(tb, _)| tb <= a) {
            continue;
        }
        if a < b {
            for _ in 0..BISECTIONS {
                let m = 0.5 * (a + b);
                if m <= a || m >= b {
                    break;
                }
                solver.dense(m, y);
                if indicator(st, y, ev, d0) < 0.0 {
                    b = m;
                } else {
                    a = m;
                }
            }
        }
        if best.is_none_or(|(tb, _)| a < tb) {
            best = Some((a, ev));
        }
    }
    best
}

/// Applies event `ev` to the state `y` (located just before it).
pub(super) fn apply_event(st: &mut RhsState<'_>, y: &mut [f64], ev: Event) {
    let sys = st.sys();
    let n = sys.len();
    match ev {
        Event::Impact(p, k) => {
            let model = st.contact.as_mut().expect("contact model");
            let (mut x, mut v) = get(y, n, p);
            let c = model.contacts.set.query(k, &x, sys.radius[p]);
            x -= c.normal * c.gap.min(0.0);
            v = model.contacts.impulse_velocity(k, &c.normal, v);
            model.impacts += 1;
            model.modes[p] = Mode::Free;
            put(y, n, p, &x, &v);
            // Zeno: a bounce lower than δ while pressed onto the surface becomes held contact.
            let a = st.free_accelerations(y);
            let model = st.contact.as_mut().expect("contact model");
            let h = model.held(p, k, &x, &v, &a[p]);
            let vn = v.dot(&c.normal);
            let rest = (2.0 * h.push.max(0.0) * model.delta).sqrt();
            if h.push > 0.0 && vn < rest {
                v -= c.normal * vn;
                let stick =
                    h.mu > 0.0 && h.v_t.norm() < model.speed_floor && h.a_t.norm() <= h.mu * h.push;
                if stick {
                    v = Vec3::zeros();
                }
                model.modes[p] = if stick {
                    Mode::Stick(k)
                } else {
                    Mode::Slide(k)
                };
                model.moving[p] = false;
                model.holds += 1;
                put(y, n, p, &x, &v);
            }
        }
        Event::Release(p) => {
            st.contact.as_mut().expect("contact model").modes[p] = Mode::Free;
        }
        Event::Stop(p) => {
            let a = st.free_accelerations(y);
            let model = st.contact.as_mut().expect("contact model");
            let k = model.held_on(p).expect("held");
            let (x, v) = get(y, n, p);
            let h = model.held(p, k, &x, &v, &a[p]);
            let v = v - h.v_t;
            model.modes[p] = if h.a_t.norm() <= h.mu * h.push * (1.0 + STICK_SLIP_HYSTERESIS) {
                Mode::Stick(k)
            } else {
                Mode::Slide(k)
            };
            model.moving[p] = false;
            put(y, n, p, &x, &v);
        }
        Event::Slip(p) => {
            let model = st.contact.as_mut().expect("contact model");
            let k = model.held_on(p).expect("held");
            model.modes[p] = Mode::Slide(k);
            model.moving[p] = false;
        }
    }
}
