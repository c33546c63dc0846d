//! springlab: how far to trust a particle-spring simulation.
//!
//! A scene ([`scenario::Scenario`]) builds a [`model::System`] with only the terms it uses;
//! [`integrate::Stepper`]s step it, each registered with its facts in a
//! [`method::Registry`]; [`run::run`] owns the loop, the energy accounts and
//! blow-up detection; [`output`] writes what a run produced, atomically. [`measure`] holds the
//! commands' measurements against a reference; [`pipeline`] runs the report's studies and
//! [`report`] renders them.
//!
//! ```
//! use springlab::{method, run, scenario::Scenario};
//! let scene = Scenario::from_toml_str(r#"
//!     [[particle]]
//!     position = [0.0, 0.0, 0.0]
//!     mass = 1.0
//!     fixed = true
//!     [[particle]]
//!     position = [1.0, 0.0, 0.0]
//!     mass = 1.0
//!     [[spring]]
//!     between = [0, 1]
//!     stiffness = 1.0
//!     rest_length = 0.5
//! "#, "osc.toml").unwrap();
//! let sys = scene.build();
//! let mut rk4 = method::create("rk4", &Default::default()).unwrap();
//! let plan = run::RunPlan::new(0.01, 100);
//! let out = run::run(&sys, &mut rk4, scene.initial_state(), &plan, &mut run::NoObserver).unwrap();
//! assert!(out.status.is_ok());
//! // Energy is conserved to rk4's accuracy.
//! assert!((out.final_energy.total - out.initial_energy.total).abs() < 1e-9);
//! ```

#![warn(missing_docs)]

pub mod collide;
pub mod error;
pub mod integrate;
pub mod measure;
pub mod method;
pub mod model;
pub mod output;
/// Scenes and timings shared by the criterion benches and the bench commands (not a stable API).
#[doc(hidden)]
pub mod perf;
pub mod pipeline;
pub mod rapier;
pub mod report;
pub mod run;
pub mod scenario;

// What a library user needs most, at the top: a scene, a method, a run, a study.
pub use error::{Error, Result};
pub use integrate::Stepper;
pub use measure::study::{study, SceneStudy, StudyConfig};
pub use method::{Method, MethodInfo, MethodOptions, Registry};
pub use model::{State, System, Vec3};
pub use run::{run, RunOutcome, RunPlan, Status};
pub use scenario::Scenario;
