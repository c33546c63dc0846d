//! Advancing one particle's contact record to a new accepted state: tunnelling, touching,
//! leaving, impacts resolved between two samples, and apex heights.

use super::{Apex, ContactMetrics, Open, Sample, Tunnelling, CONTACT_GAP, THROUGH_SAMPLES};
use crate::collide::Contact;
use crate::model::State;

impl ContactMetrics {
    /// Advances particle `p`'s contact record (its state machine and the bounce, rest and
    /// slide figures) to the sample `s`.
    pub(super) fn sample(&mut self, p: usize, s: &State) {
        let x = s.x[p];
        let v = s.v[p];
        let r = self.radius[p];
        let is_tracked = self.tracked.contains(&p);
        let margin = if is_tracked {
            f64::INFINITY
        } else {
            2.0 * v.norm() * self.dt + 1e-3
        };
        let near = self.set.nearest(&x, r, margin);
        let un = near.map_or(0.0, |c| v.dot(&c.normal));
        let tol = 1e-9 * (1.0 + x.norm());
        let in_contact = near.is_some_and(|c| c.gap < CONTACT_GAP);
        let prev = self.tracks[p].prev;
        let now = Sample {
            t: s.t,
            x,
            near,
            un,
        };
        if let Some(pr) = prev {
            self.swept_through(p, &pr, &now, tol);
        }
        if in_contact {
            self.touch(p, near.expect("in contact"), prev, &now);
        } else if let Some(o) = self.tracks[p].open.take() {
            self.leave(p, o, &now);
        } else if let (Some(pr), Some(c)) = (prev, near) {
            self.reversed(p, &pr, c, &now);
        }
        if self.lone.contains(&p) {
            self.follow_slide(p, s.t, x, v, near.filter(|_| in_contact));
        }
        if is_tracked {
            if let Some(c) = near {
                self.note_height(p, prev, c, &now, in_contact);
            }
        }
        self.tracks[p].prev = Some(now);
    }

    /// Books a tunnelling event of particle `p` through obstacle `obstacle` at `t`.
    fn tunnelled(&mut self, p: usize, obstacle: usize, t: f64) {
        self.tunnel_count += 1;
        if self.tunnels.len() < 100 {
            self.tunnels.push(Tunnelling {
                particle: p,
                obstacle,
                t,
            });
        }
    }

    /// Tunnelling: the path of particle `p` from sample `pr` to `now` entered an obstacle and
    /// left it; `tol` is the length below which a distance counts as zero.
    fn swept_through(&mut self, p: usize, pr: &Sample, now: &Sample, tol: f64) {
        let x = now.x;
        if let Some(hit) = self.set.sweep(&pr.x, &x) {
            // Through, not along: the end is outside, behind the entry face, and nearest to
            // a face turned away from the entry (a chord sliding over a sphere is not).
            let behind = (x - hit.point).dot(&hit.normal) < -tol;
            let end = self.set.query(hit.obstacle, &x, 0.0);
            if behind && end.distance > tol && end.normal.dot(&hit.normal) < 0.0 {
                self.tunnelled(p, hit.obstacle, now.t);
            }
        }
    }

    /// Particle `p` in contact `c` at `now` (`prev` the sample before): books its
    /// penetration and opens a contact, carried to the surface, when it has none open.
    fn touch(&mut self, p: usize, c: Contact, prev: Option<Sample>, now: &Sample) {
        let pen = (-c.gap).max(0.0);
        self.pen_sum += pen;
        self.pen_count += 1;
        self.pen_max = self.pen_max.max(pen);
        self.pen_min = self.pen_min.min(pen);
        let a_n = self.gravity.dot(&c.normal);
        let track = &mut self.tracks[p];
        match &mut track.open {
            Some(o) => {
                o.max_pen = o.max_pen.max(pen);
                o.samples += 1;
            }
            None => {
                // Touching: carry the last free-flight sample to the surface.
                let (t_in, v_in) = match prev.and_then(|pr| pr.near.map(|pc| (pr, pc))) {
                    Some((pr, pc)) if pc.obstacle == c.obstacle && pc.gap >= 0.0 => {
                        let u0 = pr.un;
                        let u2 = u0 * u0 - 2.0 * a_n * pc.gap;
                        let u = -u2.max(0.0).sqrt();
                        let t = if a_n != 0.0 {
                            pr.t + (u - u0) / a_n
                        } else if u0 < 0.0 {
                            pr.t + pc.gap / -u0
                        } else {
                            pr.t
                        };
                        // The surface may lie beyond the first sample in the contact band.
                        (t.max(pr.t), u)
                    }
                    _ => (now.t, now.un.min(0.0)),
                };
                // Entry side: the normal seen from the last sample outside, if it was near.
                let entry = prev
                    .and_then(|pr| pr.near)
                    .filter(|pc| pc.obstacle == c.obstacle && pc.gap >= 0.0)
                    .map_or(c.normal, |pc| pc.normal);
                track.open = Some(Open {
                    obstacle: c.obstacle,
                    normal: entry,
                    samples: 1,
                    t_in,
                    v_in,
                    max_pen: pen,
                    books: self.books_before,
                });
            }
        }
    }

    /// Particle `p` out of contact at `now` with the contact `o` open: closes it, carried
    /// back to the surface, or books a tunnelling when it left through the opposite face.
    fn leave(&mut self, p: usize, o: Open, now: &Sample) {
        let (near, un) = (now.near, now.un);
        // Through, not off: left a brief contact through the face opposite the entry.
        let through = o.samples <= THROUGH_SAMPLES
            && near.is_some_and(|c| c.obstacle == o.obstacle && c.normal.dot(&o.normal) < 0.0);
        if through {
            self.tunnelled(p, o.obstacle, now.t);
        }
        // Leaving: carry this sample back to the surface.
        let (u1, z1, a_n) = match near {
            Some(c) => (un, c.gap.max(0.0), self.gravity.dot(&c.normal)),
            None => (un, 0.0, 0.0),
        };
        let u = (u1 * u1 - 2.0 * a_n * z1).max(0.0).sqrt();
        let t_out = if a_n != 0.0 {
            now.t - (u1 - u) / a_n
        } else if u1 > 0.0 {
            now.t - z1 / u1
        } else {
            now.t
        };
        // The surface may lie before the last sample in the contact band.
        let t_out = t_out.clamp(o.t_in.min(now.t), now.t);
        let a_n = self.gravity.dot(&o.normal);
        self.close(p, &o, t_out, u, a_n, through);
    }

    /// An approach reversed into a separation between samples `pr` and `now`, neither in
    /// contact, near `c`: an impact resolved within one step in front of the surface (an
    /// engine's speculative contact). Gravity alone never reverses an approach (a_n ≤ 0).
    fn reversed(&mut self, p: usize, pr: &Sample, c: Contact, now: &Sample) {
        let un = now.un;
        let a_n = self.gravity.dot(&c.normal);
        let same = pr.near.is_some_and(|pc| pc.obstacle == c.obstacle);
        let reach = (pr.un.abs() + un.abs()) * (now.t - pr.t) + CONTACT_GAP;
        if same && pr.un < 0.0 && un > 0.0 && a_n <= 0.0 && c.gap < reach {
            let pc = pr.near.expect("same obstacle");
            let v_in = -(pr.un * pr.un - 2.0 * a_n * pc.gap).max(0.0).sqrt();
            let v_out = (un * un + 2.0 * a_n * c.gap).max(0.0).sqrt();
            let t_in = if a_n != 0.0 {
                pr.t + (v_in - pr.un) / a_n
            } else {
                pr.t + pc.gap / -pr.un
            };
            let o = Open {
                obstacle: c.obstacle,
                normal: c.normal,
                samples: 0,
                t_in: t_in.clamp(pr.t, now.t),
                v_in,
                max_pen: 0.0,
                books: self.books_before,
            };
            let t_out = if a_n != 0.0 {
                now.t - (un - v_out) / a_n
            } else {
                now.t - c.gap / un
            };
            self.close(p, &o, t_out.clamp(o.t_in, now.t), v_out, a_n, false);
        }
    }

    /// Tracked particle `p` near `c` at `now` (`prev` the sample before): records its height
    /// and, at the top of a free flight, its apex against the predicted one.
    fn note_height(
        &mut self,
        p: usize,
        prev: Option<Sample>,
        c: Contact,
        now: &Sample,
        in_contact: bool,
    ) {
        let un = now.un;
        let track = &mut self.tracks[p];
        track.heights.push([now.t, c.gap]);
        let a_n = self.gravity.dot(&c.normal);
        let rising_before = prev.is_some_and(|pr| pr.un > 0.0);
        let first = prev.is_none();
        if a_n < 0.0 && !in_contact && un <= 0.0 && (rising_before || first) {
            let (t0, z0, u0) = match prev {
                Some(pr) if !first => (pr.t, pr.near.map_or(c.gap, |n| n.gap), pr.un),
                _ => (now.t, c.gap, un.max(0.0)),
            };
            let height = z0 + u0 * u0 / (-2.0 * a_n);
            let t = t0 + u0 / -a_n;
            let h0 = track.apexes.first().map_or(height, |a| a.height);
            let bounce = track.bounces;
            let prev_h = track.apexes.last().map(|a| a.height);
            let e = track.last_e;
            let ratio = prev_h.filter(|h| *h > 0.0).map(|h| height / h);
            let predicted = match e {
                Some(e) => h0 * e.powi(2 * bounce as i32),
                None => h0,
            };
            track.apexes.push(Apex {
                bounce,
                t,
                height,
                predicted,
                ratio,
                expected_ratio: prev_h.and(e.map(|e| e * e)),
                energy_lost: ratio.map(|r| 1.0 - r),
                expected_energy_lost: prev_h.and(e.map(|e| 1.0 - e * e)),
            });
        }
    }
}
