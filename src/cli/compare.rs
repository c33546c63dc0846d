//! `springlab compare`: every applicable method at one step against the reference.

use super::common::load;
use super::measure_common::{fmt_opt, MeasureArgs};
use anyhow::Result;
use springlab::measure::compare::{compare, write_compare, CompareConfig, CompareResult};
use std::path::PathBuf;

/// Flags of `springlab compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    #[command(flatten)]
    pub m: MeasureArgs,
    /// Step (s, a number or a fraction such as 1/60; default the scene's).
    #[arg(long, value_parser = super::common::parse_seconds, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    #[command(flatten)]
    pub duration: super::common::DurationArg,
    /// Points per time series in summary.json (0: none).
    #[arg(long, default_value_t = 2000, allow_negative_numbers = true)]
    pub series_points: u64,
    /// Also record the paths of the most-travelled particles and snapshots of chains and
    /// cloths (what the report draws).
    #[arg(long)]
    pub trace: bool,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    a.m.check_out()?;
    let common = a.m.common()?;
    let scene = load(&a.scenario)?;
    let cfg = CompareConfig {
        dt: a.dt,
        duration: a.duration.value()?,
        frame_substeps: a.m.frame_substeps(),
        series_points: a.series_points,
        trace: a.trace,
        common,
        ..Default::default()
    };
    let dir = a.m.out_dir(&scene.name, "compare");
    let _lock = springlab::output::lock_dir(&dir)?;
    let res = compare(&scene, &cfg)?;
    let files = write_compare(&dir, &res)?;
    let split = res
        .frame_substeps
        .map_or(String::new(), |n| format!(" × {n} substeps"));
    println!(
        "{}: dt = {} s, {} steps{split}, reference {}",
        scene.name, res.dt, res.steps, res.reference.kind
    );
    print_table(&res);
    print_ensemble(&res);
    super::common::print_written(&files);
    Ok(())
}

/// Prints one line per method: status, errors, energy, strain and cost, with when and why an
/// unstable run blew up and why a method was skipped.
fn print_table(res: &CompareResult) {
    println!(
        "{:<22} {:<9} {:>11} {:>11} {:>11} {:>11} {:>11} {:>10} {:>11} {:>11}",
        "method",
        "status",
        "err final",
        "err max",
        "E drift/s",
        "E balance",
        "strain max",
        "evals",
        "modelled s",
        "wall s"
    );
    for e in &res.entries {
        match &e.result {
            Some(r) => {
                println!(
                    "{:<22} {:<9} {:>11} {:>11} {:>11} {:>11} {:>11} {:>10} {:>11} {:>11}",
                    e.method,
                    e.status,
                    fmt_opt(r.metric(|m| m.error_final)),
                    fmt_opt(r.metric(|m| m.error_max)),
                    fmt_opt(r.metric(|m| m.energy_drift)),
                    fmt_opt(r.metric(|m| m.energy_balance)),
                    fmt_opt(r.metric(|m| m.strain_max)),
                    r.force_evals,
                    fmt_opt(Some(r.modelled_seconds)),
                    fmt_opt(Some(r.wall_seconds))
                );
                if !r.ok() {
                    println!(
                        "{:<22}   unstable from t = {} s: {}",
                        "",
                        fmt_opt(r.unstable_time),
                        r.unstable_reason.as_deref().unwrap_or("")
                    );
                }
            }
            None => println!(
                "{:<22} skipped: {}",
                e.method,
                e.skip_reason.as_deref().unwrap_or("")
            ),
        }
    }
}

/// Prints, past the predictability horizon, each method's observables that lie outside the
/// reference ensemble's spread.
fn print_ensemble(res: &CompareResult) {
    let Some(en) = &res.ensemble else {
        return;
    };
    println!(
            "past the predictability horizon (t ≥ {} s), against an ensemble of {} references (position tolerance {} m: {}):",
            fmt_opt(Some(en.start)),
            en.members.len(),
            springlab::error::significant(res.position_tolerance.value, 4),
            res.position_tolerance.source
        );
    for e in &res.entries {
        let Some(stats) = e
            .result
            .as_ref()
            .and_then(|r| r.metrics.as_ref())
            .and_then(|m| m.statistics.as_ref())
        else {
            continue;
        };
        let off: Vec<String> = stats
            .iter()
            .filter(|(_, s)| !s.consistent)
            .map(|(k, s)| {
                format!(
                    "{k} {} (ensemble {} ± {})",
                    fmt_opt(Some(s.run_mean)),
                    fmt_opt(Some(s.ensemble_mean)),
                    fmt_opt(Some(s.ensemble_spread))
                )
            })
            .collect();
        if off.is_empty() {
            println!("{:<22} consistent on every observable", e.method);
        } else {
            println!("{:<22} inconsistent: {}", e.method, off.join("; "));
        }
    }
}
