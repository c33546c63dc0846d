//! One level of the fine-step reference kept whole: the state (positions and velocities) at the
//! end of every fine step, so the level can be sampled at any time long after it ran.
//!
//! A level steps from 0 on the lattice k·h, landing also on every impulse time and on the
//! horizon, whoever samples it later. Each knot is the state at a step's end and says what the
//! step held: nothing but the equations of motion (smooth), a contact (the contact stage moved
//! a particle or changed a velocity), or the impulses at that time (a jump: the state just after
//! them, at the same time as the knot before).
//!
//! A sample at time t gets:
//! - at a knot's time, that knot (at an impulse time the state just before the impulses, as
//!   the runner samples it);
//! - inside a smooth step with a smooth neighbour, the cubic Hermite interpolant of the step's
//!   end positions and velocities, with its error estimate θ²(1−θ)²h⁴/24 · |x⁗| (at most
//!   h⁴/384 · |x⁗|, the interpolant's remainder), |x⁗| read as the change of the interpolant's
//!   constant third derivative to a smooth neighbouring step over the distance between their
//!   midpoints (the larger of the two sides, largest over particles);
//! - inside a step that holds a contact, or a smooth step with no smooth neighbour to estimate
//!   the interpolant's error from, a partial fine step from the knot before: the method's step
//!   of length t − tₖ, then the contact stage, exactly as a run that lands its step on t does.
//!
//! So nothing is interpolated across a contact or an impulse.

use super::dense::to_vec3;
use super::finestep::FINE_METHOD;
use crate::error::{Error, Result};
use crate::integrate::Stepper;
use crate::method::create as by_name;
use crate::method::MethodOptions;
use crate::model::{State, System, Vec3};

/// What the step ending at a knot held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// The initial state.
    Start,
    /// A step of the equations of motion alone.
    Smooth,
    /// A step after which the contact stage changed the state.
    Contact,
    /// The state just after the impulses at the previous knot's time.
    Jump,
}

/// How a sample was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Via {
    /// A stored knot.
    Knot,
    /// The cubic Hermite interpolant inside a smooth step.
    Hermite,
    /// A partial fine step from the knot before.
    Landed,
}

/// A level's state at one time.
#[derive(Debug, Clone)]
pub(super) struct Sample {
    /// Positions (m).
    pub x: Vec<Vec3>,
    /// The interpolant's error estimate (m, largest over particles); 0 unless interpolated.
    pub estimate: f64,
    /// How it was made.
    pub via: Via,
}

/// One fine-step run kept whole, knot by knot.
#[derive(Debug, Clone)]
pub(super) struct Level {
    n3: usize,
    /// The lattice step (s).
    pub h: f64,
    times: Vec<f64>,
    kinds: Vec<Kind>,
    /// Per knot: 3n positions, then 3n velocities.
    data: Vec<f64>,
}

/// Bytes per knot of `n` particles (positions, velocities, time and kind).
pub(super) fn knot_bytes(n: usize) -> usize {
    48 * n + 9
}

/// Most knots a level of step `h` over `horizon` can hold: the lattice, one landing and one
/// jump per impulse, the start.
pub(super) fn most_knots(sys: &System, horizon: f64, h: f64) -> usize {
    (horizon / h).ceil() as usize + 1 + 2 * sys.impulses.len()
}

/// Runs the fine method with the scene's contact stage from `s0` on the lattice of step `h` to
/// `horizon` and keeps every knot; returns the level and its force evaluations.
pub(super) fn record(sys: &System, s0: &State, horizon: f64, h: f64) -> Result<(Level, u64)> {
    let mut stepper = by_name(FINE_METHOD, &MethodOptions::default())?;
    let n = sys.len();
    let mut level = Level {
        n3: 3 * n,
        h,
        times: Vec::new(),
        kinds: Vec::new(),
        data: Vec::with_capacity(most_knots(sys, horizon, h) * 6 * n),
    };
    let mut s = s0.clone();
    s.t = 0.0;
    level.push(&s, Kind::Start);
    let (mut imp, mut k, mut evals) = (0, 0_u64, 0);
    let mut x0 = s.x.clone();
    let mut v0 = s.v.clone();
    stepper.reset();
    while s.t < horizon {
        let mut kicked = false;
        while imp < sys.impulses.len() && sys.impulses[imp].time <= s.t {
            let im = sys.impulses[imp];
            s.v[im.particle] += im.delta_v;
            imp += 1;
            kicked = true;
        }
        if kicked {
            stepper.reset();
            level.push(&s, Kind::Jump);
        }
        while k as f64 * h <= s.t {
            k += 1;
        }
        let mut target = (k as f64 * h).min(horizon);
        if let Some(im) = sys.impulses.get(imp) {
            target = target.min(im.time);
        }
        x0.clone_from(&s.x);
        v0.clone_from(&s.v);
        let (e, contact) = step_to(sys, stepper.as_mut(), &mut s, &x0, &v0, target)?;
        evals += e;
        if !s.x.iter().all(|x| x.iter().all(|c| c.is_finite())) {
            return Err(Error::Step(format!(
                "fine-step reference ({FINE_METHOD} at {h:e} s) blew up at t = {}",
                s.t
            )));
        }
        level.push(&s, if contact { Kind::Contact } else { Kind::Smooth });
    }
    Ok((level, evals))
}

/// One step of the fine method from `s` (positions `x0`, velocities `v0`) to time `target`,
/// then the contact stage: the force evaluations and whether the stage changed the state.
fn step_to(
    sys: &System,
    stepper: &mut dyn Stepper,
    s: &mut State,
    x0: &[Vec3],
    v0: &[Vec3],
    target: f64,
) -> Result<(u64, bool)> {
    let step = target - s.t;
    let evals = stepper.step(sys, s, step)?.force_evals;
    let mut contact = false;
    if let Some(c) = &sys.post_step {
        if c.apply(sys, x0, v0, s, step).changed {
            stepper.reset();
            contact = true;
        }
    }
    s.t = target;
    Ok((evals, contact))
}

impl Level {
    fn push(&mut self, s: &State, kind: Kind) {
        self.times.push(s.t);
        self.kinds.push(kind);
        for part in [&s.x, &s.v] {
            for p in part.iter() {
                self.data.extend_from_slice(&[p.x, p.y, p.z]);
            }
        }
    }

    /// Bytes held.
    pub(super) fn bytes(&self) -> usize {
        8 * (self.data.len() + self.times.len()) + self.kinds.len()
    }

    /// Number of knots.
    pub(super) fn knots(&self) -> usize {
        self.times.len()
    }

    /// Time of knot `i` (s).
    pub(super) fn time(&self, i: usize) -> f64 {
        self.times[i]
    }

    /// Positions at knot `i`, 3n numbers.
    pub(super) fn x(&self, i: usize) -> &[f64] {
        let a = 2 * i * self.n3;
        &self.data[a..a + self.n3]
    }

    fn v(&self, i: usize) -> &[f64] {
        let a = (2 * i + 1) * self.n3;
        &self.data[a..a + self.n3]
    }

    /// True when the step ending at knot `end` is a step of the equations of motion alone.
    fn smooth(&self, end: usize) -> bool {
        self.kinds.get(end) == Some(&Kind::Smooth)
    }

    /// The level at time `t` ([module docs](self)); `stepper` is a fine-method stepper for the
    /// partial steps.
    pub(super) fn sample(&self, sys: &System, t: f64, stepper: &mut dyn Stepper) -> Result<Sample> {
        let k = self.times.partition_point(|&u| u < t);
        let knot = |i: usize| Sample {
            x: to_vec3(self.x(i)),
            estimate: 0.0,
            via: Via::Knot,
        };
        if k == self.times.len() {
            return Ok(knot(k - 1));
        }
        if k == 0 || self.times[k] == t {
            return Ok(knot(k));
        }
        if self.smooth(k) {
            if let Some(s) = self.hermite(k, t) {
                return Ok(s);
            }
        }
        self.landed(sys, k - 1, t, stepper)
    }

    /// A partial step of the fine method from knot `i` to time `t`, then the contact stage.
    fn landed(&self, sys: &System, i: usize, t: f64, stepper: &mut dyn Stepper) -> Result<Sample> {
        let (x0, v0) = (to_vec3(self.x(i)), to_vec3(self.v(i)));
        let mut s = State {
            t: self.times[i],
            x: x0.clone(),
            v: v0.clone(),
        };
        stepper.reset();
        step_to(sys, stepper, &mut s, &x0, &v0, t)?;
        Ok(Sample {
            x: s.x,
            estimate: 0.0,
            via: Via::Landed,
        })
    }

    /// The cubic Hermite interpolant inside the smooth step ending at knot `end`, with its
    /// error estimate; None when neither neighbouring step is smooth.
    fn hermite(&self, end: usize, t: f64) -> Option<Sample> {
        let sides: Vec<usize> = [end - 1, end + 1]
            .into_iter()
            .filter(|&e| self.smooth(e))
            .collect();
        if sides.is_empty() {
            return None;
        }
        let (t0, t1) = (self.times[end - 1], self.times[end]);
        let h = t1 - t0;
        let th = (t - t0) / h;
        let (h00, h10) = (
            (1.0 + 2.0 * th) * (1.0 - th).powi(2),
            th * (1.0 - th).powi(2),
        );
        let (h01, h11) = (th * th * (3.0 - 2.0 * th), th * th * (th - 1.0));
        let (x0, v0, x1, v1) = (self.x(end - 1), self.v(end - 1), self.x(end), self.v(end));
        let y: Vec<f64> = (0..self.n3)
            .map(|i| h00 * x0[i] + h10 * h * v0[i] + h01 * x1[i] + h11 * h * v1[i])
            .collect();
        // Remainder of the cubic Hermite interpolant: θ²(1−θ)²h⁴/4! · x⁗.
        let factor = (th * (1.0 - th)).powi(2) * h.powi(4) / 24.0;
        let mid = |e: usize| 0.5 * (self.times[e - 1] + self.times[e]);
        let mut x4 = 0.0_f64;
        for p in 0..self.n3 / 3 {
            let here = self.third(end, p);
            for &e in &sides {
                let d = (here - self.third(e, p)).norm() / (mid(end) - mid(e)).abs();
                x4 = x4.max(d);
            }
        }
        Some(Sample {
            x: to_vec3(&y),
            estimate: factor * x4,
            via: Via::Hermite,
        })
    }

    /// The constant third derivative of particle `p`'s cubic Hermite interpolant on the step
    /// ending at knot `end`: 6(2(x₀ − x₁) + h(v₀ + v₁))/h³.
    fn third(&self, end: usize, p: usize) -> Vec3 {
        let h = self.times[end] - self.times[end - 1];
        let (x0, v0, x1, v1) = (self.x(end - 1), self.v(end - 1), self.x(end), self.v(end));
        let c = |i: usize| 6.0 * (2.0 * (x0[i] - x1[i]) + h * (v0[i] + v1[i])) / h.powi(3);
        Vec3::new(c(3 * p), c(3 * p + 1), c(3 * p + 2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    /// A particle of 1 kg on a spring of stiffness `k` from a fixed anchor, started at rest at
    /// x = 1 + `u0` (displacement u(t) = u₀ cos ωt, ω = √k), with a projection plane at y = −1
    /// it never touches.
    fn oscillator(k: f64, u0: f64) -> Scenario {
        let toml = format!(
            "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
             [[particle]]\nposition=[{x},0.0,0.0]\nmass=1.0\n\
             [[spring]]\nbetween=[0,1]\nstiffness={k}\nrest_length=1.0\n\
             [[obstacle]]\nshape=\"plane\"\npoint=[0.0,-1.0,0.0]\nnormal=[0.0,1.0,0.0]\n\
             [collision]\nresponse=\"projection\"\n",
            x = 1.0 + u0
        );
        Scenario::from_toml_str(&toml, "plane_oscillator.toml").unwrap()
    }

    /// A ball (r = 0.1 m) released at rest with its centre at `y0` above a projection plane
    /// at y = 0, under g = 9.81 m/s².
    fn ball(y0: f64) -> Scenario {
        let toml = format!(
            "[world]\ngravity=[0.0,-9.81,0.0]\n\
             [[particle]]\nposition=[0.0,{y0},0.0]\nmass=1.0\nradius=0.1\n\
             [[obstacle]]\nshape=\"plane\"\npoint=[0.0,0.0,0.0]\nnormal=[0.0,1.0,0.0]\nrestitution=0.5\n\
             [collision]\nresponse=\"projection\"\n"
        );
        Scenario::from_toml_str(&toml, "ball.toml").unwrap()
    }

    fn rk4() -> Box<dyn Stepper> {
        by_name(FINE_METHOD, &MethodOptions::default())
            .unwrap()
            .stepper
    }

    /// A level holding the closed form x = cos ωt, v = −ω sin ωt of one particle exactly at
    /// the knots k·h, k = 0..=steps, every step smooth.
    fn exact_level(w: f64, h: f64, steps: usize) -> Level {
        let mut level = Level {
            n3: 3,
            h,
            times: Vec::new(),
            kinds: Vec::new(),
            data: Vec::new(),
        };
        for k in 0..=steps {
            let t = k as f64 * h;
            let s = State {
                t,
                x: vec![Vec3::new((w * t).cos(), 0.0, 0.0)],
                v: vec![Vec3::new(-w * (w * t).sin(), 0.0, 0.0)],
            };
            level.push(&s, if k == 0 { Kind::Start } else { Kind::Smooth });
        }
        level
    }

    #[test]
    fn hermite_on_exact_knots_has_order_four_within_its_estimate() {
        // Oracle: cos ωt at the knots and between them. The cubic Hermite remainder is
        // θ²(1−θ)²h⁴/24 · x⁗(ξ): halving h divides the error by 2⁴, and the error stays within
        // the estimate read from the neighbouring steps.
        let w = 2.0;
        let worst = |h: f64| {
            let level = exact_level(w, h, (1.5 / h) as usize);
            let (mut err, mut ratio) = (0.0_f64, 0.0_f64);
            for end in 2..level.knots() - 1 {
                for q in [0.25, 0.5, 0.7] {
                    let t = level.time(end - 1) + q * h;
                    let s = level.hermite(end, t).expect("smooth neighbours");
                    let e = (s.x[0].x - (w * t).cos()).abs();
                    err = err.max(e);
                    ratio = ratio.max(e / s.estimate);
                }
            }
            (err, ratio)
        };
        let ((a, ra), (b, rb)) = (worst(0.04), worst(0.02));
        let p = (a / b).log2();
        eprintln!(
            "exact knots: errors {a:e}, {b:e}, order {p:.3}, error / estimate {ra:.3}, {rb:.3}"
        );
        assert!((3.5..4.5).contains(&p), "observed order {p} ({a:e}, {b:e})");
        assert!(
            ra <= 1.0 && rb <= 1.0,
            "error past its estimate: {ra}, {rb}"
        );
    }

    #[test]
    fn sampled_rk4_levels_meet_cos_with_order_four() {
        // Oracle: u₀ cos ωt. Both the rk4 knots and the interpolant between them are fourth
        // order, so the error at samples inside the steps falls by 2⁴ per halving.
        let (k, u0) = (400.0_f64, 0.1);
        let scene = oscillator(k, u0);
        let (sys, s0) = (scene.build(), scene.initial_state());
        let w = k.sqrt();
        let mut st = rk4();
        let worst = |h: f64, st: &mut dyn Stepper| {
            let (level, _) = record(&sys, &s0, 1.0, h).unwrap();
            let mut err = 0.0_f64;
            for i in 1..200 {
                // 4.93 ms apart: a knot of neither level (2.465 i and 1.2325 i are not whole).
                let t = 0.00493 * i as f64;
                let s = level.sample(&sys, t, st).unwrap();
                assert_eq!(s.via, Via::Hermite, "t = {t}");
                err = err.max((s.x[1].x - 1.0 - u0 * (w * t).cos()).abs());
            }
            err
        };
        let (a, b) = (worst(0.004, st.as_mut()), worst(0.002, st.as_mut()));
        let p = (a / b).log2();
        eprintln!("rk4 levels: errors {a:e}, {b:e}, order {p:.3}");
        assert!((3.5..4.5).contains(&p), "observed order {p} ({a:e}, {b:e})");
    }

    #[test]
    fn a_sample_inside_a_contact_step_lands_there_and_one_in_free_fall_is_interpolated() {
        // Oracle for the contact step: today's landing run (`finestep::run_with` asked for the
        // one time t) on the same lattice (h a power of two, so its summed times are exactly
        // k·h): its last step is the partial step from the knot before t, then the contact
        // stage. Oracle for the twin, a step in free fall before the first contact: the closed
        // form y₀ − g t²/2, which rk4 and the cubic interpolant both reproduce to round-off.
        let y0 = 1.1;
        let scene = ball(y0);
        let (sys, s0) = (scene.build(), scene.initial_state());
        let h = 1.0 / 1024.0;
        let (level, _) = record(&sys, &s0, 1.0, h).unwrap();
        let first = (0..level.knots())
            .find(|&i| level.kinds[i] == Kind::Contact)
            .expect("the ball reaches the plane");
        let mut st = rk4();
        let t = level.time(first - 1) + 0.3 * h;
        let inside = level.sample(&sys, t, st.as_mut()).unwrap();
        assert_eq!(inside.via, Via::Landed);
        let mut landed = Vec::new();
        super::super::finestep::run_with(&sys, &s0, &[t], t, h, &mut |_, s| landed = s.x.clone())
            .unwrap();
        assert_eq!(inside.x, landed, "the contact step was not landed on");
        assert!(inside.x[0].y >= 0.1, "the sample is out of the plane");
        // The twin: a step well before the contact.
        let t = level.time(first / 2) + 0.3 * h;
        let free = level.sample(&sys, t, st.as_mut()).unwrap();
        assert_eq!(free.via, Via::Hermite);
        let exact = y0 - 0.5 * 9.81 * t * t;
        assert!(
            (free.x[0].y - exact).abs() < 1e-12,
            "free fall off by {:e}",
            free.x[0].y - exact
        );
        assert!(free.estimate < 1e-12, "estimate {:e}", free.estimate);
    }
}
