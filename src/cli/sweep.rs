//! `springlab sweep`: every method over a grid of steps from the scene's dynamics, refined
//! until asymptotic; orders (or why none); shards.

use super::common::load;
use super::measure_common::{fmt_opt, MeasureArgs};
use anyhow::Result;
use springlab::measure::sweep::{run_sweep, write_sweep, Shard, SweepConfig};
use std::path::PathBuf;

/// Flags of `springlab sweep`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    #[command(flatten)]
    pub m: MeasureArgs,
    /// Smallest step of the base grid (s). Default: the step at which the fastest linearised
    /// mode has hω_max = 0.05. Giving it fixes the small end: no refinement below it unless
    /// --extend.
    #[arg(long, allow_negative_numbers = true)]
    pub dt_min: Option<f64>,
    /// Largest step (s). Default: 1.25 × the widest theoretical stability limit of the swept
    /// methods (hω_max = 3 when none has one), at most a quarter of the duration.
    #[arg(long, allow_negative_numbers = true)]
    pub dt_max: Option<f64>,
    /// Number of log-spaced steps in [dt-min, dt-max]. Default: halving-spaced.
    #[arg(long, allow_negative_numbers = true)]
    pub points: Option<usize>,
    /// Refine each method by halving below the base grid until its error is asymptotic (the
    /// local slopes at the finest steps steady), at the reference floor or at the cost cap.
    /// Default: on, unless --dt-min is given.
    #[arg(long, conflicts_with = "no_extend")]
    pub extend: bool,
    /// Run the base grid only.
    #[arg(long)]
    pub no_extend: bool,
    /// Cost cap per method: steps × particles summed over its runs (default 4e6). It counts
    /// steps, not time: a costly method (rapier_multibody on a large cloth) can still be slow.
    #[arg(long, allow_negative_numbers = true)]
    pub cost_cap: Option<f64>,
    #[command(flatten)]
    pub duration: super::common::DurationArg,
    /// Run only slice I of N (0 ≤ I < N); join the slices with `springlab merge`.
    #[arg(long)]
    pub shard: Option<Shard>,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    a.m.check_out()?;
    let common = a.m.common()?;
    let scene = load(&a.scenario)?;
    let cfg = SweepConfig {
        dt_min: a.dt_min,
        dt_max: a.dt_max,
        points: a.points,
        extend: match (a.extend, a.no_extend) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
        cost_cap: a.cost_cap,
        duration: a.duration.value()?,
        shard: a.shard,
        common,
        ..Default::default()
    };
    let dir = match a.shard {
        Some(s) if a.m.out.out.is_none() => a.m.out_dir(
            &scene.name,
            &format!("sweep/shard-{}-of-{}", s.index, s.count),
        ),
        _ => a.m.out_dir(&scene.name, "sweep"),
    };
    let _lock = springlab::output::lock_dir(&dir)?;
    let t0 = std::time::Instant::now();
    let res = run_sweep(&scene, &cfg)?;
    let files = write_sweep(&dir, &res)?;
    println!(
        "{}: {} cases, reference {} ({} s), {:.2} s wall",
        scene.name,
        res.rows.len(),
        res.reference.kind,
        res.plan.duration,
        t0.elapsed().as_secs_f64()
    );
    if let Some(s) = &res.summary {
        println!(
            "{:<22} {:>8} {:>8} {:>9} {:>8} {:>10}  dt range (or why no order)",
            "method", "theory", "observed", "R²", "points", "finest dt"
        );
        for i in &s.methods {
            println!(
                "{:<22} {:>8} {:>8} {:>9} {:>8} {:>10}  {}",
                i.method,
                i.theoretical_order.map_or("-".into(), |o| o.to_string()),
                i.observed_order.map_or("-".into(), |o| format!("{o:.3}")),
                i.fit.r_squared.map_or("-".into(), |r| format!("{r:.5}")),
                format!(
                    "{}/{}",
                    i.fit.points_used,
                    i.stable_points + i.unstable_points
                ),
                fmt_opt(Some(i.finest_dt)),
                i.fit.dt_range.map_or_else(
                    || i.fit.note.clone().unwrap_or_default(),
                    |r| format!("{} .. {}", fmt_opt(Some(r[0])), fmt_opt(Some(r[1])))
                )
            );
        }
        for (n, why) in &s.skipped {
            println!("{n:<22} skipped: {why}");
        }
        let r = &s.grid_rule;
        println!(
            "grid: ω_max {:.4e} rad/s; dt_max {:.4e} s ({}); dt_min {:.4e} s ({}); refinement {}; cost cap {:e} particle-steps per method",
            r.omega_max,
            r.dt_max,
            r.dt_max_source,
            r.dt_min,
            r.dt_min_source,
            if r.extend { "on" } else { "off" },
            r.cost_cap_particle_steps
        );
        if let Some(b) = &s.budget {
            for m in b.methods.iter().filter(|m| m.finest > res.plan.base_from) {
                println!(
                    "budget: {} runs dt ≥ {} s only: {}",
                    m.method,
                    fmt_opt(Some(res.plan.dts[m.finest])),
                    b.sentence(m)
                );
            }
        }
    }
    super::common::print_written(&files);
    Ok(())
}
