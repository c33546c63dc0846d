//! The exact solution for scenes of independent damped linear springs tied to fixed anchors.
//!
//! Each free particle obeys m u'' + c u' + k u = 0 for its displacement u from equilibrium,
//! solved in closed form (under-, critically and over-damped alike) through the fundamental
//! solution u(t) = e^{-γt}[u₀ C(t) + (v₀ + γu₀) S(t)], with γ = c/2m, Δ = γ² - k/m and
//! C, S = cos, sin(√-Δ t)/√-Δ (Δ<0), 1, t (Δ=0), cosh, sinh(√Δ t)/√Δ (Δ>0).
//! It is evaluated from the last reset (start or impulse), so it is exact at any step size.

use super::{StepStats, Stepper};
use crate::error::{Error, Result};
use crate::model::{State, System, Vec3};

/// One free particle's oscillator: its anchor and spring, equilibrium, ω₀², γ.
#[derive(Debug, Clone, Copy)]
struct Oscillator {
    particle: usize,
    anchor: usize,
    spring: usize,
    eq: Vec3,
    w2: f64,
    gamma: f64,
}

/// Closed-form stepper; refuses scenes that are not independent linear oscillators.
#[derive(Debug, Default)]
pub struct Analytic {
    osc: Vec<Oscillator>,
    origin: Option<(f64, Vec<Vec3>, Vec<Vec3>)>,
}

/// e^{-γt}·C(t) and e^{-γt}·S(t), computed without overflow or cancellation.
fn propagators(gamma: f64, w2: f64, t: f64) -> (f64, f64) {
    let delta = gamma * gamma - w2;
    if delta < 0.0 {
        let b = (-delta).sqrt();
        let e = (-gamma * t).exp();
        (e * (b * t).cos(), e * (b * t).sin() / b)
    } else if delta == 0.0 {
        let e = (-gamma * t).exp();
        (e, e * t)
    } else {
        let b = delta.sqrt();
        let slow = (-(gamma - b) * t).exp();
        let fast = (-(gamma + b) * t).exp();
        if 2.0 * b * t > 50.0 {
            (0.5 * (slow + fast), 0.5 * (slow - fast) / b)
        } else {
            // sinh via expm1 keeps accuracy when b·t is small (near-critical damping).
            (
                0.5 * (slow + fast),
                fast * (2.0 * b * t).exp_m1() / (2.0 * b),
            )
        }
    }
}

fn parallel(a: Vec3, n: Vec3) -> bool {
    a.cross(&n).norm() <= 1e-12 * a.norm()
}

impl Analytic {
    /// Builds the oscillators or says why the scene has no closed form here.
    fn oscillators(sys: &System) -> std::result::Result<Vec<Oscillator>, String> {
        if !sys.constraints.is_empty() {
            return Err("the scene has rigid constraints".into());
        }
        if sys.post_step.is_some() {
            return Err("the scene has obstacles: contacts have no closed form here".into());
        }
        if sys
            .terms
            .iter()
            .any(|t| !matches!(t.name(), "gravity" | "drag"))
        {
            return Err("the scene has force terms other than springs, gravity and drag".into());
        }
        let n = sys.len();
        let mut spring_of = vec![None; n];
        let sp = &sys.springs;
        for s in 0..sp.len() {
            let (i, j) = (sp.i[s] as usize, sp.j[s] as usize);
            let (free, anchor) = match (sys.free[i], sys.free[j]) {
                (true, false) => (i, j),
                (false, true) => (j, i),
                (true, true) => {
                    return Err(format!(
                    "spring {s} joins two free particles ({i}, {j}): the oscillators are coupled"
                ))
                }
                (false, false) => continue,
            };
            if spring_of[free].replace((s, anchor)).is_some() {
                return Err(format!("particle {free} has more than one spring"));
            }
        }
        let drag = sys.drag.unwrap_or(0.0);
        let mut out = Vec::new();
        // The geometry (axis, equilibrium) needs the state, so `resolve` completes it.
        for p in (0..n).filter(|&p| sys.free[p]) {
            let Some((s, anchor)) = spring_of[p] else {
                return Err(format!("free particle {p} has no spring to a fixed anchor"));
            };
            if sp.k[s] <= 0.0 {
                return Err(format!("spring {s} has zero stiffness"));
            }
            let m = sys.mass[p];
            out.push(Oscillator {
                particle: p,
                anchor,
                spring: s,
                eq: Vec3::zeros(),
                w2: sp.k[s] / m,
                gamma: (sp.c[s] + drag) / (2.0 * m),
            });
        }
        Ok(out)
    }

    /// Resolves each oscillator's equilibrium for the current state, checking linearity.
    fn resolve(&mut self, sys: &System, s: &State) -> std::result::Result<(), String> {
        let mut osc = Self::oscillators(sys)?;
        let g = sys.gravity.unwrap_or_else(Vec3::zeros);
        let drag = sys.drag.unwrap_or(0.0);
        for o in osc.iter_mut() {
            let p = o.particle;
            let sp = &sys.springs;
            let (k, l0, c, m) = (sp.k[o.spring], sp.l0[o.spring], sp.c[o.spring], sys.mass[p]);
            let a = s.x[o.anchor];
            let d = s.x[p] - a;
            if l0 == 0.0 && c == 0.0 {
                o.eq = a + g * (m / k);
                o.gamma = drag / (2.0 * m);
                continue;
            }
            if d.norm() == 0.0 {
                return Err(format!(
                    "particle {p} starts on its anchor: the spring direction is undefined"
                ));
            }
            let axis = d / d.norm();
            let mut along = vec![s.v[p], g];
            along.extend(
                sys.impulses
                    .iter()
                    .filter(|im| im.particle == p && im.time > s.t + 1e-12 * (1.0 + s.t.abs()))
                    .map(|im| im.delta_v),
            );
            if along.iter().any(|w| !parallel(*w, axis)) {
                return Err(format!("particle {p} does not move along its spring's axis: the spring force is nonlinear off-axis"));
            }
            let s_eq = l0 + m * g.dot(&axis) / k;
            if l0 > 0.0 {
                // Walk the exact solution through this particle's impulses: in each segment the
                // amplitude about equilibrium is at most √(u² + v²/ω₀²) (energy never grows).
                let (mut u, mut v, mut t) = (d.norm() - s_eq, s.v[p].dot(&axis), s.t);
                let kicks = sys
                    .impulses
                    .iter()
                    .filter(|im| im.particle == p && im.time > s.t + 1e-12 * (1.0 + s.t.abs()));
                for dv in kicks
                    .map(|im| Some((im.time, im.delta_v.dot(&axis))))
                    .chain([None])
                {
                    if s_eq - (u * u + v * v / o.w2).sqrt() <= 0.0 {
                        return Err(format!("particle {p} may pass through its anchor, where the spring law is not linear"));
                    }
                    let Some((ti, dvi)) = dv else { break };
                    let (ec, es) = propagators(o.gamma, o.w2, ti - t);
                    (u, v) = (
                        u * ec + (v + u * o.gamma) * es,
                        v * ec - (v * o.gamma + u * o.w2) * es + dvi,
                    );
                    t = ti;
                }
            }
            o.eq = a + axis * s_eq;
        }
        self.osc = osc;
        Ok(())
    }
}

impl Stepper for Analytic {
    fn check(&self, sys: &System) -> std::result::Result<(), String> {
        Self::oscillators(sys).map(|_| ())
    }
    fn reset(&mut self) {
        self.origin = None;
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        if self.origin.is_none() {
            self.resolve(sys, s)
                .map_err(|why| Error::Step(format!("analytic: {why}")))?;
            self.origin = Some((s.t, s.x.clone(), s.v.clone()));
        }
        let e_before = sys.state_energy(s).mechanical();
        let (t0, x0, v0) = self.origin.as_ref().expect("origin set above");
        let t = s.t + h - t0;
        let mut damped = false;
        for o in &self.osc {
            let p = o.particle;
            let (ec, es) = propagators(o.gamma, o.w2, t);
            let u0 = x0[p] - o.eq;
            s.x[p] = o.eq + u0 * ec + (v0[p] + u0 * o.gamma) * es;
            s.v[p] = v0[p] * ec - (v0[p] * o.gamma + u0 * o.w2) * es;
            damped |= o.gamma > 0.0;
        }
        s.t += h;
        // Exact solution: the work of the dampers is exactly the mechanical energy lost.
        let dissipated = if damped {
            e_before - sys.state_energy(s).mechanical()
        } else {
            0.0
        };
        Ok(StepStats {
            force_evals: 0,
            dissipated,
            ..StepStats::default()
        })
    }
}
