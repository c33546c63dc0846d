//! Collision validation metrics, measured by an [`Observer`] from the accepted states alone
//! (so they measure what a response really did, whatever it is):
//!
//! - per contact event: normal velocity in and out, measured restitution next to the expected
//!   one, contact duration and maximum penetration next to the expected ones. For impulse and
//!   projection the expectation is the obstacle's e, no penetration and no duration; for
//!   penalty it is the contact ODE with gravity along the normal, solved per impact from the
//!   measured approach speed ([`crate::collide::penalty_impact`]);
//! - impacts are found the same way for every method, from each particle's state relative to
//!   its nearest obstacle: touching (gap below [`CONTACT_GAP`], which covers an engine's
//!   resting gap) and leaving, or an approach reversed into a separation between two samples
//!   near the obstacle without a sample in contact (an engine's speculative contact);
//! - a summary over the impacts faster than [`IMPACT_SPEED_SHARE`] of the fastest approach:
//!   mean and worst deviation of the measured restitution from the expected one;
//! - per lone particle (the first [`TRACKED_PARTICLES`] free ones with no spring, constraint
//!   or drag acting on them, so only gravity, the contact and friction do): slides in resting
//!   contact (a stop ends one: up an incline and back are two), their mean acceleration
//!   against the point-mass Coulomb law and their stopping
//!   distance against v0²/(2|a|) ([`Slide`]). A particle held by springs obeys Coulomb's law
//!   with its spring forces in it, which the accepted states alone cannot give; such scenes
//!   report no slides and say why ([`ContactReport::slides_unmeasured`]);
//! - per tracked particle: apex heights after each bounce against h0·e^(2n), energy lost per
//!   bounce against 1 − e², and the height over time;
//! - per run: penetration statistics and tunnelling events: a path between two accepted states
//!   that enters an obstacle and ends outside it behind the entry face, or a contact of at most
//!   [`THROUGH_SAMPLES`] states left through the face opposite the entry.
//!
//! Sampled velocities are carried to the moment of touching the surface with the ballistic
//! relation u² = u₀² − 2 a_n z₀ (a_n = g·n): exact in free flight, so a step of dt does not bias
//! the in/out speeds by g·dt. Apexes use the same relation from the last rising sample. For a
//! particle held by springs or constraints the carry leaves their pull out, so its slow impacts
//! (where that pull over a step rivals the approach speed) measure far from e: on
//! chain_on_box the first impacts read 0.2001–0.2008 for 0.2, later slow ones up to 1.2.

use crate::collide::{damping_ratio_for_restitution, restitution_for_damping_ratio};
use crate::collide::{Contact, ObstacleSet, PenaltyDamping, Response};
use crate::error::Result;
use crate::model::{State, System, Vec3};
use crate::run::{EnergyRecord, Observer};
use std::sync::Arc;

pub mod differences;
mod report;
mod sample;
mod slides;
pub use report::{
    write_report, Apex, ContactEvent, ContactReport, ObstacleInfo, ParticleBounces, Stats,
    Tunnelling,
};
use slides::{OpenSlide, Pushed};
pub use slides::{Slide, MIN_SLIDE_SAMPLES, STOP_SPEED};

/// Particles whose apex heights and height-over-time series are recorded (the first free ones).
pub const TRACKED_PARTICLES: usize = 8;
/// Most contact events listed one by one (all are counted and enter the statistics).
pub const MAX_LISTED_EVENTS: usize = 10_000;
/// A contact of at most this many accepted states, left through the face opposite the one it
/// entered by, is a tunnelling event (the particle went through, not off).
pub const THROUGH_SAMPLES: u32 = 3;
/// Gap (m) below which a particle counts as touching an obstacle: it covers the gap at which
/// an engine holds a resting contact (Rapier: 3e-5 to 2e-4 m, from its speculative and soft
/// contacts; springlab's own responses hold 0).
pub const CONTACT_GAP: f64 = 5e-4;
/// [`ContactReport::slides_unmeasured`] when no particle is lone (see the module docs).
pub const NO_LONE_PARTICLE: &str = "no free slides: every particle is held by springs or constraints or slowed by drag, so the point-mass Coulomb law does not apply";
/// Most points of each height-over-time series (evenly decimated at the end).
pub const MAX_SERIES_POINTS: usize = 4_000;
/// The restitution summary covers impacts whose approach speed is at least this share of the
/// fastest one (tiny late bounces, measured at a few samples, would dominate a plain mean).
pub const IMPACT_SPEED_SHARE: f64 = 0.01;

#[derive(Debug, Clone, Copy)]
struct Sample {
    t: f64,
    x: Vec3,
    near: Option<Contact>,
    un: f64,
}

#[derive(Debug, Clone, Copy)]
struct Open {
    obstacle: usize,
    normal: Vec3,
    samples: u32,
    t_in: f64,
    v_in: f64,
    max_pen: f64,
    /// The run's (dissipated, created) accounts at the sample before touching.
    books: (f64, f64),
}

#[derive(Debug, Default)]
struct Track {
    prev: Option<Sample>,
    open: Option<Open>,
    bounces: u32,
    last_e: Option<f64>,
    apexes: Vec<Apex>,
    /// `[t, gap]` while near an obstacle, decimated past [`crate::measure::decimated::MAX_KEPT`].
    heights: crate::measure::decimated::Decimated<[f64; 2]>,
    slide: Option<OpenSlide>,
}

/// The metrics observer; attach it to a run of a system with obstacles and call
/// [`ContactMetrics::report`] afterwards.
#[derive(Debug)]
pub struct ContactMetrics {
    set: Arc<ObstacleSet>,
    response: Response,
    gravity: Vec3,
    mass: Vec<f64>,
    radius: Vec<f64>,
    free: Vec<bool>,
    dt: f64,
    tracks: Vec<Track>,
    tracked: Vec<usize>,
    /// Particles whose slides are measured: free, with only gravity, contact and friction
    /// acting (see the module docs).
    lone: Vec<usize>,
    events: Vec<ContactEvent>,
    events_total: u64,
    /// (|v_in|, measured e, expected e) of every impact with a measured restitution.
    impacts: Vec<(f64, f64, f64)>,
    event_pen: Vec<f64>,
    pen_sum: f64,
    pen_count: u64,
    pen_max: f64,
    pen_min: f64,
    tunnels: Vec<Tunnelling>,
    tunnel_count: u64,
    q0: u64,
    q1: u64,
    /// The run's (dissipated, created) accounts at the previous and the current sample.
    books_before: (f64, f64),
    books: (f64, f64),
    slides: Vec<Slide>,
}

impl ContactMetrics {
    /// Metrics for `sys` sampled every `dt`; `None` when the system has no obstacles.
    pub fn new(sys: &System, dt: f64) -> Option<Self> {
        let c = crate::collide::of(sys)?;
        let tracked: Vec<usize> = (0..sys.len())
            .filter(|&p| sys.free[p])
            .take(TRACKED_PARTICLES)
            .collect();
        let mut held = vec![false; sys.len()];
        for (&i, &j) in sys.springs.i.iter().zip(&sys.springs.j) {
            held[i as usize] = true;
            held[j as usize] = true;
        }
        for c in &sys.constraints {
            held[c.i] = true;
            held[c.j] = true;
        }
        let lone: Vec<usize> = (0..sys.len())
            .filter(|&p| sys.free[p] && !held[p] && sys.drag.is_none())
            .take(TRACKED_PARTICLES)
            .collect();
        Some(ContactMetrics {
            set: c.set.clone(),
            response: c.response,
            gravity: sys.gravity.unwrap_or_else(Vec3::zeros),
            mass: sys.mass.clone(),
            radius: sys.radius.clone(),
            free: sys.free.clone(),
            dt,
            tracks: (0..sys.len()).map(|_| Track::default()).collect(),
            tracked,
            lone,
            events: Vec::new(),
            events_total: 0,
            impacts: Vec::new(),
            event_pen: Vec::new(),
            pen_sum: 0.0,
            pen_count: 0,
            pen_max: f64::NEG_INFINITY,
            pen_min: f64::INFINITY,
            tunnels: Vec::new(),
            tunnel_count: 0,
            q0: crate::collide::query_count(),
            q1: 0,
            books_before: (0.0, 0.0),
            books: (0.0, 0.0),
            slides: Vec::new(),
        })
    }

    /// Expected restitution of particle `p` against obstacle `k` under this response.
    pub fn expected_restitution(&self, k: usize, p: usize) -> f64 {
        match self.zeta(k, p) {
            Some(z) => restitution_for_damping_ratio(z),
            None => self.set.obstacles()[k].restitution,
        }
    }

    fn zeta(&self, k: usize, p: usize) -> Option<f64> {
        let Response::Penalty { stiffness, damping } = self.response else {
            return None;
        };
        Some(match damping {
            PenaltyDamping::Coefficient(c) => c / (2.0 * (stiffness * self.mass[p]).sqrt()),
            PenaltyDamping::Restitution(e) => damping_ratio_for_restitution(e),
            PenaltyDamping::PerObstacle => {
                damping_ratio_for_restitution(self.set.obstacles()[k].restitution)
            }
        })
    }

    /// Approach speed (m/s) below which a contact is resting or grazing and gets no measured
    /// restitution: max(1 mm/s, 2|g|·dt), the speed gravity adds in two samples.
    pub fn grazing_speed(&self) -> f64 {
        (2.0 * self.gravity.norm() * self.dt).max(1e-3)
    }

    /// Penalty only: the contact spring's natural frequency √(k/m) for particle `p`.
    fn omega(&self, p: usize) -> Option<f64> {
        match self.response {
            Response::Penalty { stiffness, .. } => Some((stiffness / self.mass[p]).sqrt()),
            _ => None,
        }
    }

    /// Expected (restitution, penetration, duration) of an impact of particle `p` on obstacle
    /// `k` at approach speed `v_in` with normal gravity `a_n` (see the module docs).
    fn expectation(&self, k: usize, p: usize, v_in: f64, a_n: f64) -> (f64, f64, Option<f64>) {
        match (self.omega(p), self.zeta(k, p)) {
            (Some(w), Some(z)) if v_in != 0.0 => {
                let i = crate::collide::penalty_impact(w, z, a_n, v_in);
                (i.restitution, i.max_penetration, i.duration)
            }
            _ => (self.expected_restitution(k, p), 0.0, Some(0.0)),
        }
    }

    /// Slide bookkeeping of tracked particle `p` at (t, x, v), in contact `c` or not: a slide
    /// runs while the particle stays on one obstacle without a normal speed above the grazing
    /// speed (a bounce ends it).
    fn follow_slide(&mut self, p: usize, t: f64, x: Vec3, v: Vec3, c: Option<Contact>) {
        let resting = c.filter(|c| v.dot(&c.normal).abs() < self.grazing_speed());
        let open = &mut self.tracks[p].slide;
        match (resting, open.as_mut()) {
            (Some(c), Some(sl)) if sl.obstacle() == c.obstacle => {
                if sl.push(t, x, v) == Pushed::Ended {
                    // Stopped and pulled on: the next slide starts here (slides module docs).
                    if let Some(done) = sl.finish(p, self.gravity) {
                        self.slides.push(done);
                    }
                    let mu = self.set.obstacles()[c.obstacle].friction;
                    *open = OpenSlide::start(t, x, v, c.obstacle, c.normal, mu, self.gravity);
                }
            }
            (rest, _) => {
                if let Some(done) = open.take().and_then(|sl| sl.finish(p, self.gravity)) {
                    self.slides.push(done);
                }
                *open = rest.and_then(|c| {
                    let mu = self.set.obstacles()[c.obstacle].friction;
                    OpenSlide::start(t, x, v, c.obstacle, c.normal, mu, self.gravity)
                });
            }
        }
    }

    /// Books the event of particle `p` on the open contact `o`, left at `t_out` with normal
    /// speed `u` (carried to the surface); `a_n` is gravity along the normal.
    fn close(&mut self, p: usize, o: &Open, t_out: f64, u: f64, a_n: f64, through: bool) {
        let (e_exp, pen_exp, dur_exp) = self.expectation(o.obstacle, p, o.v_in, a_n);
        let restitution =
            (!through && o.v_in.abs() > self.grazing_speed()).then(|| u / o.v_in.abs());
        let ev = ContactEvent {
            particle: p,
            obstacle: o.obstacle,
            t_in: o.t_in,
            t_out,
            duration: t_out - o.t_in,
            expected_duration: dur_exp,
            v_in: o.v_in,
            v_out: u,
            restitution,
            expected_restitution: e_exp,
            gravity_share: self
                .omega(p)
                .map(|w| a_n.abs() / (w * o.v_in.abs().max(f64::MIN_POSITIVE))),
            max_penetration: o.max_pen,
            expected_penetration: pen_exp,
            energy_dissipated: self.books.0 - o.books.0,
            energy_created: self.books.1 - o.books.1,
        };
        self.events_total += 1;
        if let Some(e) = restitution {
            self.impacts.push((o.v_in.abs(), e, e_exp));
        }
        self.event_pen.push(o.max_pen);
        if self.events.len() < MAX_LISTED_EVENTS {
            self.events.push(ev);
        }
        let track = &mut self.tracks[p];
        track.bounces += 1;
        track.last_e = Some(e_exp);
    }

    /// The measured metrics (call after the run).
    pub fn report(&self) -> ContactReport {
        let open: Vec<f64> = self
            .tracks
            .iter()
            .filter_map(|t| t.open.map(|o| o.max_pen))
            .collect();
        let bounces = self
            .tracked
            .iter()
            .map(|&p| {
                let t = &self.tracks[p];
                let stride = t.heights.kept().len().div_ceil(MAX_SERIES_POINTS).max(1);
                ParticleBounces {
                    particle: p,
                    apexes: t.apexes.clone(),
                    heights: t.heights.kept().iter().step_by(stride).copied().collect(),
                }
            })
            .collect();
        let fastest = self.impacts.iter().map(|i| i.0).fold(0.0, f64::max);
        let floor = (IMPACT_SPEED_SHARE * fastest).max(self.grazing_speed());
        let summary = self.impacts.iter().filter(move |i| i.0 >= floor);
        let stiff = match self.response {
            Response::Penalty { stiffness, .. } => Some(stiffness),
            _ => None,
        };
        ContactReport {
            response: self.response.kind(),
            dt: self.dt,
            obstacles: self
                .set
                .obstacles()
                .iter()
                .map(|o| ObstacleInfo {
                    shape: o.kind,
                    restitution: o.restitution,
                    friction: o.friction,
                })
                .collect(),
            penalty_stiffness: stiff,
            penalty_steps_per_contact: (0..self.mass.len())
                .filter(|&p| self.free[p])
                .filter_map(|p| self.omega(p))
                .fold(None, |w: Option<f64>, x| Some(w.map_or(x, |w| w.max(x))))
                .map(|w| std::f64::consts::PI / (w * self.dt)),
            events_total: self.events_total,
            open_contacts: open.len() as u64,
            events: self.events.clone(),
            impact_speed_floor: floor,
            restitution: Stats::of(summary.clone().map(|i| i.1)),
            expected_restitution: Stats::of(summary.clone().map(|i| i.2)),
            restitution_deviation: Stats::of(summary.clone().map(|i| i.1 - i.2)),
            restitution_worst_deviation: summary.map(|i| i.1 - i.2).fold(0.0, |w, d| {
                if d.abs() > w.abs() {
                    d
                } else {
                    w
                }
            }),
            penetration: Stats::of(self.event_pen.iter().chain(&open).copied()),
            penetration_samples: if self.pen_count == 0 {
                Stats::default()
            } else {
                Stats {
                    count: self.pen_count,
                    mean: self.pen_sum / self.pen_count as f64,
                    min: self.pen_min,
                    max: self.pen_max,
                }
            },
            tunnelling_count: self.tunnel_count,
            tunnelling: self.tunnels.clone(),
            bounces,
            slides: self
                .slides
                .iter()
                .cloned()
                .chain(self.lone.iter().filter_map(|&p| {
                    self.tracks[p]
                        .slide
                        .as_ref()
                        .and_then(|sl| sl.finish(p, self.gravity))
                }))
                .collect(),
            slides_unmeasured: self.lone.is_empty().then_some(NO_LONE_PARTICLE),
            parry_queries: self.q1.saturating_sub(self.q0),
        }
    }
}

impl Observer for ContactMetrics {
    fn observe(&mut self, _step: u64, s: &State, e: &EnergyRecord) -> Result<()> {
        self.books_before = self.books;
        self.books = (e.dissipated, e.created);
        for p in 0..s.len() {
            if self.free[p] {
                self.sample(p, s);
            }
        }
        self.q1 = crate::collide::query_count();
        Ok(())
    }
    fn finish(&mut self, _step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        self.q1 = crate::collide::query_count();
        Ok(())
    }
}
