//! `springlab small-steps`: the Small Steps comparison (n substeps × 1 iteration against
//! 1 step × n iterations of xpbd at a frame step), written as JSON and CSV.

use super::common::load;
use anyhow::Result;
use springlab::measure::small_steps::{small_steps, SmallStepsConfig, DEFAULT_BUDGETS};
use std::path::{Path, PathBuf};

/// Flags of `springlab small-steps`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario files (default: scenarios/stiff_chain.toml and scenarios/cloth.toml).
    pub scenarios: Vec<PathBuf>,
    /// Frame step in seconds (default 1/60).
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    #[command(flatten)]
    pub duration: super::common::DurationArg,
    /// Budgets n (sweeps per frame), comma-separated (default 1,2,4,8,16,32,64).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub budgets: Vec<usize>,
    #[command(flatten)]
    pub out: super::common::OutArg,
    #[command(flatten)]
    pub budget: super::common::BudgetArg,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    a.out.check()?;
    let paths = if a.scenarios.is_empty() {
        springlab::measure::small_steps::DEFAULT_SCENES
            .iter()
            .map(|f| Path::new("scenarios").join(f))
            .collect()
    } else {
        a.scenarios.clone()
    };
    let scenes = paths.iter().map(load).collect::<Result<Vec<_>>>()?;
    let cfg = SmallStepsConfig {
        frame_dt: a.dt.unwrap_or(springlab::measure::small_steps::FRAME_DT),
        duration: a.duration.value()?,
        budgets: if a.budgets.is_empty() {
            DEFAULT_BUDGETS.to_vec()
        } else {
            a.budgets.clone()
        },
        budget_seconds: Some(a.budget.budget),
    };
    let out = a.out.or(|| PathBuf::from("out/small_steps"));
    let _lock = springlab::output::lock_dir(&out)?;
    let doc = small_steps(&scenes, &cfg)?;
    let fmt = |v: Option<f64>| v.map_or("-".into(), |x| format!("{x:.3e}"));
    for sc in &doc.scenes {
        println!(
            "{} at dt = {:.6} s over {} s ({} frames compared; reference stretch {:.3e})",
            sc.scene, sc.frame_dt, sc.duration, sc.compared_frames, sc.reference_stretch_max
        );
        println!(
            "  {:>4} {:>13} {:>10} {:>10} {:>11} {:>10} {:>10}",
            "n", "split", "error_max", "stretch", "stretch_err", "num_diss", "wall_s"
        );
        for b in &sc.budgets {
            for (label, r) in [("n sub x 1 it", &b.substeps), ("1 x n it", &b.iterations)] {
                println!(
                    "  {:>4} {:>13} {:>10} {:>10} {:>11} {:>10} {:>10.3e}",
                    b.n,
                    label,
                    fmt(r.error_max),
                    fmt(r.stretch_max),
                    fmt(r.stretch_error),
                    fmt(r.numerical_dissipation),
                    r.wall_seconds
                );
            }
        }
        println!("  {}", sc.verdict);
    }
    springlab::measure::small_steps::write_small_steps(&out, &doc)?;
    println!("wrote {}", out.display());
    Ok(())
}
