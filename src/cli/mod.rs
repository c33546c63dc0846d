//! Command-line interface: clap subcommands, one file each, validated into library calls.

mod advise;
mod bench_ratios;
mod bench_scaling;
mod check;
mod common;
mod compare;
mod expect;
mod framerate;
mod list;
mod measure_common;
mod merge;
mod method_args;
mod report;
mod run;
mod small_steps;
mod stability;
mod sweep;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// How far to trust a particle-spring simulation.
#[derive(Debug, Parser)]
#[command(name = "springlab", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Solve every reference afresh, neither reading nor writing the reference store
    /// (SPRINGLAB_CACHE_DIR, else the platform cache folder's springlab/references; the
    /// environment variable SPRINGLAB_NO_CACHE turns the store off alone); `report` also
    /// studies every scene again
    #[arg(long, global = true)]
    no_cache: bool,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run one scenario with one method and write its trajectory, energy and summary.
    Run(run::Args),
    /// Validate a scenario and print its particles, springs, constraints and active terms.
    Check(check::Args),
    /// List the methods and the shipped scenarios.
    List(list::Args),
    /// Time every method on n×n cloths: cost per step against particle count (CSV + log-log SVG).
    BenchScaling(bench_scaling::Args),
    /// Measure the cost ratios that have targets in one interleaved run: step vs hand loop, Rapier frame vs
    /// step, 1→2 threads, implicit Euler at 1/60 (CSV + table).
    BenchRatios(bench_ratios::Args),
    /// Run every scene through every method and write plots, pages and summary.json.
    Report(report::Args),
    /// Run every method over a log grid of steps against the reference: sweep.csv, orders.
    Sweep(sweep::Args),
    /// Largest stable step per method (spectral radius and empirical bisection).
    Stability(stability::Args),
    /// Cheapest verified method and step for an error tolerance.
    Advise(advise::Args),
    /// Every applicable method at one step against the reference, side by side.
    Compare(compare::Args),
    /// Each method at game frame rates: the run at one substep, the fewest substeps meeting a
    /// tolerance, and the cost per frame (framerate.csv, framerate.json).
    Framerate(framerate::Args),
    /// Hold scenes to their `[expect]` tables: run each one's method and step against
    /// the reference, print pass/FAIL per expectation, optionally write JUnit XML.
    Expect(expect::Args),
    /// Join the shard directories of one sweep.
    Merge(merge::Args),
    /// Small Steps replicated: xpbd's n substeps × 1 iteration against 1 step × n iterations
    /// at a frame step (small_steps.json + small_steps.csv).
    SmallSteps(small_steps::Args),
}

impl Command {
    /// The subcommand's name, as typed: the label of the command's progress stage.
    fn name(&self) -> &'static str {
        match self {
            Command::Run(_) => "run",
            Command::Check(_) => "check",
            Command::List(_) => "list",
            Command::BenchScaling(_) => "bench-scaling",
            Command::BenchRatios(_) => "bench-ratios",
            Command::Report(_) => "report",
            Command::Sweep(_) => "sweep",
            Command::Stability(_) => "stability",
            Command::Advise(_) => "advise",
            Command::Compare(_) => "compare",
            Command::Framerate(_) => "framerate",
            Command::Expect(_) => "expect",
            Command::Merge(_) => "merge",
            Command::SmallSteps(_) => "small-steps",
        }
    }
}

/// Parses the command line, runs the command, and maps errors to a message and exit code 1.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let no_store = std::env::var_os("SPRINGLAB_NO_CACHE").is_some_and(|v| !v.is_empty());
    let no_cache = cli.no_cache;
    if !no_cache && !no_store {
        springlab::measure::reference::store::use_dir(
            springlab::measure::reference::store::default_dir(),
        );
    }
    // The whole command is a stage: a long one prints a progress line at least every
    // interval until it ends, whatever part of it runs.
    let _stage = springlab::run::progress_stage(cli.command.name(), true);
    // The flag a method name came from, named when the name is unknown.
    let method_flag = match cli.command {
        Command::Run(_) => "--method",
        _ => "--methods",
    };
    let result = match cli.command {
        Command::Run(a) => run::run(a),
        Command::Check(a) => check::run(a),
        Command::List(a) => list::run(a),
        Command::BenchScaling(a) => bench_scaling::run(a),
        Command::BenchRatios(a) => bench_ratios::run(a),
        Command::Report(a) => report::run(a, no_cache),
        Command::Sweep(a) => sweep::run(a),
        Command::Stability(a) => stability::run(a),
        Command::Advise(a) => advise::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Framerate(a) => framerate::run(a),
        Command::Expect(a) => expect::run(a),
        Command::Merge(a) => merge::run(a),
        Command::SmallSteps(a) => small_steps::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let unknown_method = matches!(
                e.downcast_ref::<springlab::error::Error>(),
                Some(springlab::error::Error::UnknownMethod { .. })
            );
            let flag = if unknown_method {
                format!("{method_flag}: ")
            } else {
                String::new()
            };
            eprintln!("error: {flag}{}", message(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, each cause once: a library error that already
/// prints its cause (an OS error) is not followed by that cause again.
fn message(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if out.contains(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out
}

#[cfg(test)]
mod tests {
    /// No command declares a flag twice, counting the method options generated from the
    /// registry: clap checks this itself only in debug builds, and the tests run in release.
    #[test]
    fn no_command_declares_a_flag_twice() {
        use clap::CommandFactory;
        let cli = super::Cli::command();
        for sub in cli.get_subcommands() {
            let mut seen = std::collections::BTreeSet::new();
            for arg in sub.get_arguments() {
                if let Some(long) = arg.get_long() {
                    assert!(
                        seen.insert(long.to_string()),
                        "springlab {}: --{long} is declared twice",
                        sub.get_name()
                    );
                }
            }
        }
        assert!(cli.get_subcommands().count() > 10);
    }
}
