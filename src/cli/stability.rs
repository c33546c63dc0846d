//! `springlab stability`: largest stable step per method, theory and experiment.

use super::common::load;
use super::measure_common::{fmt_opt, MeasureArgs};
use anyhow::{bail, Result};
use springlab::error::num;
use springlab::measure::stability::{
    analyse, stability_map, write_stability, MapConfig, StabilityConfig, StabilityReport,
    MAP_HEADER,
};
use springlab::output::write_atomic;
use springlab::scenario::Scenario;
use std::path::{Path, PathBuf};

/// Flags of `springlab stability`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    #[command(flatten)]
    pub m: MeasureArgs,
    /// Horizon of each empirical trial run (s; default 100 periods of the highest mode).
    #[arg(long, allow_negative_numbers = true)]
    pub horizon: Option<f64>,
    /// Skip the empirical bisection.
    #[arg(long)]
    pub theory_only: bool,
    /// Run the empirical bisection only for methods without linear theory (engines); where the
    /// spectral radius applies it decides anyway, and the bisection is a costly cross-check.
    #[arg(long, conflicts_with = "theory_only")]
    pub empirical_where_no_theory: bool,
    /// Also sweep stiffness × dt into stability_map.csv.
    #[arg(long)]
    pub map: bool,
    /// Damping multipliers for the map, comma-separated (default 1).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub damping_scales: Vec<f64>,
    /// Stiffness multipliers for the map, comma-separated (default 1/16 … 16, 9 points).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub stiffness_scales: Vec<f64>,
    /// Absolute steps (s) for the map, comma-separated (default: 16 steps with hω from 0.02
    /// to 20 on the unscaled scene).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub dts: Vec<f64>,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    a.m.check_out()?;
    let common = a.m.common()?;
    let scene = load(&a.scenario)?;
    if let Some(h) = a.horizon {
        if !(h.is_finite() && h > 0.0) {
            bail!("--horizon: must be a finite number > 0, got {}", num(h));
        }
    }
    check_map_args(&a)?;
    let cfg = StabilityConfig {
        horizon: a.horizon,
        theory_only: a.theory_only,
        empirical_where_no_theory: a.empirical_where_no_theory,
        common: common.clone(),
    };
    let dir = a.m.out_dir(&scene.name, "stability");
    let _lock = springlab::output::lock_dir(&dir)?;
    let rep = analyse(&scene, &cfg)?;
    let mut files = vec![write_stability(&dir, &rep)?];
    print_report(&scene.name, &rep);
    if a.map {
        files.push(write_map(&scene, &a, common, &dir)?);
    }
    super::common::print_written(&files);
    Ok(())
}

/// Checks the map's scales and steps: stiffness scales and steps finite and > 0, damping
/// scales finite and ≥ 0.
fn check_map_args(a: &Args) -> Result<()> {
    for v in &a.stiffness_scales {
        if !(v.is_finite() && *v > 0.0) {
            bail!(
                "--stiffness-scales: values must be finite and > 0, got {}",
                num(*v)
            );
        }
    }
    for v in &a.dts {
        if !(v.is_finite() && *v > 0.0) {
            bail!("--dts: steps must be finite and > 0 s, got {}", num(*v));
        }
    }
    for v in &a.damping_scales {
        if !(v.is_finite() && *v >= 0.0) {
            bail!(
                "--damping-scales: values must be finite and ≥ 0, got {}",
                num(*v)
            );
        }
    }
    Ok(())
}

/// Prints the stability table (verdict, largest stable step, hω and what decided it), then
/// the skipped methods, each method's statement and its notes.
fn print_report(scene: &str, rep: &StabilityReport) {
    println!(
        "{}: ω_max = {:.6} rad/s ({})",
        scene, rep.omega_max, rep.modes.found_by
    );
    println!(
        "{:<22} {:<24} {:>12} {:>9} {:<22}",
        "method", "verdict", "max dt", "hω", "decided by"
    );
    for i in &rep.methods {
        println!(
            "{:<22} {:<24} {:>12} {:>9} {:<22}",
            i.method,
            i.verdict.words(),
            fmt_opt(i.max_stable_dt),
            i.h_omega.map_or("-".into(), |h| format!("{h:.6}")),
            i.decided_by.name(),
        );
    }
    for (n, why) in &rep.skipped {
        println!("{n:<22} skipped: {why}");
    }
    for i in &rep.methods {
        println!("{:<22} {}", i.method, i.statement);
    }
    for i in &rep.methods {
        if let Some(note) = &i.note {
            println!("{:<22} note: {note}", i.method);
        }
    }
}

/// Sweeps stiffness × dt (at each damping scale) for the methods asked for and writes the rows to
/// `stability_map.csv` in `dir`; returns the file written.
fn write_map(
    scene: &Scenario,
    a: &Args,
    common: springlab::measure::Common,
    dir: &Path,
) -> Result<PathBuf> {
    let mut mc = MapConfig {
        common: springlab::measure::Common {
            budget_seconds: None,
            ..common
        },
        ..Default::default()
    };
    if !a.damping_scales.is_empty() {
        mc.damping_scales = a.damping_scales.clone();
    }
    if !a.stiffness_scales.is_empty() {
        mc.stiffness_scales = a.stiffness_scales.clone();
    }
    mc.dts = a.dts.clone();
    let rows = stability_map(scene, &mc)?;
    let mut csv = String::from(MAP_HEADER);
    csv.push('\n');
    for r in &rows {
        csv.push_str(&r.csv_line());
        csv.push('\n');
    }
    Ok(write_atomic(dir.join("stability_map.csv"), csv.as_bytes())?)
}
