//! Contacts in the adaptive reference, for the `impulse` response, as the scene defines them.
//!
//! - **Impacts** are events on DOP853's dense output: the gap (signed distance to an obstacle
//!   minus the particle radius) is sampled at [`IMPACT_CHECKS`] points inside every accepted
//!   step; the first sign change beyond round-off (gap < −δ) is bisected to round-off, the
//!   particle is put on the surface, the scene's own impulse law
//!   ([`crate::collide::Contacts::impulse_velocity`]: restitution and a Coulomb friction
//!   impulse) changes its velocity, and the solver restarts.
//! - **Resting and sliding contact**: when a bounce would rise less than δ (outward speed
//!   below √(2 a_n δ), a_n the pressing acceleration, so Zeno sequences end) the particle is
//!   *held*: a unilateral constraint keeps its normal acceleration at the surface's
//!   (g̈ = n·a + vₜᵀ H vₜ = 0, H the distance field's Hessian by central differences) while the
//!   normal force N is compressive, with Coulomb friction: sliding feels μN against its
//!   tangential velocity; it sticks when the tangential speed reaches zero and the static
//!   force needed is at most μN. Release (N < 0), stopping (vₜ reverses or falls below the
//!   speed floor) and slipping (static force needed > μN) are events bisected on the dense
//!   output at step ends. Held particles are projected back onto the surface after each step.
//!
//! A held particle is held on one obstacle at a time; a contact with a second obstacle is an
//! impact. Interior impact checks can miss a path that enters and leaves an obstacle between
//! two checks: a body thinner than a step's travel / [`IMPACT_CHECKS`]; steps are capped
//! (see `solve`) so the shipped scenes' obstacles are far thicker.

use crate::collide::Contacts;
use crate::model::{System, Vec3};

/// Points inside each accepted step where every particle's gaps are checked for an impact.
pub const IMPACT_CHECKS: usize = 8;

/// Relative margin by which the static force needed must exceed μN for a sticking particle to
/// slip: without it a particle exactly at the threshold would stop and slip again forever.
pub const STICK_SLIP_HYSTERESIS: f64 = 1e-6;

/// Bisection iterations for an event time (2⁻⁶⁰ of a step: round-off).
pub(super) const BISECTIONS: usize = 60;

/// What one particle is doing with respect to the obstacles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Mode {
    /// In flight (impacts are events).
    Free,
    /// Held on obstacle `k`, sliding (kinetic friction μN against the tangential velocity).
    Slide(usize),
    /// Held on obstacle `k` and at rest on it (static friction).
    Stick(usize),
}

/// A located change of contact mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Event {
    /// Particle `p` hits obstacle `k`.
    Impact(usize, usize),
    /// The normal force on held particle `p` would pull: it leaves the surface.
    Release(usize),
    /// Sliding particle `p` comes to rest (tangentially).
    Stop(usize),
    /// Sticking particle `p` needs more than μN: it starts to slide.
    Slip(usize),
}

/// The contact state of the reference: one mode per particle and the tolerance scales.
#[derive(Debug, Clone)]
pub(super) struct ContactModel<'a> {
    sys: &'a System,
    /// The obstacles' contact stage (its queries locate the events).
    pub(super) contacts: &'a Contacts,
    /// Mode of every particle.
    pub(super) modes: Vec<Mode>,
    /// Penetration treated as round-off, and the largest bounce height ignored (m).
    pub(super) delta: f64,
    /// Tangential speed below which a slide is over (m/s).
    pub(super) speed_floor: f64,
    /// Per particle: a slide that has reached the speed floor (only those can stop by it).
    pub(super) moving: Vec<bool>,
    /// Impacts applied.
    pub(super) impacts: u64,
    /// Times a particle was put into held contact.
    pub(super) holds: u64,
}

/// The quantities of a held particle at one state.
pub(super) struct Held {
    /// The obstacle's normal at the particle.
    pub(super) n: Vec3,
    /// Normal force per unit mass needed to keep g̈ = 0 (positive: compressive).
    pub(super) push: f64,
    /// Tangential part of the unconstrained acceleration.
    pub(super) a_t: Vec3,
    /// Tangential velocity.
    pub(super) v_t: Vec3,
    /// The friction coefficient.
    pub(super) mu: f64,
}

impl<'a> ContactModel<'a> {
    /// The model for `sys` (with an impulse stage `contacts`), at tolerance `rtol` over a scene
    /// of length scale `length`.
    pub(super) fn new(sys: &'a System, contacts: &'a Contacts, rtol: f64, length: f64) -> Self {
        let delta = 10.0 * rtol * length;
        let a_scale = sys.gravity.map_or(1.0, |g| g.norm().max(1e-3));
        ContactModel {
            sys,
            contacts,
            modes: vec![Mode::Free; sys.len()],
            moving: vec![false; sys.len()],
            delta,
            speed_floor: (2.0 * a_scale * delta).sqrt(),
            impacts: 0,
            holds: 0,
        }
    }

    pub(super) fn held_on(&self, p: usize) -> Option<usize> {
        match self.modes[p] {
            Mode::Free => None,
            Mode::Slide(k) | Mode::Stick(k) => Some(k),
        }
    }

    /// vₜᵀ H vₜ for obstacle `k` at `x`: the normal acceleration a point moving with `v_t` along
    /// the surface needs to stay on it (central difference of the normal along vₜ).
    fn curvature_term(&self, k: usize, x: &Vec3, v_t: &Vec3, r: f64) -> f64 {
        let s = v_t.norm();
        if s == 0.0 {
            return 0.0;
        }
        let dir = v_t / s;
        let eps = 1e-6 * (1.0 + x.norm());
        let set = &self.contacts.set;
        let np = set.query(k, &(x + dir * eps), r).normal;
        let nm = set.query(k, &(x - dir * eps), r).normal;
        s * s * dir.dot(&(np - nm)) / (2.0 * eps)
    }

    pub(super) fn held(&self, p: usize, k: usize, x: &Vec3, v: &Vec3, a_free: &Vec3) -> Held {
        let r = self.sys.radius[p];
        let c = self.contacts.set.query(k, x, r);
        let n = c.normal;
        let v_t = v - n * v.dot(&n);
        let kappa = self.curvature_term(k, x, &v_t, r);
        Held {
            n,
            push: -kappa - a_free.dot(&n),
            a_t: a_free - n * a_free.dot(&n),
            v_t,
            mu: self.contacts.set.obstacles()[k].friction,
        }
    }

    /// Adds the held particles' contact accelerations (normal constraint and friction) to the
    /// unconstrained accelerations `a`.
    pub(super) fn constrain(&self, x: &[Vec3], v: &[Vec3], a: &mut [Vec3]) {
        for p in 0..x.len() {
            let Some(k) = self.held_on(p) else { continue };
            let h = self.held(p, k, &x[p], &v[p], &a[p]);
            a[p] += h.n * h.push;
            match self.modes[p] {
                Mode::Stick(_) => a[p] -= h.a_t,
                _ if h.mu > 0.0 => {
                    let dir = h
                        .v_t
                        .try_normalize(0.0)
                        .or_else(|| h.a_t.try_normalize(0.0));
                    if let Some(d) = dir {
                        a[p] -= d * (h.mu * h.push.max(0.0));
                    }
                }
                _ => {}
            }
        }
    }

    /// Puts held particles back on their surfaces (position and normal velocity; a sticking
    /// particle's velocity is zero). Returns true when something changed.
    pub(super) fn project(&self, y: &mut [f64]) -> bool {
        let n = self.sys.len();
        let mut changed = false;
        for p in 0..n {
            let Some(k) = self.held_on(p) else { continue };
            let (mut x, mut v) = get(y, n, p);
            let c = self.contacts.set.query(k, &x, self.sys.radius[p]);
            x -= c.normal * c.gap;
            v -= c.normal * v.dot(&c.normal);
            if matches!(self.modes[p], Mode::Stick(_)) {
                v = Vec3::zeros();
            }
            put(y, n, p, &x, &v);
            changed = true;
        }
        changed
    }

    /// Time until the first sliding particle would stop at its present deceleration (from
    /// the solver's derivative at its current point), to land the next step there.
    pub(super) fn stop_bound(&self, y: &[f64], dy: &[f64]) -> Option<f64> {
        let n = self.sys.len();
        let mut best: Option<f64> = None;
        for p in 0..n {
            let Mode::Slide(k) = self.modes[p] else {
                continue;
            };
            let (x, v) = get(y, n, p);
            let a = Vec3::new(
                dy[3 * n + 3 * p],
                dy[3 * n + 3 * p + 1],
                dy[3 * n + 3 * p + 2],
            );
            let nrm = self.contacts.set.query(k, &x, self.sys.radius[p]).normal;
            let v_t = v - nrm * v.dot(&nrm);
            let s = v_t.norm();
            if s == 0.0 {
                continue;
            }
            let rate = a.dot(&v_t) / s;
            if rate < 0.0 {
                let t = s / -rate;
                best = Some(best.map_or(t, |b| b.min(t)));
            }
        }
        best
    }
}

pub(super) fn get(y: &[f64], n: usize, p: usize) -> (Vec3, Vec3) {
    let q = 3 * n + 3 * p;
    (
        Vec3::new(y[3 * p], y[3 * p + 1], y[3 * p + 2]),
        Vec3::new(y[q], y[q + 1], y[q + 2]),
    )
}

pub(super) fn put(y: &mut [f64], n: usize, p: usize, x: &Vec3, v: &Vec3) {
    y[3 * p..3 * p + 3].copy_from_slice(x.as_slice());
    let q = 3 * n + 3 * p;
    y[q..q + 3].copy_from_slice(v.as_slice());
}
