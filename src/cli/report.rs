//! `springlab report`: every scene through every backend, plots and pages under `reports/`.

use anyhow::Result;
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
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    let files = scenario_files(&a.scenarios)?;
    if files.is_empty() {
        anyhow::bail!("{}: no scenario files (*.toml)", a.scenarios.display());
    }
    let opts = ReportOptions {
        out: a.out.clone(),
        quick: a.quick,
        energy_terms: a.energy_terms,
        methods: springlab::method::Registry::builtin(),
    };
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(files.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} {msg}")
                .expect("valid template"),
        );
        b
    });
    let start = Instant::now();
    let mut sum = Summary {
        generator: format!("springlab {} report", env!("CARGO_PKG_VERSION")),
        quick: a.quick,
        scenes: Vec::new(),
        failed: Vec::new(),
    };
    for f in &files {
        let name = f
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        match &bar {
            Some(b) => b.set_message(name.clone()),
            None => eprintln!("report: {name} …"),
        }
        let t0 = Instant::now();
        let res = Scenario::from_file(f).and_then(|scene| report_scene(&scene, &opts));
        match res {
            Ok(s) => {
                let line = format!(
                    "report: {} done in {:.1} s",
                    s.scene,
                    t0.elapsed().as_secs_f64()
                );
                match &bar {
                    Some(b) => b.println(line),
                    None => eprintln!("{line}"),
                }
                sum.scenes.push(s);
            }
            Err(e) => {
                let line = format!("report: {}: {e}", f.display());
                match &bar {
                    Some(b) => b.println(&line),
                    None => eprintln!("{line}"),
                }
                sum.failed.push((f.display().to_string(), e.to_string()));
            }
        }
        if let Some(b) = &bar {
            b.inc(1);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
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
