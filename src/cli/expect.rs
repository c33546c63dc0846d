//! `springlab expect`: hold scenes to their `[expect]` tables, for a CI job.

use anyhow::{bail, Result};
use springlab::measure::expect::{check_scene, describe, error_row, junit, ExpectRow};
use springlab::scenario::Scenario;
use std::path::PathBuf;

/// Flags of `springlab expect`.
#[derive(Debug, clap::Args)]
#[command(
    long_about = "Runs each scene's [expect] method at its frame step (hz or dt) with its \
substeps over the scene's duration against the reference, the same run `compare` makes for one \
method, and prints one line per expectation: what is expected, what was measured, pass or FAIL. \
The run and its reference are held to --budget (modelled seconds, as compare's): a scene whose \
reference or run would pass it fails with the figure. \
A scene without an [expect] table is listed as skipped (not a failure) unless no scene given has \
one, which is an error; a scene that does not load is a failing line naming the file. \
Exits non-zero when any expectation fails."
)]
pub struct Args {
    /// Scenario files (TOML); those without an `[expect]` table are listed as skipped.
    #[arg(required = true)]
    pub scenarios: Vec<PathBuf>,
    /// Also write the results as JUnit XML to this file (one testcase per expectation, named
    /// without its limit; the limit is in the failure message).
    #[arg(long)]
    pub junit: Option<PathBuf>,
    #[command(flatten)]
    pub budget: super::common::BudgetArg,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    let mut rows: Vec<ExpectRow> = Vec::new();
    for path in &a.scenarios {
        let label = path.display().to_string();
        match Scenario::from_file(path) {
            Err(e) => rows.push(error_row(&label, "scene loads", &e.to_string())),
            Ok(scene) => {
                if let Some(e) = &scene.expect {
                    println!("{label}: {}", describe(e));
                }
                // A scene that cannot be measured (a reference past the budget) fails with
                // the reason; the other scenes are still checked.
                match check_scene(&scene, &label, Some(a.budget.budget)) {
                    Ok(r) => rows.extend(r),
                    Err(e) => rows.push(error_row(&label, "scene is measured", &e.to_string())),
                }
            }
        }
    }
    let w = |f: fn(&ExpectRow) -> usize, head: &str| {
        rows.iter()
            .map(f)
            .max()
            .unwrap_or(0)
            .max(head.chars().count())
    };
    let ws = w(|r| r.scene.chars().count(), "scene");
    let we = w(|r| r.expectation.chars().count(), "expectation");
    let wm = w(|r| r.measured.chars().count(), "measured");
    let pad = |s: &str, n: usize| format!("{s}{}", " ".repeat(n.saturating_sub(s.chars().count())));
    println!(
        "{}  {}  {}  result",
        pad("scene", ws),
        pad("expectation", we),
        pad("measured", wm)
    );
    for r in &rows {
        println!(
            "{}  {}  {}  {}",
            pad(&r.scene, ws),
            pad(&r.expectation, we),
            pad(&r.measured, wm),
            r.verdict()
        );
    }
    if let Some(file) = &a.junit {
        let written = springlab::output::write_atomic(file, junit(&rows).as_bytes())?;
        println!("wrote {}", written.display());
    }
    let failed = rows.iter().filter(|r| !r.passed()).count();
    let checked = rows.iter().filter(|r| !r.skipped).count();
    if checked == 0 {
        bail!(
            "none of the {} scene(s) given has an [expect] table: nothing was checked",
            a.scenarios.len()
        );
    }
    if failed > 0 {
        bail!(
            "{failed} of {checked} expectations failed ({})",
            rows.iter()
                .filter(|r| !r.passed())
                .map(|r| format!("{}: {}", r.scene, r.expectation))
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    println!("all {checked} expectations hold");
    Ok(())
}
