//! The report: runs every scene through every applicable backend, measures, and writes plots
//! (SVG + the CSV behind each), HTML pages, a Markdown overview and `summary.json`.

pub mod collect;
pub mod data;
pub mod finite;
pub mod plots;
pub mod results;
pub mod sampler;
