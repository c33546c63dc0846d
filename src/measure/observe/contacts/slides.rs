//! Friction measured from the trajectory: while a lone particle (only gravity, the contact and
//! friction act on it; the caller picks them) stays on one obstacle without bouncing (a resting
//! contact), its tangential motion is a slide whose mean acceleration along
//! the sliding direction d is compared with the point-mass Coulomb law a = g·d − μ·|g·n|
//! (incline: g(sin θ − μ cos θ); flat: −μg), its stopping distance with v0²/(2|a|), and a
//! particle released at rest where μ·|g·n| ≥ g·d with no motion at all.
//!
//! A slide ends where its particle stops: its tangential speed falls below [`STOP_SPEED`] at a
//! sample, or its motion along the sliding direction reverses between two samples (it then
//! ends at the last sample before the reversal). Friction changes direction with the motion,
//! so what follows is another slide with its own law: a particle pushed up an incline
//! decelerates at g(sin θ + μ cos θ), stops, and slides back at g(sin θ − μ cos θ), two
//! slides. A new slide starts after a stop only where gravity's pull along the surface beats
//! static friction (|g_t| > μ·|g·n|), the only way a lone particle at rest moves again;
//! elsewhere the stopped slide stays as it stopped.

use crate::model::Vec3;
use serde::Serialize;

/// Fewest samples a slide needs to be reported.
pub const MIN_SLIDE_SAMPLES: u32 = 10;
/// Tangential speed (m/s) below which a sliding particle counts as stopped (and a released
/// one as at rest).
pub const STOP_SPEED: f64 = 1e-6;

/// One slide of a particle on an obstacle.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Slide {
    /// Particle index.
    pub particle: usize,
    /// Obstacle index.
    pub obstacle: usize,
    /// First sample of the resting contact (s).
    pub t_start: f64,
    /// Last sample measured: the stop, or the end of the contact (s).
    pub t_end: f64,
    /// Tangential speed at `t_start` (m/s).
    pub speed_start: f64,
    /// Tangential speed at `t_end` (m/s).
    pub speed_end: f64,
    /// Distance travelled along the sliding direction by `t_end` (m).
    pub distance: f64,
    /// Mean acceleration along the sliding direction over the slide (m/s²).
    pub acceleration: f64,
    /// Point-mass Coulomb law along the same direction: g·d − μ|g·n|, or 0 when static
    /// friction holds a particle released at rest (m/s²).
    pub expected_acceleration: f64,
    /// True when the slide ended with the particle stopping: its speed fell below
    /// [`STOP_SPEED`], or its motion reversed before the next sample (module docs).
    pub stopped: bool,
    /// v0²/(2|a|) for a decelerating slide (m).
    pub expected_stop_distance: Option<f64>,
}

/// What a new sample did to an open slide.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pushed {
    /// The sample belongs to the slide (or the slide stays stopped).
    Kept,
    /// The particle stopped and gravity pulls it on: the slide is over, and a new one starts
    /// at this sample (module docs).
    Ended,
}

/// A slide being measured.
#[derive(Debug, Clone, Copy)]
pub(super) struct OpenSlide {
    obstacle: usize,
    normal: Vec3,
    dir: Vec3,
    /// Gravity's pull along the surface beats static friction: a stop is followed by a new
    /// slide.
    moves_from_rest: bool,
    samples: u32,
    t0: f64,
    x0: Vec3,
    v0: f64,
    mu: f64,
    t: f64,
    x: Vec3,
    v: f64,
    stopped: bool,
}

impl OpenSlide {
    /// Starts a slide at (t, x, v) on obstacle `k` with outward normal `n`, friction `mu`,
    /// under gravity `g`; `None` without a sliding direction (no motion, no pull).
    pub(super) fn start(
        t: f64,
        x: Vec3,
        v: Vec3,
        k: usize,
        n: Vec3,
        mu: f64,
        g: Vec3,
    ) -> Option<Self> {
        let vt = v - n * v.dot(&n);
        let gt = g - n * g.dot(&n);
        let dir = if vt.norm() > STOP_SPEED {
            vt.normalize()
        } else if gt.norm() > 0.0 {
            gt.normalize()
        } else {
            return None;
        };
        let v0 = vt.dot(&dir);
        let press = (-g.dot(&n)).max(0.0);
        Some(OpenSlide {
            obstacle: k,
            normal: n,
            dir,
            moves_from_rest: gt.norm() > mu * press,
            samples: 1,
            t0: t,
            x0: x,
            v0,
            mu,
            t,
            x,
            v: v0,
            stopped: false,
        })
    }

    /// The obstacle slid on.
    pub(super) fn obstacle(&self) -> usize {
        self.obstacle
    }

    /// Adds a sample. A stop at this sample ends the slide with it, a reversal since the last
    /// sample ends it before it; either is [`Pushed::Ended`] when gravity pulls the particle
    /// on, else the slide stays frozen at the stop.
    pub(super) fn push(&mut self, t: f64, x: Vec3, v: Vec3) -> Pushed {
        if self.stopped {
            return Pushed::Kept;
        }
        let vt = v - self.normal * v.dot(&self.normal);
        let along = vt.dot(&self.dir);
        let moving = self.v0 > STOP_SPEED;
        if moving && vt.norm() > STOP_SPEED && along < 0.0 {
            // Reversed between the last sample and this one: the slide ends at the last.
            self.stopped = true;
        } else {
            self.samples += 1;
            self.t = t;
            self.x = x;
            self.v = along;
            self.stopped = moving && vt.norm() <= STOP_SPEED;
        }
        if self.stopped && self.moves_from_rest {
            Pushed::Ended
        } else {
            Pushed::Kept
        }
    }

    /// The measured slide of particle `p` under gravity `g`, if long enough.
    pub(super) fn finish(&self, p: usize, g: Vec3) -> Option<Slide> {
        if self.samples < MIN_SLIDE_SAMPLES || self.t <= self.t0 {
            return None;
        }
        let press = (-g.dot(&self.normal)).max(0.0);
        let law = g.dot(&self.dir) - self.mu * press;
        let at_rest = self.v0 <= STOP_SPEED;
        let expected = if at_rest { law.max(0.0) } else { law };
        Some(Slide {
            particle: p,
            obstacle: self.obstacle,
            t_start: self.t0,
            t_end: self.t,
            speed_start: self.v0,
            speed_end: self.v,
            distance: (self.x - self.x0).dot(&self.dir),
            acceleration: (self.v - self.v0) / (self.t - self.t0),
            expected_acceleration: expected,
            stopped: self.stopped,
            expected_stop_distance: (!at_rest && expected < 0.0)
                .then(|| self.v0 * self.v0 / (-2.0 * expected)),
        })
    }
}
