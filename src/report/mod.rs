//! The report: runs every scene through every applicable backend, measures, and writes plots
//! (SVG + the CSV behind each), HTML pages, a Markdown overview and `summary.json`.
//!
//! Data flows one way: [`collect`] → [`results`] → [`charts`] (plain [`data`]) → [`plots`]
//! (SVG) and [`summary`] → [`verdict`], [`html`], [`markdown`]; [`generate`] writes it all.

pub mod charts;
pub mod collect;
pub mod data;
pub mod finite;
pub mod generate;
pub mod html;
pub mod markdown;
pub mod plots;
pub mod results;
pub mod sampler;
pub mod summary;
pub mod verdict;

pub use generate::{report_scene, scenario_files, write_overview, ReportOptions};
pub use summary::Summary;
