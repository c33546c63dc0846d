//! The report: runs every scene through every applicable backend, measures, and writes plots
//! (SVG + the CSV behind each), HTML pages, a Markdown overview and `summary.json`.

pub mod data;
pub mod finite;
pub mod plots;
