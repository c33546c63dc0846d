//! The report's work, apart from its rendering: per scene the study
//! ([`crate::measure::study`]) unless the scene's folder is unchanged, the Small Steps runs,
//! and the whole report as one library call ([`build()`]). [`crate::report`] renders what these
//! hand it and runs nothing itself.

pub mod build;
pub mod scene;
pub mod small_steps;

pub use build::{build, BuildConfig, Built};
pub use scene::report_scene;
