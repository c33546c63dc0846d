//! `springlab framerate`: each method at game frame rates, with one substep and with the
//! fewest substeps that meet a tolerance, and the cost per frame.

use super::common::load;
use anyhow::Result;
use springlab::measure::framerate::{
    framerate, write_framerate, Framerate, FramerateConfig, DEFAULT_MAX_SUBSTEPS,
};
use std::path::{Path, PathBuf};

/// Flags of `springlab framerate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Frame rates in Hz, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        default_value = "30,60,120,144,240"
    )]
    pub hz: Vec<f64>,
    /// The rates engines (Rapier) are searched at, comma-separated, each one of --hz
    /// (default: every rate).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub engine_hz: Vec<f64>,
    #[command(flatten)]
    pub judge: super::common::JudgeArgs,
    #[command(flatten)]
    pub common: super::common::CommonArgs,
    #[command(flatten)]
    pub duration: super::common::DurationArg,
    /// Largest number of substeps per frame tried.
    #[arg(long, default_value_t = DEFAULT_MAX_SUBSTEPS, allow_negative_numbers = true)]
    pub max_substeps: u64,
    /// Largest run tried, in particle-steps (particles × frames × substeps); default no cap.
    #[arg(long, allow_negative_numbers = true)]
    pub cost_cap: Option<f64>,
    #[command(flatten)]
    pub out: super::common::OutArg,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    a.out.check()?;
    let common = a.common.common(None)?;
    let scene = load(&a.scenario)?;
    let duration = a.duration.value()?;
    let cfg = FramerateConfig {
        rates: a.hz.clone(),
        engine_rates: (!a.engine_hz.is_empty()).then(|| a.engine_hz.clone()),
        tolerance: a.judge.tolerance,
        metric: a.judge.metric,
        duration,
        max_substeps: a.max_substeps,
        cost_cap: a.cost_cap,
        common,
        ..Default::default()
    };
    let dir = a
        .out
        .or(|| Path::new("out").join(&scene.name).join("framerate"));
    let _lock = springlab::output::lock_dir(&dir)?;
    let fr = framerate(&scene, &cfg)?;
    let files = write_framerate(&dir, &fr)?;
    println!(
        "{}: {} over {} s, reference {}, events {}",
        scene.name,
        fr.judged.describe(),
        fr.duration,
        fr.head.reference.kind,
        fr.events
    );
    if let Some(n) = &fr.judged.metric_note {
        println!("  {n}");
    }
    print_table(&fr);
    for e in fr.entries.iter().filter(|e| e.fewest.is_none()) {
        if let Some(note) = &e.fewest_note {
            println!("{} at {} Hz: {note}", e.method, e.hz);
        }
    }
    if let Some(note) = &fr.reference_note {
        println!("note: {note}");
    }
    for (n, why) in &fr.skipped {
        println!("skipped {n}: {why}");
    }
    super::common::print_written(&files);
    Ok(())
}

/// Prints one line per method and rate: the run at one substep, the fewest substeps that meet
/// the bound with that run's error and cost per frame.
pub(super) fn print_table(fr: &Framerate) {
    println!(
        "{:<22} {:>6} {:>9} {:>11} {:>9} {:>11} {:>12} {:>12} {:>10}",
        "method",
        "hz",
        "1 substep",
        "error 1",
        "needed",
        "error",
        "model/frame",
        "wall/frame",
        "evals/fr"
    );
    let e3 = super::measure_common::fmt_opt;
    for e in &fr.entries {
        let one = &e.one_substep;
        let (needed, err, modelled, wall, evals) = match &e.fewest {
            Some(f) => (
                f.substeps.to_string(),
                e3(f.error),
                e3(f.modelled_seconds_per_frame),
                e3(f.wall_seconds_per_frame),
                f.force_evals_per_frame
                    .map_or("—".to_string(), |x| format!("{x:.0}")),
            ),
            None => (
                "none".into(),
                "—".into(),
                "—".into(),
                "—".into(),
                "—".into(),
            ),
        };
        println!(
            "{:<22} {:>6} {:>9} {:>11} {:>9} {:>11} {:>12} {:>12} {:>10}",
            e.method,
            e.hz,
            one.status,
            e3(one.error),
            needed,
            err,
            modelled,
            wall,
            evals
        );
    }
}
