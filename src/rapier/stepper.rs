//! The Rapier methods as [`Stepper`]s: build lazily, step the pipeline, read back.

use super::convert::{to_glam, to_na};
use super::user_forces::{is_user_force, UserForces};
use super::world::{align_axial, build, set_step, Built, Mode};
use crate::error::Result;
use crate::integrate::{StepStats, Stepper};
use crate::model::{State, System, TermKind, Vec3};

/// Rapier 0.36 (f64) stepping a scene; `dt` is Rapier's frame step, `substeps` its
/// `num_solver_iterations`.
///
/// Cost: `force_evals` is reported as 0 (Rapier never evaluates our force model); each frame
/// reports its modelled seconds ([`super::cost`]) as `engine_seconds`. `dissipated` is the damper, drag and penalty-contact damping power (c·(n·v_rel)², c_d·|v|², the penalty's) of the read-back
/// states, integrated by the trapezoidal rule over the step: an estimate of the work Rapier's
/// implicit dampers did, accurate to O(h²) for smooth motion. The drag held as a user force on
/// multibody links is booked by its own work instead (`UserForces::drag_dissipated`).
pub struct RapierStepper {
    mode: Mode,
    substeps: usize,
    built: Option<Built>,
    /// The state was changed from outside since the last step (impulse): push it in.
    dirty: bool,
    /// Penalty contacts, applied as user forces held over each Rapier step.
    user: UserForces,
    /// Modelled seconds of one frame on the built scene ([`super::cost`]).
    frame_seconds: f64,
}

impl RapierStepper {
    /// A stepper of the given mode with `substeps` solver iterations per frame.
    pub fn new(mode: Mode, substeps: usize) -> Self {
        RapierStepper {
            mode,
            substeps: substeps.max(1),
            built: None,
            dirty: false,
            user: UserForces::default(),
            frame_seconds: 0.0,
        }
    }

    /// The multibody topology note (trees, fallback edges) for `sys`, `None` for the impulse
    /// method. Computed from the scene, so callers can print it before running.
    pub fn topology_note(&self, sys: &System) -> Option<String> {
        match self.mode {
            Mode::Impulse => None,
            Mode::Multibody => {
                Some(super::topology::Topology::of(sys, super::topology::tree_cap(sys)).describe())
            }
        }
    }

    fn prepare(&mut self, sys: &System, s: &State, h: f64) {
        let rebuild = self.built.is_none() || (self.dirty && self.mode == Mode::Multibody);
        if rebuild {
            if self.built.is_none() {
                // The price depends on the scene alone: once, not at every rebuild.
                self.frame_seconds = self.modelled_frame_seconds(sys).unwrap_or(0.0);
            }
            self.built = Some(build(sys, s, self.mode, self.substeps, h));
        } else if let Some(b) = &mut self.built {
            if self.dirty {
                // Impulse bodies hold maximal coordinates: push the changed state in.
                for (p, &hnd) in b.bodies.iter().enumerate() {
                    if sys.free[p] {
                        let rb = &mut b.world.bodies[hnd];
                        rb.set_translation(to_glam(&s.x[p]), true);
                        rb.set_linvel(to_glam(&s.v[p]), true);
                    }
                }
            }
            set_step(&mut b.world, self.substeps, h);
        }
        self.dirty = false;
    }
}

/// Damper and drag power (W) at (x, v): the same terms `System::forces` reports, without the
/// drag of the particles `held` marks (multibody links, whose drag is a held user force booked
/// by its own work).
pub(crate) fn damping_power(sys: &System, x: &[Vec3], v: &[Vec3], held: &[bool]) -> f64 {
    let sp = &sys.springs;
    let mut p = 0.0;
    if sp.any_damping {
        for s in 0..sp.len() {
            let (a, b) = (sp.i[s] as usize, sp.j[s] as usize);
            let d = x[b] - x[a];
            let len = d.norm();
            if sp.c[s] > 0.0 && len > 0.0 {
                let vr = (v[b] - v[a]).dot(&d) / len;
                p += sp.c[s] * vr * vr;
            }
        }
    }
    if let Some(c) = sys.drag {
        p += v
            .iter()
            .zip(&sys.free)
            .enumerate()
            .filter(|(p, (_, &f))| f && !held.get(*p).copied().unwrap_or(false))
            .map(|(_, (vi, _))| c * vi.norm_squared())
            .sum::<f64>();
    }
    p
}

/// Energy a step's contacts took: in a step where some contact was active (`e0`, the
/// mechanical energy at the step's start, is `Some`), the mechanical energy lost beyond the
/// dampers' work `damper`; never negative (contacts give nothing back, so a gain stays a gain
/// for the verdict). 0 in a step without contact.
pub(crate) fn contact_loss(sys: &System, s: &State, e0: Option<f64>, damper: f64) -> f64 {
    e0.map_or(0.0, |e0| {
        (e0 - sys.energy(&s.x, &s.v).mechanical() - damper).max(0.0)
    })
}

impl Stepper for RapierStepper {
    fn check(&self, sys: &System) -> std::result::Result<(), String> {
        if let Some(t) = sys
            .terms
            .iter()
            .find(|t| {
                !matches!(t.kind(), TermKind::Gravity | TermKind::Drag) && !is_user_force(t.kind())
            })
            .map(|t| t.name())
        {
            return Err(format!(
                "the Rapier methods map springs, constraints, gravity, drag and penalty contacts; the force term '{t}' has no Rapier equivalent yet"
            ));
        }
        Ok(())
    }
    fn modelled_frame_seconds(&self, sys: &System) -> Option<f64> {
        Some(super::cost::EngineShape::of(sys, self.mode).frame_seconds(self.substeps))
    }
    fn reset(&mut self) {
        self.dirty = true;
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        self.prepare(sys, s, h);
        let b = self.built.as_mut().expect("built in prepare");
        let p0 = damping_power(sys, &s.x, &s.v, &b.linked) + self.user.power(sys, &s.x, &s.v);
        let e0 = sys
            .post_step
            .as_ref()
            .map(|_| sys.energy(&s.x, &s.v).mechanical());
        let mut held_drag = 0.0;
        if b.axial.is_empty() {
            self.user
                .apply(sys, &b.bodies, &b.linked, &mut b.world.bodies, h);
            b.world.step();
            held_drag += self.user.drag_dissipated(&b.bodies, &b.world.bodies);
        } else {
            // Loop-closing joints between multibody links must follow the particle axis, which
            // Rapier only lets us set between frames: run `substeps` frames of h/N with one
            // solver iteration each (for impulse joints this is the same scheme as N substeps).
            let hs = h / self.substeps as f64;
            set_step(&mut b.world, 1, hs);
            for _ in 0..self.substeps {
                align_axial(b);
                self.user
                    .apply(sys, &b.bodies, &b.linked, &mut b.world.bodies, hs);
                b.world.step();
                held_drag += self.user.drag_dissipated(&b.bodies, &b.world.bodies);
            }
        }
        for (p, &hnd) in b.bodies.iter().enumerate() {
            if sys.free[p] {
                let rb = &b.world.bodies[hnd];
                s.x[p] = to_na(rb.translation());
                s.v[p] = to_na(rb.linvel());
            }
        }
        // Rapier's contacts remove energy we cannot see term by term: in a step where some
        // contact was active, book the mechanical energy lost beyond the dampers' work as
        // dissipated by contacts (this also absorbs Rapier's integration error in that step).
        // Contacts never give energy back: a gain in such a step stays a gain, so the run's
        // verdict sees it.
        let touching = e0.is_some() && b.world.contact_pairs().any(|c| c.has_any_active_contact());
        s.t += h;
        let p1 = damping_power(sys, &s.x, &s.v, &b.linked) + self.user.power(sys, &s.x, &s.v);
        let damper = 0.5 * (p0 + p1) * h + held_drag;
        Ok(StepStats {
            force_evals: 0,
            dissipated: damper + contact_loss(sys, s, e0.filter(|_| touching), damper),
            engine_seconds: self.frame_seconds,
            ..StepStats::default()
        })
    }
}
