//! The scenario file format as serde types: exactly the keys users write, nothing more.
//!
//! Every table denies unknown keys so a typo is an error, not a silently ignored setting.

use super::words::{ChainEnd, Corner, Plane};
use serde::{Deserialize, Serialize};

/// A 3-vector as written in TOML: `[x, y, z]`.
pub type Triple = [f64; 3];

/// One scene file (`scenarios/*.toml`).
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// Scene name; defaults to the file stem.
    pub name: Option<String>,
    /// Free text shown in reports.
    pub description: Option<String>,
    /// Global forces.
    #[serde(default)]
    pub world: WorldSpec,
    /// Explicit particles, indexed first (0-based, in file order).
    #[serde(default)]
    pub particle: Vec<ParticleSpec>,
    /// Springs between particles.
    #[serde(default)]
    pub spring: Vec<SpringSpec>,
    /// Rigid distance constraints (rods).
    #[serde(default)]
    pub constraint: Vec<ConstraintSpec>,
    /// Instantaneous velocity changes.
    #[serde(default)]
    pub impulse: Vec<ImpulseSpec>,
    /// Rope generators, indexed after explicit particles, in file order.
    #[serde(default)]
    pub chain: Vec<ChainSpec>,
    /// Cloth generators, indexed after all chains, in file order.
    #[serde(default)]
    pub cloth: Vec<ClothSpec>,
    /// Run settings (step, length, default methods).
    pub run: Option<RunSpec>,
    /// Static obstacles.
    #[serde(default)]
    pub obstacle: Vec<super::obstacle_file::ObstacleSpec>,
    /// How contacts with obstacles are resolved (default: impulse).
    pub collision: Option<super::obstacle_file::CollisionSpec>,
    /// What a run of this scene must achieve (`springlab expect`).
    pub expect: Option<ExpectSpec>,
}

/// `[world]`: gravity and drag; absent values mean the term does not exist.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Gravitational acceleration in m/s²; absent means no gravity term at all.
    pub gravity: Option<Triple>,
    /// Linear air drag coefficient in kg/s (force = -drag·v); absent or 0 means no drag term.
    pub drag: Option<f64>,
}

/// `[[particle]]`: one point mass.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    /// Initial position in m.
    pub position: Triple,
    /// Initial velocity in m/s (default zero).
    #[serde(default)]
    pub velocity: Triple,
    /// Mass in kg (must be positive unless fixed).
    pub mass: f64,
    /// Fixed particles never move.
    #[serde(default)]
    pub fixed: bool,
    /// Collision radius in m (default 0: a point).
    #[serde(default)]
    pub radius: f64,
}

/// How a spring's force depends on its extension.
#[derive(Debug, Clone, Copy, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SpringLaw {
    /// f = k (|d| - l0), k in N/m.
    #[default]
    Hooke,
    /// f = k (|d| - l0) / l0, k in N (engineering strain).
    Strain,
}

/// `[[spring]]`: a spring (with optional axial damper) between two particles.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    /// The two particle indices.
    pub between: [i64; 2],
    /// Stiffness (N/m for hooke, N for strain).
    pub stiffness: f64,
    /// Rest length in m (default: initial distance).
    pub rest_length: Option<f64>,
    /// Axial damping in N·s/m (default 0: no damper).
    #[serde(default)]
    pub damping: f64,
    /// Force law (default hooke).
    #[serde(default)]
    pub law: SpringLaw,
}

/// `[[constraint]]`: a rigid rod keeping two particles at a fixed distance.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    /// The two particle indices.
    pub between: [i64; 2],
    /// Rod length in m (default: initial distance).
    pub length: Option<f64>,
    /// XPBD compliance in m/N (default 0: rigid); used by `verlet_constraints` and `xpbd`.
    #[serde(default)]
    pub compliance: f64,
}

/// `[[impulse]]`: an instantaneous velocity change at a given time.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ImpulseSpec {
    /// When, in s from the start.
    pub time: f64,
    /// Which particle.
    pub particle: i64,
    /// Velocity change in m/s.
    pub delta_v: Triple,
}

/// `[[chain]]`: a rope of `count` particles joined by springs along a straight line.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ChainSpec {
    /// First particle position.
    pub start: Triple,
    /// Last particle position.
    pub end: Triple,
    /// Number of particles (at least 2).
    pub count: i64,
    /// Mass per particle in kg.
    pub mass: f64,
    /// Spring stiffness in N/m.
    pub stiffness: f64,
    /// Spring damping in N·s/m (default 0).
    #[serde(default)]
    pub damping: f64,
    /// Ends to fix: any of "first", "last".
    #[serde(default)]
    pub fix: Vec<String>,
}

impl ChainSpec {
    /// Whether `fix` names `end` (its words are validated before the chain is generated).
    pub fn fixes(&self, end: ChainEnd) -> bool {
        self.fix.iter().any(|w| ChainEnd::parse(w) == Some(end))
    }
}

/// `[[cloth]]`: an nx × ny grid with structural, shear and optional bend springs.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ClothSpec {
    /// Bottom-left corner of the grid; rows run along x, columns along the plane's second axis.
    pub origin: Triple,
    /// Extent in x and in the second axis, m.
    pub size: [f64; 2],
    /// Particles along each axis (each at least 2).
    pub count: [i64; 2],
    /// Mass per particle in kg.
    pub mass: f64,
    /// Structural and shear stiffness in N/m.
    pub stiffness: f64,
    /// Spring damping in N·s/m (default 0).
    #[serde(default)]
    pub damping: f64,
    /// Bend (skip-one) spring stiffness; 0 means no bend springs.
    #[serde(default)]
    pub bend_stiffness: f64,
    /// Corners to fix: any of "top_left", "top_right", "bottom_left", "bottom_right".
    #[serde(default)]
    pub fix: Vec<String>,
    /// Plane of the cloth: "xy" (hanging, default) or "xz" (horizontal).
    #[serde(default)]
    pub plane: Option<String>,
}

impl ClothSpec {
    /// Whether `fix` names `corner` (its words are validated before the cloth is generated).
    pub fn fixes(&self, corner: Corner) -> bool {
        self.fix.iter().any(|w| Corner::parse(w) == Some(corner))
    }
    /// The cloth's plane (xy where `plane` is absent; validated before generation).
    pub fn plane(&self) -> Plane {
        self.plane
            .as_deref()
            .and_then(Plane::parse)
            .unwrap_or_default()
    }
}

/// `[run]`: the default step and length of a run.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// Time step in s.
    pub dt: Option<f64>,
    /// Number of steps (exclusive with duration).
    pub steps: Option<i64>,
    /// Simulated time in s (exclusive with steps).
    pub duration: Option<f64>,
    /// Methods `compare` uses by default (`integrators` is read as the same key).
    #[serde(alias = "integrators")]
    pub methods: Option<Vec<String>>,
    /// When impulses take effect: "exact" (default) or "frame".
    pub events: Option<String>,
    /// Position tolerance of the scene's answers (m; default 1 % of the motion scale).
    pub tolerance: Option<f64>,
    /// The game's frame rate (Hz) its answer is given at (default 60).
    pub hz: Option<f64>,
}

/// `[expect]`: the method, step and limits a scene is held to by `springlab expect`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ExpectSpec {
    /// Method name (a registered method; `integrator` is read as the same key).
    #[serde(alias = "integrator")]
    pub method: String,
    /// Frame rate in Hz (exclusive with `dt`).
    pub hz: Option<f64>,
    /// Frame step in s (exclusive with `hz`).
    pub dt: Option<f64>,
    /// Steps per frame (default 1).
    pub substeps: Option<i64>,
    /// Whether the run must stay stable.
    pub stable: Option<bool>,
    /// Largest position error against the reference, m.
    pub max_position_error: Option<f64>,
    /// Largest |l/l0 − 1| of any spring or rod during the run.
    pub max_strain: Option<f64>,
    /// Largest |slope| of the energy balance, J/s.
    pub max_energy_drift_rate: Option<f64>,
}
