//! Extended position-based dynamics, XPBD (Macklin, Müller & Chentanez, "XPBD: Position-Based
//! Simulation of Compliant Constrained Dynamics", MIG 2016), with substeps (Macklin, Storey,
//! Lu, Terdiman, Chentanez, Jeschke & Müller, "Small Steps in Physics Simulation", SCA 2019).
//!
//! One step of h is `substeps` substeps of hₛ = h / substeps, each:
//!
//! 1. **predict** with the external forces (every force term but the springs: gravity, drag,
//!    penalty contacts): vₛ = v + hₛ M⁻¹ f_ext(x, v), x̃ = x + hₛ vₛ;
//! 2. **solve** `iterations` Gauss–Seidel sweeps over the links (every spring as a compliant
//!    distance constraint with compliance 1/k_eff and XPBD damping β = c, then every
//!    `[[constraint]]` with its own compliance; see [`link`]), λ starting from 0;
//! 3. **update** v = (x − xₙ) / hₛ.
//!
//! Small scenes sweep the links in index order; scenes with at least
//! [`PARALLEL_MIN_SPRINGS`](crate::model::PARALLEL_MIN_SPRINGS) springs sweep them colour by
//! colour in parallel ([`colouring`]), bit-identical whatever the thread count.
//!
//! **Order 1.** On a linear spring one iteration per substep is backward Euler on the spring
//! and the damper with the external forces explicit, so the method converges at first order
//! in hₛ; more iterations converge the substep's implicit solve, not the order.
//!
//! **Energy.** The runner books the state's energy (a spring's ½k(|d| − L)² is exactly the
//! constraint's ½α⁻¹C²) and the step's `dissipated`: the dampers' power c (n·v_rel)² at the
//! end of each substep (the velocity XPBD's implicit damping acts on) plus the drag power of
//! the predict, each × hₛ. The energy the position solve removes (it is implicit Euler on the
//! constraint potential, and unconverged iterations remove more) is *not* booked: it is the
//! method's numerical dissipation, and shows in the energy balance error (`energy_drift`)
//! exactly as implicit Euler's does.
//!
//! **Cost.** XPBD never evaluates springlab's spring force model, so its registered cost is
//! wall time and `StepStats::force_evals` is 0; [`Xpbd::sweeps`] counts the constraint sweeps
//! (one sweep visits every link once, about the work of one spring-force evaluation).

mod colouring;
mod link;

use super::{ensure_len, StepStats, Stepper};
use crate::error::Result;
use crate::model::parallel::{each_particle, each_particle2, sum_partials, SPRING_CHUNK};
use crate::model::{State, System, Vec3, PARALLEL_MIN_SPRINGS};
use colouring::Colouring;
use rayon::prelude::*;

/// XPBD with `substeps` substeps per step and `iterations` constraint sweeps per substep.
#[derive(Debug)]
pub struct Xpbd {
    /// Substeps per step (≥ 1).
    pub substeps: usize,
    /// Gauss–Seidel sweeps over the links per substep (≥ 1).
    pub iterations: usize,
    /// Constraint sweeps made so far (substeps × iterations per step), for cost reports.
    pub sweeps: u64,
    f: Vec<Vec3>,
    x0: Vec<Vec3>,
    lambda: Vec<f64>,
    corr: Vec<Vec3>,
    parts: Vec<f64>,
    colouring: Colouring,
}

impl Xpbd {
    /// XPBD with `substeps` substeps per step and `iterations` sweeps per substep (0 is
    /// taken as 1).
    pub fn new(substeps: usize, iterations: usize) -> Self {
        Xpbd {
            substeps: substeps.max(1),
            iterations: iterations.max(1),
            sweeps: 0,
            f: Vec::new(),
            x0: Vec::new(),
            lambda: Vec::new(),
            corr: Vec::new(),
            parts: Vec::new(),
            colouring: Colouring::default(),
        }
    }
}

impl Default for Xpbd {
    /// One substep, one iteration: plain XPBD at the runner's step.
    fn default() -> Self {
        Self::new(1, 1)
    }
}

/// True when `sys` takes the coloured parallel sweep (a property of the scene only).
pub fn is_parallel(sys: &System) -> bool {
    sys.springs.len() >= PARALLEL_MIN_SPRINGS
}

impl Xpbd {
    /// One serial Gauss–Seidel sweep over the links in index order.
    fn sweep_serial(&mut self, sys: &System, x: &mut [Vec3], h: f64) {
        for (l, lambda) in self.lambda.iter_mut().enumerate() {
            let k = link::link(sys, l);
            if let Some(g) = link::solve(&k, &sys.inv_mass, x, &self.x0, h, lambda) {
                x[k.i] -= g * sys.inv_mass[k.i];
                x[k.j] += g * sys.inv_mass[k.j];
            }
        }
    }

    /// Power of the dampers at (x, v), summed per fixed chunk of springs, the chunk sums
    /// added in order (in parallel for large scenes: the same sum whatever the thread count).
    fn damper_power(&mut self, sys: &System, x: &[Vec3], v: &[Vec3]) -> f64 {
        if !sys.springs.any_damping {
            return 0.0;
        }
        let m = sys.springs.len();
        let chunks = m.div_ceil(SPRING_CHUNK);
        ensure_len(&mut self.parts, chunks);
        let part = |c: usize| {
            let lo = c * SPRING_CHUNK;
            link::damper_power(sys, x, v, lo, (lo + SPRING_CHUNK).min(m))
        };
        if is_parallel(sys) {
            self.parts
                .par_iter_mut()
                .enumerate()
                .for_each(|(c, p)| *p = part(c));
        } else {
            self.parts
                .iter_mut()
                .enumerate()
                .for_each(|(c, p)| *p = part(c));
        }
        sum_partials(&self.parts)
    }

    /// One substep of `h`; returns the energy it books as dissipated.
    fn substep(&mut self, sys: &System, s: &mut State, h: f64) -> f64 {
        // 1. Predict with the external forces (every term but the springs).
        each_particle(&mut self.f, |_, f| *f = Vec3::zeros());
        let mut drag_power = 0.0;
        for t in &sys.terms {
            drag_power += t.add_forces(&s.x, &s.v, &mut self.f);
        }
        self.x0.copy_from_slice(&s.x);
        let f = &self.f;
        each_particle2(&mut s.x, &mut s.v, |p, x, v| {
            if sys.free[p] {
                *v += f[p] * (sys.inv_mass[p] * h);
                *x += *v * h;
            }
        });
        // 2. Solve.
        self.lambda.iter_mut().for_each(|l| *l = 0.0);
        for _ in 0..self.iterations {
            if is_parallel(sys) {
                self.colouring
                    .sweep(sys, &mut s.x, &self.x0, h, &mut self.lambda, &mut self.corr);
            } else {
                self.sweep_serial(sys, &mut s.x, h);
            }
        }
        self.sweeps += self.iterations as u64;
        // 3. Velocities from the positions.
        let x0 = &self.x0;
        each_particle2(&mut s.v, &mut s.x, |p, v, x| {
            if sys.free[p] {
                *v = (*x - x0[p]) / h;
            }
        });
        (drag_power + self.damper_power(sys, &s.x, &s.v)) * h
    }
}

impl Stepper for Xpbd {
    fn check(&self, _sys: &System) -> std::result::Result<(), String> {
        Ok(())
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        ensure_len(&mut self.f, n);
        ensure_len(&mut self.x0, n);
        ensure_len(&mut self.lambda, link::count(sys));
        if is_parallel(sys) {
            self.colouring.fit(sys);
            ensure_len(&mut self.corr, link::count(sys));
        }
        let hs = h / self.substeps as f64;
        let mut dissipated = 0.0;
        for _ in 0..self.substeps {
            dissipated += self.substep(sys, s, hs);
        }
        s.t += h;
        Ok(StepStats {
            dissipated,
            link_updates: (self.substeps * self.iterations * link::count(sys)) as u64,
            ..StepStats::default()
        })
    }
}
