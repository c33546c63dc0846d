//! The post-step contact stage for the `impulse` and `projection` responses: after each
//! accepted integrator step, the runner calls [`Contacts::apply`], which resolves every
//! particle's contacts (including crossings between steps found by a swept test) and reports
//! the mechanical energy the response removed, so the run's energy account stays a balance.

use super::def::Response;
use super::obstacles::{Contact, ObstacleSet};
use crate::model::{PostStep, StageStep, State, System, Vec3};
use std::sync::Arc;

/// What the contact stage did in one step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactStep {
    /// True when some position or velocity changed (the integrator must then be reset).
    pub changed: bool,
    /// Mechanical energy removed by the responses (J); negative when pushing a particle out
    /// raised its potential energy more than the impulse removed.
    pub dissipated: f64,
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

    /// Resolves contacts after a step of length `h` that moved the particles from `x0` to
    /// `s.x`. Fixed particles are never touched.
    pub fn apply(&self, sys: &System, x0: &[Vec3], s: &mut State, h: f64) -> ContactStep {
        let mut out = ContactStep::default();
        if matches!(self.response, Response::Penalty { .. }) {
            return out;
        }
        let mut e_before = None;
        for p in 0..s.x.len() {
            // Fixed particles never move; a non-finite state is the runner's to report.
            if !sys.free[p] || !s.x[p].iter().all(|c| c.is_finite()) {
                continue;
            }
            let r = sys.radius[p];
            // 1. A crossing between steps: the path entered an obstacle's surface.
            if let Some(hit) = self.set.sweep(&x0[p], &s.x[p]) {
                let end = self.set.query(hit.obstacle, &s.x[p], 0.0);
                // Only a real crossing: the end is behind the entry face (inside, or through).
                if (s.x[p] - hit.point).dot(&hit.normal) < 0.0 || end.distance < 0.0 {
                    e_before.get_or_insert_with(|| sys.energy(&s.x, &s.v).mechanical());
                    let depth = -(s.x[p] - hit.point).dot(&hit.normal) + r;
                    let c = Contact {
                        obstacle: hit.obstacle,
                        distance: 0.0,
                        gap: -depth,
                        normal: hit.normal,
                        point: hit.point,
                    };
                    s.x[p] = hit.point + hit.normal * r;
                    self.respond(&c, p, x0, s, h);
                    out.resolved += 1;
                    out.swept += 1;
                    out.max_penetration = out.max_penetration.max(depth);
                    continue;
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
                let c = if n > 1 {
                    self.set.query(c.obstacle, &s.x[p], r)
                } else {
                    *c
                };
                if c.gap >= 0.0 {
                    continue;
                }
                e_before.get_or_insert_with(|| sys.energy(&s.x, &s.v).mechanical());
                s.x[p] += c.normal * (-c.gap);
                self.respond(&c, p, x0, s, h);
                out.resolved += 1;
                out.max_penetration = out.max_penetration.max(-c.gap);
            }
        }
        if let Some(e0) = e_before {
            out.changed = true;
            out.dissipated = e0 - sys.energy(&s.x, &s.v).mechanical();
        }
        out
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

    /// Velocity response for particle `p` already moved onto the surface of contact `c`.
    fn respond(&self, c: &Contact, p: usize, x0: &[Vec3], s: &mut State, h: f64) {
        let o = &self.set.obstacles()[c.obstacle];
        let (e, mu, n) = (o.restitution, o.friction, c.normal);
        match self.response {
            Response::Impulse | Response::Penalty { .. } => {
                s.v[p] = self.impulse_velocity(c.obstacle, &n, s.v[p]);
            }
            Response::Projection => {
                // Position-level Coulomb friction: the tangential displacement of this step is
                // cut by μ × the corrected depth (sticking when it is smaller).
                let depth = -c.gap;
                let dx = s.x[p] - x0[p];
                let dt_ = dx - n * dx.dot(&n);
                let dtn = dt_.norm();
                if mu > 0.0 && dtn > 0.0 {
                    let cut = (mu * depth / dtn).min(1.0);
                    s.x[p] -= dt_ * cut;
                }
                // Implied velocity, with the approach speed reflected by the restitution.
                let vn_in = s.v[p].dot(&n);
                let mut v = (s.x[p] - x0[p]) / h;
                if vn_in < 0.0 {
                    v += n * (-e * vn_in - v.dot(&n));
                }
                s.v[p] = v;
            }
        }
    }
}

impl PostStep for Contacts {
    fn name(&self) -> Option<&'static str> {
        self.stage_name()
    }
    fn apply(&self, sys: &System, x0: &[Vec3], s: &mut State, h: f64) -> StageStep {
        let c = Contacts::apply(self, sys, x0, s, h);
        StageStep {
            changed: c.changed,
            dissipated: c.dissipated,
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
