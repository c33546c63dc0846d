//! `springlab report`: every scene through every method, plots and pages under `reports/`
//! ([`springlab::pipeline::build`] does the work; this parses the flags).

use anyhow::Result;
use springlab::pipeline::{build, BuildConfig, Built};
use springlab::report::ReportOptions;
use std::path::PathBuf;

/// Flags of `springlab report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Directory of scenario files (*.toml).
    #[arg(long, default_value = "scenarios")]
    pub scenarios: PathBuf,
    /// Output directory.
    #[arg(long, default_value = "reports")]
    pub out: PathBuf,
    /// Fast, coarse pass (short runs, few sweep points); used by tests.
    #[arg(long)]
    pub quick: bool,
    /// Also plot the individual energy terms (kinetic, gravity, elastic, …).
    #[arg(long)]
    pub energy_terms: bool,
    /// Study only the scenes with index k ≡ I (mod N) (scene files in name order) and record
    /// them in OUT/shards/; build the overview afterwards with --merge (a Slurm array's tasks).
    #[arg(long, conflicts_with = "merge")]
    pub shard: Option<springlab::measure::sweep::Shard>,
    /// Build the overview (index.html, README.md, summary.json) from the shards in OUT/shards/.
    #[arg(long)]
    pub merge: bool,
    #[command(flatten)]
    pub blowup: super::common::BlowupArg,
}

/// Runs the command; `no_cache` (the global `--no-cache`) studies every scene again, even one
/// whose folder already holds what its unchanged scene file, these flags and this build
/// produce (see OUT/SCENE/inputs.txt).
pub fn run(a: Args, no_cache: bool) -> Result<()> {
    super::common::check_out(&a.out)?;
    let generator = format!("springlab {} report", env!("CARGO_PKG_VERSION"));
    if a.merge {
        let _lock = springlab::output::lock_dir(&a.out)?;
        let sum = springlab::report::shard::merge_shards(&a.out, &generator, a.quick)?;
        springlab::report::write_overview(&sum, &a.out)?;
        println!(
            "wrote {} ({} scenes, {} failed) from shards",
            a.out.join("index.html").display(),
            sum.scenes.len(),
            sum.failed.len()
        );
        return Ok(());
    }
    let cfg = BuildConfig {
        scenarios: a.scenarios,
        opts: ReportOptions {
            out: a.out,
            quick: a.quick,
            energy_terms: a.energy_terms,
            registry: springlab::method::Registry::builtin(),
            blowup_factor: a.blowup.value()?,
            no_cache,
        },
        shard: a.shard,
        generator,
    };
    let say = |l: &str| eprintln!("{l}");
    let start = std::time::Instant::now();
    let seconds = || start.elapsed().as_secs_f64();
    match build(&cfg, &say)? {
        Built::Shard(rec, p) => {
            println!(
                "wrote {} scenes and {} in {:.1} s; build the overview with --merge",
                rec.scenes.len(),
                p.display(),
                seconds()
            );
            Ok(())
        }
        Built::Overview(sum) => {
            let kept = sum.scenes.iter().filter(|s| s.failed_this_time.is_some());
            println!(
                "wrote {} ({} scenes, {} failed) in {:.1} s",
                cfg.opts.out.join("index.html").display(),
                sum.scenes.len() - kept.count(),
                sum.failed.len(),
                seconds()
            );
            if !sum.failed.is_empty() {
                anyhow::bail!("{} scenario(s) could not be reported", sum.failed.len());
            }
            Ok(())
        }
    }
}
