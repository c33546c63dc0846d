//! `springlab report`: every scene through every backend, plots and pages under `reports/`.

use anyhow::Result;
use rayon::prelude::*;
use springlab::report::{report_scene, scenario_files, write_overview, ReportOptions, Summary};
use springlab::scenario::Scenario;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

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
    pub blowup: super::measure_common::BlowupArg,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    super::common::check_out(&a.out)?;
    let generator = format!("springlab {} report", env!("CARGO_PKG_VERSION"));
    // Shards of one report write disjoint scenes side by side: they share the folder.
    let _lock = match a.shard {
        Some(_) => springlab::output::lock_dir_shared(&a.out)?,
        None => springlab::output::lock_dir(&a.out)?,
    };
    if a.merge {
        let sum = springlab::report::shard::merge_shards(&a.out, &generator, a.quick)?;
        write_overview(&sum, &a.out)?;
        println!(
            "wrote {} ({} scenes, {} failed) from shards",
            a.out.join("index.html").display(),
            sum.scenes.len(),
            sum.failed.len()
        );
        return Ok(());
    }
    let all = scenario_files(&a.scenarios)?;
    let files: Vec<(usize, PathBuf)> = all
        .into_iter()
        .enumerate()
        .filter(|(k, _)| a.shard.is_none_or(|s| k % s.count == s.index))
        .collect();
    if files.is_empty() {
        anyhow::bail!("{}: no scenario files (*.toml)", a.scenarios.display());
    }
    let opts = ReportOptions {
        out: a.out.clone(),
        quick: a.quick,
        energy_terms: a.energy_terms,
        methods: springlab::method::Registry::builtin(),
        blowup_factor: a.blowup.value()?,
    };
    let bar = std::io::stderr()
        .is_terminal()
        .then(|| springlab::run::progress_bar(files.len() as u64, "report", true));
    let start = Instant::now();
    let mut rec = springlab::report::shard::ReportShard {
        shard: a
            .shard
            .unwrap_or(springlab::measure::sweep::Shard { index: 0, count: 1 }),
        scenes: Vec::new(),
        failed: Vec::new(),
    };
    let mut sum = Summary {
        generator,
        quick: a.quick,
        scenes: Vec::new(),
        failed: Vec::new(),
        small_steps: None,
    };
    // Scenes are independent: they are studied concurrently (two at a time on two cores,
    // sharing rayon's pool with their own inner loops) and gathered in file order, so the
    // documents and the overview do not depend on which finished first.
    let say = |line: &str| match &bar {
        Some(b) => b.println(line),
        None => eprintln!("{line}"),
    };
    // The report-level Small Steps page (shard 0 of a sharded report) runs beside the scenes.
    let small_steps_here = a.shard.is_none_or(|s| s.index == 0) && !a.quick;
    let (results, small_steps) = rayon::join(
        || {
            files
            .par_iter()
            .with_max_len(1)
            .map(|(k, f)| {
                let t0 = Instant::now();
                let res = Scenario::from_file(f).and_then(|scene| report_scene(&scene, &opts));
                match &res {
                    Ok(s) => {
                        let p = s.seconds;
                        say(&format!(
                            "report: {} done in {:.1} s (compare {:.1}, sweep {:.1}, stability {:.1}, advice {:.1}, frame rates {:.1})",
                            s.scene,
                            t0.elapsed().as_secs_f64(),
                            p.compare,
                            p.sweep,
                            p.stability,
                            p.advice,
                            p.framerate
                        ));
                    }
                    Err(e) => say(&format!("report: {}: {e}", f.display())),
                }
                if let Some(b) = &bar {
                    b.inc(1);
                }
                (*k, f, res)
            })
                .collect::<Vec<_>>()
        },
        || {
            small_steps_here
                .then(|| springlab::report::small_steps::write_page(&a.scenarios, &a.out))
                .transpose()
        },
    );
    match small_steps {
        Ok(link) => sum.small_steps = link.flatten(),
        Err(e) => say(&format!("report: small steps: {e}")),
    }
    for (k, f, res) in results {
        match res {
            Ok(s) => {
                rec.scenes.push((k, s.scene.clone()));
                sum.scenes.push(s);
            }
            Err(e) => {
                rec.failed.push((k, f.display().to_string(), e.to_string()));
                sum.failed.push((f.display().to_string(), e.to_string()));
            }
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if a.shard.is_some() {
        let p = springlab::report::shard::write_shard(&a.out, &rec)?;
        println!(
            "wrote {} scenes and {} in {:.1} s; build the overview with --merge",
            rec.scenes.len(),
            p.display(),
            start.elapsed().as_secs_f64()
        );
        return Ok(());
    }
    write_overview(&sum, &a.out)?;
    println!(
        "wrote {} ({} scenes, {} failed) in {:.1} s",
        a.out.join("index.html").display(),
        sum.scenes.len(),
        sum.failed.len(),
        start.elapsed().as_secs_f64()
    );
    if !sum.failed.is_empty() {
        anyhow::bail!("{} scenario(s) could not be reported", sum.failed.len());
    }
    Ok(())
}
