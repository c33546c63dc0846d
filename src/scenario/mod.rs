//! Scenario files: parse, validate (with field paths), and build the [`System`] a scene needs.
//!
//! ```
//! use springlab::scenario::Scenario;
//! let scene = Scenario::from_toml_str(r#"
//!     [[particle]]
//!     position = [0.0, 0.0, 0.0]
//!     mass = 1.0
//!     fixed = true
//!     [[particle]]
//!     position = [0.0, -1.0, 0.0]
//!     mass = 1.0
//!     [[spring]]
//!     between = [0, 1]
//!     stiffness = 100.0
//!     rest_length = 0.5
//!     [run]
//!     dt = 0.001
//!     duration = 1.0
//! "#, "inline.toml").unwrap();
//! assert_eq!(scene.particles.len(), 2);
//! let sys = scene.build();
//! assert_eq!(sys.active_terms(), vec!["springs"]);
//! ```

pub mod append_expect;
mod checker;
pub mod file;
mod finite;
mod generate;
mod load;
mod obj;
pub mod obstacle_file;
mod obstacle_validate;
mod parse;
mod run_table;
mod time_scales;
mod timing;
mod validate;
pub mod words;
pub use checker::{MAX_PARTICLES, MAX_STEPS};

pub use file::{ExpectSpec, ScenarioFile, SpringLaw};
pub use generate::Block;
pub use timing::{Asked, Timing};

use crate::model::{
    DistanceConstraint, Drag, ForceTerm, Gravity, Impulse, Springs, State, System, Vec3,
};
use std::path::PathBuf;

/// One particle of a validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Particle {
    /// Initial position (m).
    pub position: Vec3,
    /// Initial velocity (m/s).
    pub velocity: Vec3,
    /// Mass (kg).
    pub mass: f64,
    /// Fixed particles never move.
    pub fixed: bool,
    /// Collision radius (m).
    pub radius: f64,
}

/// One spring of a validated scene, before the law is folded into an effective stiffness.
#[derive(Debug, Clone, PartialEq)]
pub struct SpringDef {
    /// First particle.
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Stiffness as written (N/m for hooke, N for strain).
    pub stiffness: f64,
    /// Rest length (m); `None` means the initial distance.
    pub rest_length: Option<f64>,
    /// Axial damping (N·s/m).
    pub damping: f64,
    /// Force law.
    pub law: SpringLaw,
}

impl SpringDef {
    /// A Hooke spring at its initial length.
    pub fn hooke(i: usize, j: usize, stiffness: f64, damping: f64) -> Self {
        SpringDef {
            i,
            j,
            stiffness,
            rest_length: None,
            damping,
            law: SpringLaw::Hooke,
        }
    }
}

/// How long a run lasts and with which step.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSettings {
    /// Time step (s), if the scene gives one.
    pub dt: Option<f64>,
    /// Number of steps, if given.
    pub steps: Option<u64>,
    /// Simulated time (s), if given.
    pub duration: Option<f64>,
    /// Methods `compare` uses by default (empty: all that apply).
    pub methods: Vec<String>,
    /// When impulses take effect: at their time, or at the next frame boundary.
    pub events: crate::model::Events,
    /// Position tolerance of the scene's answers (m), when the scene gives one; else
    /// [`crate::measure::tolerance`] derives it from the motion.
    pub tolerance: Option<f64>,
    /// The game's frame rate (Hz) of the scene's answer, when the scene gives one (else 60).
    pub hz: Option<f64>,
}

impl RunSettings {
    /// The run's length in seconds as the file gives it: `duration`, else `steps` × `dt`;
    /// `None` when the file leaves it to a command (steps without a step, or neither).
    pub fn length(&self) -> Option<f64> {
        self.duration
            .or_else(|| self.steps.zip(self.dt).map(|(n, dt)| n as f64 * dt))
    }
}

/// A validated scene: everything needed to build a [`System`] and its initial [`State`].
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Scene name (file stem by default).
    pub name: String,
    /// Free text.
    pub description: String,
    /// Where the scene came from (`<memory>` for scenes built in code).
    pub source: PathBuf,
    /// Particles: explicit ones first, then generated ones in block order.
    pub particles: Vec<Particle>,
    /// Springs with resolved rest lengths.
    pub springs: Vec<SpringDef>,
    /// Rigid rods.
    pub constraints: Vec<DistanceConstraint>,
    /// Impulses, sorted by time (stable).
    pub impulses: Vec<Impulse>,
    /// Gravity, if any.
    pub gravity: Option<Vec3>,
    /// Linear drag, if any (> 0).
    pub drag: Option<f64>,
    /// Run defaults.
    pub run: RunSettings,
    /// Generated blocks (chains, cloths) for plots.
    pub blocks: Vec<Block>,
    /// Obstacles and contact response; `None` when the scene has no obstacles.
    pub collision: Option<crate::collide::CollisionSetup>,
    /// What a run of this scene must achieve, when the file has an `[expect]` table.
    pub expect: Option<Expect>,
    /// The raw file, for later stages that read more tables.
    pub raw: ScenarioFile,
}

/// A validated `[expect]` table: one method at one frame step, and the limits its run
/// is held to (each check optional).
#[derive(Debug, Clone, PartialEq)]
pub struct Expect {
    /// Method name (registered).
    pub method: String,
    /// Frame step (s): `1/hz` or `dt`.
    pub frame_dt: f64,
    /// Steps per frame (≥ 1).
    pub substeps: u64,
    /// `Some(true)`: the run must stay stable.
    pub stable: Option<bool>,
    /// Largest position error (m) over the reference's predictable horizon.
    pub max_position_error: Option<f64>,
    /// Largest |l/l0 − 1| of any spring or rod.
    pub max_strain: Option<f64>,
    /// Largest |slope| of the energy balance (J/s).
    pub max_energy_drift_rate: Option<f64>,
}

/// The distance between particles `i` and `j` at their initial positions: the rest length of
/// a spring that gives none (and of every generated spring), and a rod's default length.
pub(crate) fn initial_distance(particles: &[Particle], i: usize, j: usize) -> f64 {
    (particles[j].position - particles[i].position).norm()
}

impl Scenario {
    /// Number of free (moving) particles.
    pub fn free_count(&self) -> usize {
        self.particles.iter().filter(|p| !p.fixed).count()
    }

    /// Rest length of spring `s` (m): as given, else the initial distance of its particles
    /// (the one rule, `initial_distance`).
    pub fn rest_length(&self, s: &SpringDef) -> f64 {
        s.rest_length
            .unwrap_or_else(|| initial_distance(&self.particles, s.i, s.j))
    }

    /// Builds the system with only the terms this scene uses.
    pub fn build(&self) -> System {
        let mass: Vec<f64> = self.particles.iter().map(|p| p.mass).collect();
        let free: Vec<bool> = self.particles.iter().map(|p| !p.fixed).collect();
        let inv_mass = self
            .particles
            .iter()
            .map(|p| if p.fixed { 0.0 } else { 1.0 / p.mass })
            .collect();
        let mut springs = Springs::default();
        for s in &self.springs {
            let l0 = self.rest_length(s);
            let k = match s.law {
                SpringLaw::Hooke => s.stiffness,
                SpringLaw::Strain => s.stiffness / l0,
            };
            springs.push(s.i, s.j, k, l0, s.damping);
        }
        let mut terms: Vec<Box<dyn ForceTerm>> = Vec::new();
        if let Some(g) = self.gravity {
            let gm = self
                .particles
                .iter()
                .map(|p| if p.fixed { 0.0 } else { p.mass })
                .collect();
            terms.push(Box::new(Gravity { g, mass: gm }));
        }
        if let Some(c) = self.drag {
            terms.push(Box::new(Drag { c }));
        }
        // Obstacles: parry shapes and the broad phase are built only when they exist.
        let contacts = self.collision.as_ref().map(|c| {
            let set = std::sync::Arc::new(crate::collide::ObstacleSet::build(&c.obstacles));
            if let crate::collide::Response::Penalty { stiffness, damping } = c.response {
                terms.push(Box::new(crate::collide::Penalty::new(
                    set.clone(),
                    stiffness,
                    damping,
                    self.particles.iter().map(|p| p.mass).collect(),
                    self.particles.iter().map(|p| p.radius).collect(),
                    self.particles.iter().map(|p| !p.fixed).collect(),
                )));
            }
            Box::new(crate::collide::Contacts::new(set, c.response))
                as Box<dyn crate::model::PostStep>
        });
        System {
            mass,
            inv_mass,
            free,
            radius: self.particles.iter().map(|p| p.radius).collect(),
            springs,
            gravity: self.gravity,
            drag: self.drag,
            constraints: self.constraints.clone(),
            impulses: self.impulses.clone(),
            events: self.run.events,
            terms,
            post_step: contacts,
        }
    }

    /// The initial state at t = 0.
    pub fn initial_state(&self) -> State {
        State {
            t: 0.0,
            x: self.particles.iter().map(|p| p.position).collect(),
            v: self
                .particles
                .iter()
                .map(|p| if p.fixed { Vec3::zeros() } else { p.velocity })
                .collect(),
        }
    }
}
