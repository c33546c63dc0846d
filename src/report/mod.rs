//! The report renders what measure measured: per scene, [`crate::measure::study::study`]
//! returns the commands' own documents; the report writes them (same names, same schemas, each
//! with the command that re-creates it) and renders plots (SVG + the CSV behind each), HTML
//! pages, a Markdown overview and `summary.json`. It runs no method and measures nothing.
//!
//! Data flows one way: study → `charts` (plain [`data`]) → [`plots`] (SVG) and [`summary`]
//! → `verdict`, `html`, `markdown`; [`generate`] writes a scene and the overview;
//! [`crate::pipeline`] runs the studies and calls these.

mod charts;
mod collision_table;
pub mod data;
mod figures;
mod finite;
mod framerate;
mod game_rate;
pub mod generate;
mod html;
mod markdown;
mod method_table;
pub mod overview;
mod playback;
pub mod plots;
pub mod reuse;
pub mod shard;
pub mod small_steps;
pub mod summary;
mod verdict;

pub use generate::{scenario_files, write_overview, write_scene, ReportOptions};
pub use summary::Summary;
