//! The command line end to end: every test here runs the `springlab` binary (one test binary).

mod bad_input;
mod bench_cli;
mod check_obstacles;
mod cli_errors;
mod defaults_doc;
mod expect;
mod faults;
mod finite_scenes;
mod framerate;
mod interrupt;
mod measure_cli;
mod output_lock;
mod progress_budget;
mod progress_lines;
mod reference_store;
mod report_browser;
mod report_collision;
mod report_commands;
mod report_files;
mod report_rerun;
mod runaway;
mod support;
mod verdict_outputs;
