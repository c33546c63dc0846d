//! The post-step contact stage for the `impulse` and `projection` responses: after each
//! accepted step, the runner calls [`Contacts::apply`], which resolves every
//! particle's contacts (including crossings between steps found by a swept test) and reports
//! the mechanical energy the response removed and, apart, the energy it created, so the run's
//! energy account stays a balance that cannot hide a gain behind a loss.
//!
//! The books are per particle: the stage moves one particle at a time, and each move's change
//! of the mechanical energy — the particle's kinetic and gravitational energy plus the elastic
//! energy of the springs and compliant constraints at it ([`System::elastic_at`]) — is booked
//! as dissipated when it falls and as created when it rises. The moves' changes sum to the
//! stage's change, so created − dissipated is exactly what the stage did to the system's
//! energy, and one particle's gain is never netted against another's loss. (Booking the
//! elastic change of the whole system apart from the particles' own would call every lift of
//! a particle out of an obstacle against a spring "created", though the same move took the
//! kinetic energy the spring had given it.)
//!
//! The books measure the stage, never the method: what the stage removes from the state it
//! is handed is dissipated even when the method had just created it (explicit Euler gains
//! ½m h²|g|² per step under gravity; on a resting particle the stage takes it back), so the
//! run's balance keeps the method's own gain or loss, step for step.
//!
//! Coulomb friction acts at both levels, with the same cone for every method: the
//! tangential velocity loses at most μ·Δv_n (Δv_n the normal velocity change the contact
//! makes, which is the method's own approach speed times 1 + e), and the step's tangential
//! displacement is made consistent with it (see [`Response`]), so a sliding particle
//! decelerates at μ·g, sticks when the cone holds it, and never creeps.

use super::def::Response;
use super::obstacles::{Contact, ObstacleSet, SHEET_CLEARANCE};
use crate::model::{PostStep, StageStep, State, System, Vec3};
use std::sync::Arc;

/// What the contact stage did in one step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactStep {
    /// True when some position or velocity changed (the stepper must then be reset).
    pub changed: bool,
    /// Mechanical energy the responses removed (J, ≥ 0): the sum of the particles' drops, each
    /// its kinetic plus gravitational energy plus the elastic energy at it (module docs).
    pub dissipated: f64,
    /// Mechanical energy the responses created (J, ≥ 0): the sum of the particles' rises, on
    /// the same terms (e.g. a particle the method moved deeper than its speed allowed,
    /// pushed back out against gravity). Never netted against `dissipated`; `created −
    /// dissipated` is the stage's change of the system's mechanical energy.
    pub created: f64,
    /// Contacts resolved.
    pub resolved: u64,
    /// Of those, crossings found by the swept test (the particle had passed the surface).
    pub swept: u64,
    /// Largest penetration corrected (m).
    pub max_penetration: f64,
}

/// A scene's obstacles and response, attached to [`System::post_step`] only when the scene has
/// obstacles (read it back with [`of`]). For `penalty` the forces live in a force term and [`Contacts::apply`] does nothing.
#[derive(Debug, Clone)]
pub struct Contacts {
    /// The obstacles with their broad phase (shared with the penalty term and the metrics).
    pub set: Arc<ObstacleSet>,
    /// The response.
    pub response: Response,
}

impl Contacts {
    /// The stage for `set` with `response`.
    pub fn new(set: Arc<ObstacleSet>, response: Response) -> Self {
        Contacts { set, response }
    }

    /// Name listed by [`System::active_terms`]; `None` for penalty (its force term is listed).
    fn stage_name(&self) -> Option<&'static str> {
        match self.response {
            Response::Impulse => Some("impulse_contacts"),
            Response::Projection => Some("projection_contacts"),
            Response::Penalty { .. } => None,
        }
    }

    /// Resolves contacts after a step of length `h` that took the particles from positions
    /// `x0` and velocities `v0` to `s`. Fixed particles are never touched.
    pub fn apply(
        &self,
        sys: &System,
        x0: &[Vec3],
        v0: &[Vec3],
        s: &mut State,
        h: f64,
    ) -> ContactStep {
        let mut out = ContactStep::default();
        if matches!(self.response, Response::Penalty { .. }) {
            return out;
        }
        let g = sys.gravity.unwrap_or_else(Vec3::zeros);
        for p in 0..s.x.len() {
            // Fixed particles never move; a non-finite state is the runner's to report.
            if !sys.free[p] || !s.x[p].iter().all(|c| c.is_finite()) {
                continue;
            }
            let (x_in, v_in) = (s.x[p], s.v[p]);
            let r = sys.radius[p];
            let mut touched = false;
            // The elastic energy at p before its first correction (module docs).
            let mut elastic_before = None;
            // 1. A crossing between steps: the path entered an obstacle's surface. The particle
            // goes back onto the entry face's tangent plane (its travel along the face kept),
            // never back to where the path met the surface.
            if let Some(hit) = self.set.sweep(&x0[p], &s.x[p]) {
                let end = self.set.query(hit.obstacle, &s.x[p], 0.0);
                // Only a real crossing: the end is behind the entry face (inside, or through).
                let behind = (s.x[p] - hit.point).dot(&hit.normal) < 0.0;
                if behind || end.distance < 0.0 {
                    elastic_before.get_or_insert_with(|| sys.elastic_at(p, &s.x));
                    let depth = -(s.x[p] - hit.point).dot(&hit.normal) + r;
                    let c = Contact {
                        obstacle: hit.obstacle,
                        distance: 0.0,
                        gap: -depth,
                        normal: hit.normal,
                        point: hit.point,
                    };
                    let lift = depth.max(0.0) + self.clearance(c.obstacle, &s.x[p]);
                    s.x[p] += hit.normal * lift;
                    self.respond(&c, p, x0, v0, s, h);
                    touched = true;
                    out.resolved += 1;
                    out.swept += 1;
                    out.max_penetration = out.max_penetration.max(depth);
                }
            }
            // 2. Overlaps at the new position, resolved one obstacle after another.
            let mut overlaps = [None; 8];
            let mut n = 0;
            self.set.for_each_near(&s.x[p], r, 0.0, |c| {
                if n < overlaps.len() {
                    overlaps[n] = Some(c);
                    n += 1;
                }
            });
            for c in overlaps.iter().take(n).flatten() {
                // Re-query after earlier corrections moved the particle.
                let c = if n > 1 || touched {
                    self.set.query(c.obstacle, &s.x[p], r)
                } else {
                    *c
                };
                if c.gap >= 0.0 {
                    continue;
                }
                elastic_before.get_or_insert_with(|| sys.elastic_at(p, &s.x));
                let lift = self.clearance(c.obstacle, &s.x[p]) - c.gap;
                s.x[p] += c.normal * lift;
                self.respond(&c, p, x0, v0, s, h);
                touched = true;
                out.resolved += 1;
                out.max_penetration = out.max_penetration.max(-c.gap);
            }
            if let Some(e0) = elastic_before {
                // This move's energy change: p's kinetic and gravitational energy and the
                // elastic energy at p.
                let m = sys.mass[p];
                let de = 0.5 * m * (s.v[p].norm_squared() - v_in.norm_squared())
                    - m * g.dot(&(s.x[p] - x_in))
                    + (sys.elastic_at(p, &s.x) - e0);
                book(&mut out, de);
                out.changed = true;
            }
        }
        out
    }

    /// How far off the surface a response leaves a particle at `x` against obstacle `k`:
    /// [`SHEET_CLEARANCE`] for a two-sided sheet (so the particle keeps its side), else 0.
    fn clearance(&self, k: usize, x: &Vec3) -> f64 {
        if self.set.obstacles()[k].two_sided {
            SHEET_CLEARANCE * (1.0 + x.norm())
        } else {
            0.0
        }
    }

    /// The impulse response's velocity after an impact on obstacle `obstacle` with outward unit
    /// normal `n`: an approaching normal velocity is reflected with the obstacle's restitution
    /// and the tangential part loses up to μ × the normal velocity change (Coulomb friction
    /// impulse, stopping it at most). A separating velocity is returned unchanged. The
    /// adaptive reference applies the same law at its located impact times.
    pub fn impulse_velocity(&self, obstacle: usize, n: &Vec3, v: Vec3) -> Vec3 {
        let o = &self.set.obstacles()[obstacle];
        let (e, mu) = (o.restitution, o.friction);
        let vn = v.dot(n);
        if vn >= 0.0 {
            return v;
        }
        let dvn = -(1.0 + e) * vn;
        let vt = v - n * vn;
        let vtn = vt.norm();
        let keep = if vtn > 0.0 {
            (1.0 - mu * dvn / vtn).max(0.0)
        } else {
            0.0
        };
        vt * keep - n * (e * vn)
    }

    /// Velocity response for particle `p` already moved onto the surface of contact `c`, with
    /// the friction's effect on the step's tangential displacement (see [`Response`]).
    fn respond(&self, c: &Contact, p: usize, x0: &[Vec3], v0: &[Vec3], s: &mut State, h: f64) {
        let o = &self.set.obstacles()[c.obstacle];
        let (e, mu, n) = (o.restitution, o.friction, c.normal);
        let tangential = |v: Vec3| v - n * v.dot(&n);
        let v_in = s.v[p];
        let vn_in = v_in.dot(&n);
        match self.response {
            Response::Impulse | Response::Penalty { .. } => {
                let v = self.impulse_velocity(c.obstacle, &n, v_in);
                let vt = tangential(v);
                if mu > 0.0 && vt != tangential(v_in) {
                    // Friction acted: its velocity change moves the step's end as a constant
                    // force over the step would, by h/2 times it (exact for constant
                    // deceleration; the method's own travel under the other forces is
                    // kept, so its stability is its own). A particle friction stops travels
                    // the trapezoid h·v_t,start/2 instead: zero for a stuck one, no creep.
                    if vt == Vec3::zeros() {
                        let d = s.x[p] - x0[p];
                        s.x[p] = x0[p] + n * d.dot(&n) + tangential(v0[p]) * (0.5 * h);
                    } else {
                        s.x[p] += (vt - tangential(v_in)) * (0.5 * h);
                    }
                }
                s.v[p] = v;
            }
            Response::Projection => {
                // Position-level Coulomb friction: the tangential displacement of this step
                // loses at most μ·Δv_n·h, where Δv_n = (1 + e)·(approach speed) is the normal
                // velocity change the contact makes (the same for every method, unlike the
                // per-step penetration depth); the velocity loses at most μ·Δv_n.
                let dvn = if vn_in < 0.0 { -(1.0 + e) * vn_in } else { 0.0 };
                let cut = mu * dvn;
                let dt_ = tangential(s.x[p] - x0[p]);
                let dtn = dt_.norm();
                if cut > 0.0 && dtn > 0.0 {
                    s.x[p] -= dt_ * (cut * h / dtn).min(1.0);
                }
                let vt = tangential(v_in);
                let vtn = vt.norm();
                let keep = if vtn > 0.0 {
                    (1.0 - cut / vtn).max(0.0)
                } else {
                    0.0
                };
                let vn = if vn_in < 0.0 { -e * vn_in } else { vn_in };
                s.v[p] = vt * keep + n * vn;
            }
        }
    }
}

/// Books an energy change `de` (J) of the contact stage as created (> 0) or dissipated (< 0).
fn book(out: &mut ContactStep, de: f64) {
    if de > 0.0 {
        out.created += de;
    } else {
        out.dissipated -= de;
    }
}

impl PostStep for Contacts {
    fn name(&self) -> Option<&'static str> {
        self.stage_name()
    }
    fn apply(&self, sys: &System, x0: &[Vec3], v0: &[Vec3], s: &mut State, h: f64) -> StageStep {
        let c = Contacts::apply(self, sys, x0, v0, s, h);
        StageStep {
            changed: c.changed,
            dissipated: c.dissipated,
            created: c.created,
        }
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// The contact stage of `sys`, `None` for a scene without obstacles.
pub fn of(sys: &System) -> Option<&Contacts> {
    sys.post_step.as_ref()?.as_any().downcast_ref::<Contacts>()
}
