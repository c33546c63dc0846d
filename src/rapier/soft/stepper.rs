//! The soft-body methods as [`Stepper`]s: build the world lazily from the first state, step
//! Rapier's pipeline a frame at a time, read the particles back.

use super::mapping::{soft_plan, SoftPlan};
use crate::error::{Error, Result};
use crate::integrate::{StepStats, Stepper};
use crate::model::{State, System, TermKind, Vec3};
use crate::rapier::convert::{to_glam, to_na};
use crate::rapier::stepper::{contact_loss, damping_power};
use crate::rapier::user_forces::is_user_force;
use crate::rapier::world::set_step;
use rapier3d_f64::prelude::*;

/// CLI name of the soft-constraint method.
pub const SOFT: &str = "rapier_soft";
/// CLI name of the FEM soft-body method.
pub const SOFT_FEM: &str = "rapier_soft_fem";

/// Which of Rapier's soft-body solvers carries the edges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SoftSolver {
    /// Soft constraints, swept by coloured Gauss-Seidel once per substep.
    Constraints,
    /// Implicit Euler elasticity over the whole body once per substep.
    Fem,
}

impl SoftSolver {
    /// The method's name.
    pub fn name(self) -> &'static str {
        match self {
            SoftSolver::Constraints => SOFT,
            SoftSolver::Fem => SOFT_FEM,
        }
    }
    fn rapier(self) -> SoftBodySolver {
        match self {
            SoftSolver::Constraints => SoftBodySolver::Constraints,
            SoftSolver::Fem => SoftBodySolver::Fem,
        }
    }
}

/// A built world: the soft bodies and the plan that placed each particle.
struct Built {
    world: PhysicsWorld,
    bodies: Vec<SoftBodyHandle>,
    plan: SoftPlan,
}

/// Rapier 0.36 soft bodies stepping a scene; `dt` is Rapier's frame step, `substeps` its
/// `num_solver_iterations`. Cost and energy books as for the other Rapier methods
/// ([`crate::rapier::RapierStepper`]).
pub struct SoftStepper {
    solver: SoftSolver,
    substeps: usize,
    built: Option<Built>,
    dirty: bool,
    frame_seconds: f64,
}

impl SoftStepper {
    /// A stepper with the given solver and `substeps` solver substeps per frame.
    pub fn new(solver: SoftSolver, substeps: usize) -> Self {
        SoftStepper {
            solver,
            substeps: substeps.max(1),
            built: None,
            dirty: false,
            frame_seconds: 0.0,
        }
    }

    fn build(&self, sys: &System, s: &State, h: f64) -> Result<Built> {
        let plan = soft_plan(sys, Some(&s.x)).map_err(Error::Step)?;
        let mut world = PhysicsWorld::new();
        world.gravity = sys.gravity.as_ref().map(to_glam).unwrap_or(Vector::ZERO);
        set_step(&mut world, self.substeps, h);
        crate::rapier::obstacles::contact_parameters(&mut world.integration_parameters);
        for c in crate::rapier::obstacles::obstacle_colliders(sys) {
            world.insert_collider(c, None);
        }
        let mut bodies = Vec::with_capacity(plan.bodies.len());
        for b in &plan.bodies {
            let pinned = b
                .particles
                .iter()
                .enumerate()
                .filter(|(_, &p)| !sys.free[p])
                .map(|(l, _)| l as u32);
            let softness = b.edges.iter().enumerate().map(|(k, e)| {
                (
                    k as u32,
                    SpringCoefficients::new(e.frequency, e.damping_ratio),
                )
            });
            let mut builder = SoftBodyBuilder::new(b.rest.iter().map(to_glam).collect())
                .masses(b.particles.iter().map(|&p| sys.mass[p]).collect())
                .pinned_particles(pinned)
                .edges(b.edges.iter().map(|e| e.ends).collect())
                .solver(self.solver.rapier())
                .linear_damping(b.damping)
                .can_sleep(false)
                .particle_radius(b.radius.max(1e-6));
            builder.edge_softness = softness.collect();
            builder = if plan.collides {
                let groups = crate::rapier::obstacles::particle_groups();
                builder
                    .wire(b.edges.iter().map(|e| e.ends).collect())
                    .surface_collider(
                        ColliderBuilder::ball(b.radius.max(1e-6))
                            .density(0.0)
                            .collision_groups(groups)
                            .solver_groups(groups)
                            .restitution(0.0)
                            .restitution_combine_rule(crate::rapier::RESTITUTION_RULE)
                            .friction(0.0)
                            .friction_combine_rule(CoefficientCombineRule::Max)
                            .contact_skin(0.0),
                    )
            } else {
                builder.no_surface_collider()
            };
            bodies.push(world.insert_soft_body(builder));
        }
        let mut built = Built {
            world,
            bodies,
            plan,
        };
        push_state(&mut built, sys, s);
        Ok(built)
    }

    fn prepare(&mut self, sys: &System, s: &State, h: f64) -> Result<()> {
        if self.built.is_none() {
            self.frame_seconds = self.modelled_frame_seconds(sys).unwrap_or(0.0);
            self.built = Some(self.build(sys, s, h)?);
        } else if let Some(b) = &mut self.built {
            if self.dirty {
                push_state(b, sys, s);
            }
            set_step(&mut b.world, self.substeps, h);
        }
        self.dirty = false;
        Ok(())
    }
}

/// Moves every particle of the built bodies to the state's position and velocity (the bodies
/// were built in their rest pose; an impulse changed a velocity).
fn push_state(b: &mut Built, sys: &System, s: &State) {
    for (plan, &h) in b.plan.bodies.iter().zip(&b.bodies) {
        let Some(sb) = b.world.soft_bodies.get_mut(h) else {
            continue;
        };
        for (l, &p) in plan.particles.iter().enumerate() {
            sb.set_particle_position(l, to_glam(&s.x[p]));
            let v = if sys.free[p] { s.v[p] } else { Vec3::zeros() };
            sb.set_particle_velocity(l, to_glam(&v));
        }
    }
}

impl Stepper for SoftStepper {
    fn check(&self, sys: &System) -> std::result::Result<(), String> {
        if let Some(t) = sys
            .terms
            .iter()
            .find(|t| !matches!(t.kind(), TermKind::Gravity | TermKind::Drag))
        {
            let (kind, t) = (t.kind(), t.name());
            return Err(if is_user_force(kind) {
                format!("the soft bodies meet obstacles through Rapier's contacts; the force term '{t}' (a penalty contact) is applied as a held user force by rapier_impulse only")
            } else {
                format!("the soft-body methods map springs, compliant rods, gravity and drag; the force term '{t}' has no Rapier equivalent")
            });
        }
        soft_plan(sys, None).map(|_| ())
    }
    fn modelled_frame_seconds(&self, sys: &System) -> Option<f64> {
        Some(super::super::cost::SoftShape::of(sys).frame_seconds(self.solver, self.substeps))
    }
    fn reset(&mut self) {
        self.dirty = true;
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        self.prepare(sys, s, h)?;
        let p0 = damping_power(sys, &s.x, &s.v, &[]);
        let e0 = sys
            .post_step
            .as_ref()
            .map(|_| sys.energy(&s.x, &s.v).mechanical());
        let b = self.built.as_mut().expect("built in prepare");
        b.world.step();
        for (plan, &h) in b.plan.bodies.iter().zip(&b.bodies) {
            let Some(sb) = b.world.soft_bodies.get(h) else {
                continue;
            };
            for (l, &p) in plan.particles.iter().enumerate() {
                if sys.free[p] {
                    s.x[p] = to_na(sb.particle_position(l));
                    s.v[p] = to_na(sb.particle_velocity(l));
                }
            }
        }
        let touching = e0.is_some() && b.world.contact_pairs().any(|c| c.has_any_active_contact());
        s.t += h;
        let damper = 0.5 * (p0 + damping_power(sys, &s.x, &s.v, &[])) * h;
        Ok(StepStats {
            force_evals: 0,
            dissipated: damper + contact_loss(sys, s, e0.filter(|_| touching), damper),
            engine_seconds: self.frame_seconds,
            ..StepStats::default()
        })
    }
}
