//! `springlab advise`: the cheapest verified method and step for a tolerance.

use super::common::load;
use super::measure_common::{fmt_opt, MeasureArgs};
use anyhow::Result;
use springlab::measure::advise::{advise, write_advice, Advice, AdviseConfig};
use std::path::{Path, PathBuf};

/// Flags of `springlab advise`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    #[command(flatten)]
    pub m: MeasureArgs,
    /// Leave out the game view: `springlab framerate`'s table of the verified candidates at
    /// 30, 60, 120, 144 and 240 Hz, with each rate's cheapest.
    #[arg(long)]
    pub no_frame_rates: bool,
    #[command(flatten)]
    pub judge: super::common::JudgeArgs,
    /// Horizon (s; default the scene's duration).
    #[arg(long, allow_negative_numbers = true)]
    pub horizon: Option<f64>,
    /// Predictions aim at tolerance / safety.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub safety: f64,
    /// Smallest step tried (s).
    #[arg(long, allow_negative_numbers = true)]
    pub dt_min: Option<f64>,
    /// Largest step tried (s).
    #[arg(long, allow_negative_numbers = true)]
    pub dt_max: Option<f64>,
    /// Steps tried per method.
    #[arg(long, default_value_t = 10, allow_negative_numbers = true)]
    pub points: usize,
    /// Screen: a candidate, or a grid step of one, modelled above this many times the cost of
    /// the cheapest verified answer is not run (named with the figure); `inf` runs them all.
    #[arg(long, allow_negative_numbers = true, default_value_t = springlab::measure::advise::SCREEN_FACTOR)]
    pub screen: f64,
    /// Append the advised answer to the scenario file as an [expect] table (method, step,
    /// stable, position error within the tolerance, strain and energy drift rate with a
    /// margin over the verified run's), for `springlab expect` to hold the scene to it.
    #[arg(long)]
    pub write_expect: bool,
    /// The game's frame rate (Hz) whose answer --write-expect writes (method, hz, substeps);
    /// default: the scene's [run] hz when it has one, else the free step is written. A rate
    /// outside the game view's rates is added to it.
    #[arg(long, allow_negative_numbers = true)]
    pub hz: Option<f64>,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    a.m.check_out()?;
    let common = a.m.common()?;
    let scene = load(&a.scenario)?;
    if a.write_expect && scene.expect.is_some() {
        anyhow::bail!(
            "{}: expect: the file already has an [expect] table; remove it to write a new one (--write-expect)",
            a.scenario.display()
        );
    }
    if let Some(h) = a.hz.filter(|h| !(h.is_finite() && *h > 0.0)) {
        anyhow::bail!(
            "--hz: must be a finite frame rate > 0, got {}",
            springlab::error::num(h)
        );
    }
    let game_hz = a.hz.or(scene.run.hz);
    let cfg = AdviseConfig {
        tolerance: a.judge.tolerance,
        metric: a.judge.metric,
        horizon: a.horizon,
        safety: a.safety,
        points: a.points,
        dt_min: a.dt_min,
        dt_max: a.dt_max,
        frame_rates: !a.no_frame_rates,
        game_hz,
        screen_factor: a.screen,
        common,
        ..Default::default()
    };
    springlab::measure::advise::check_config(&scene, &cfg)?;
    let dir = a.m.out_dir(&scene.name, "advise");
    let _lock = springlab::output::lock_dir(&dir)?;
    let adv = advise(&scene, &cfg)?;
    let f = write_advice(&dir, &adv)?;
    print_pick(&scene.name, &adv);
    print_alternatives(&adv);
    print_frame_rates(&adv);
    super::common::print_written(&f);
    if a.write_expect {
        write_expect(&a.scenario, &adv, game_hz)?;
    }
    Ok(())
}

/// Prints how the advice was judged and what it picked, with the pick's cost.
fn print_pick(scene: &str, adv: &Advice) {
    println!("{}: {}", scene, adv.judged.describe());
    if let Some(n) = &adv.judged.metric_note {
        println!("  {n}");
    }
    match &adv.method {
        Some(n) => {
            let evals = match adv.cost_per_second {
                Some(e) => format!("{e:.0} force evaluations per simulated second"),
                None => "no force-evaluation count (Rapier method)".into(),
            };
            println!(
                "{}: use {n} at dt = {} s (predicted error {}, verified {})",
                scene,
                fmt_opt(adv.dt),
                fmt_opt(adv.predicted_error),
                fmt_opt(adv.verified_error),
            );
            println!(
                "  picked by {}: {} modelled s per simulated s ({} wall s, median of {} interleaved runs); {evals}",
                adv.picked_by.map_or("-".into(), |p| p.describe()),
                fmt_opt(adv.modelled_per_second),
                fmt_opt(adv.wall_per_second),
                adv.alternatives
                    .first()
                    .map_or(0, |c| c.timing.repetitions),
            );
        }
        None => println!(
            "{}: no candidate meets it on the steps tried (down to {} s)",
            scene,
            fmt_opt(adv.grid.first().copied())
        ),
    }
}

/// Prints the table of verified candidates, then the methods that cannot answer and the
/// candidates the screen left out.
fn print_alternatives(adv: &Advice) {
    println!(
        "{:<22} {:>12} {:>12} {:>14} {:>12} {:>12} {:>12}",
        "alternative", "modelled s/s", "wall s/s", "evals/s", "dt", "predicted", "verified"
    );
    for c in &adv.alternatives {
        println!(
            "{:<22} {:>12} {:>12} {:>14} {:>12} {:>12} {:>12}",
            c.method,
            fmt_opt(Some(c.modelled_per_second)),
            fmt_opt(Some(c.wall_per_second)),
            c.cost_per_second.map_or("-".into(), |e| format!("{e:.0}")),
            fmt_opt(Some(c.dt)),
            fmt_opt(Some(c.predicted_error)),
            fmt_opt(Some(c.verified_error)),
        );
    }
    for (n, why) in &adv.unable {
        println!("{n:<22} cannot: {why}");
    }
    for s in &adv.screened {
        println!("{:<22} {}", s.method, s.reason);
    }
}

/// Prints the game view: the frame-rate table of the verified candidates, then per rate the
/// cheapest method meeting the bound.
fn print_frame_rates(adv: &Advice) {
    let Some(fr) = &adv.frame_rates else {
        return;
    };
    super::framerate::print_table(fr);
    for b in &adv.best_at_rates {
        match (&b.method, b.substeps) {
            (Some(m), Some(n)) => println!(
                "{:>5} Hz: best {m} ×{n} ({})",
                b.hz,
                b.picked_by.map_or("-".into(), |p| p.describe())
            ),
            _ => println!("{:>5} Hz: no verified candidate meets the bound", b.hz),
        }
    }
}

/// Appends the advised answer to the scenario file as an [expect] table: the game-rate answer
/// at `game_hz` when there is one, else the free step.
fn write_expect(scenario: &Path, adv: &Advice, game_hz: Option<f64>) -> Result<()> {
    let spec = match game_hz {
        Some(hz) => springlab::measure::expect_answer::game_rate_table(adv, hz).ok_or_else(|| {
            anyhow::anyhow!(
                "--write-expect: no method meets the bound at {} Hz (the scene's frame rate, or --hz), so there is no game-rate answer to hold {} to",
                springlab::error::num(hz),
                scenario.display()
            )
        })?,
        None => springlab::measure::advise::expect_table(adv).ok_or_else(|| {
            anyhow::anyhow!(
                "--write-expect: no candidate met the bound, so there is no answer to hold {} to",
                scenario.display()
            )
        })?,
    };
    let path = springlab::scenario::append_expect::append_expect(
        scenario,
        &spec,
        &format!("The answer verified by: {}", adv.head.command),
    )?;
    println!("appended an [expect] table to {}", path.display());
    Ok(())
}
