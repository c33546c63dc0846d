//! Building the report: per scene, collect → charts (SVG + CSV) → page; then the overview,
//! the Markdown README and `summary.json`. Every file is written atomically, scene pages
//! before the overview, so an interrupted run leaves every earlier file whole.

use super::charts;
use super::collect::{collect_scene, CollectOptions};
use super::data::ChartCsv;
use super::html::{index_page, scene_page, Figure};
use super::plots;
use super::results::SceneResults;
use super::summary::{scene_summary, SceneSummary, Summary};
use crate::error::{Error, Result};
use crate::output::write_atomic;
use crate::scenario::Scenario;
use std::path::{Path, PathBuf};

/// What `springlab report` was asked for.
#[derive(Debug, Clone)]
pub struct ReportOptions {
    /// Output directory (`reports/`).
    pub out: PathBuf,
    /// Coarse, fast pass.
    pub quick: bool,
    /// Add the individual energy terms to the energy chart.
    pub energy_terms: bool,
}

/// Steps of a quick pass's comparison runs at most.
pub const QUICK_MAX_STEPS: u64 = 300;

/// The scenario files of a directory (`*.toml`), sorted by name.
pub fn scenario_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let rd = std::fs::read_dir(dir).map_err(|source| Error::Read {
        file: dir.to_path_buf(),
        source,
    })?;
    let mut files: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    Ok(files)
}

/// The comparison step and length of a scene: its `[run]` table, shortened for `--quick`.
pub fn scene_plan(scene: &Scenario, quick: bool) -> Result<(f64, u64)> {
    let dt = scene.run.dt.ok_or_else(|| {
        Error::invalid(
            &scene.source,
            "run.dt",
            "the report needs a time step: set [run].dt",
        )
    })?;
    let steps = match (scene.run.steps, scene.run.duration) {
        (Some(n), _) => n,
        (None, Some(d)) => ((d / dt).round() as u64).max(1),
        (None, None) => {
            return Err(Error::invalid(
                &scene.source,
                "run.duration",
                "the report needs a run length: set [run].duration or [run].steps",
            ))
        }
    };
    Ok((
        dt,
        if quick {
            steps.min(QUICK_MAX_STEPS)
        } else {
            steps
        },
    ))
}

fn write_chart(dir: &Path, stem: &str, svg: Result<String>, data: &dyn ChartCsv) -> Result<()> {
    write_atomic(dir.join(format!("{stem}.csv")), &data.to_csv()?)?;
    write_atomic(dir.join(format!("{stem}.svg")), svg?.as_bytes())?;
    Ok(())
}

/// Writes one scene's charts and page under `out/<scene>/` and returns its summary.
pub fn write_scene(r: &SceneResults, opts: &ReportOptions) -> Result<SceneSummary> {
    let dir = opts.out.join(&r.scene);
    let mut figs = Vec::new();
    let mut fig = |stem: &str, title: &str, caption: String| {
        figs.push(Figure {
            stem: stem.into(),
            title: title.into(),
            caption,
        })
    };
    let e = charts::energy(r, opts.energy_terms);
    write_chart(&dir, "energy", plots::energy(&e), &e)?;
    fig("energy", "Energy over time", "The total energy account per backend; flat is right. A run that blew up stops at its × marker.".into());
    let ee = charts::energy_error(r);
    write_chart(&dir, "energy_error", plots::energy_error(&ee), &ee)?;
    fig(
        "energy_error",
        "Relative energy error",
        format!(
            "|E(t) − E(0)| / E_scale on a log scale, with {}.",
            ee.scale_note
        ),
    );
    let pe = charts::position_error(r);
    write_chart(&dir, "position_error", plots::position_error(&pe), &pe)?;
    fig(
        "position_error",
        "Position error against the reference",
        format!(
            "RMS distance of the free particles from the reference ({}), log scale.",
            r.reference
        ),
    );
    if let Some(c) = charts::convergence(r) {
        write_chart(&dir, "convergence", plots::convergence(&c), &c)?;
        fig("convergence", "Convergence", format!("End-point error against the step over {} s, log-log; the legend gives each line's least-squares slope over its three finest stable points, dashed lines are reference slopes. Blow-ups are marked at the coarsest unstable step.", super::finite::cell(r.sweep.as_ref().map(|s| s.duration), 3)));
    }
    let mut notes = Vec::new();
    if let Some(w) = charts::work_precision(r) {
        write_chart(&dir, "work_precision", plots::work_precision(&w), &w)?;
        fig("work_precision", "Work against precision", "The same sweep as cost: lower-left is better. Wall time varies between machines and runs; force evaluations do not.".into());
    } else if r.sweep.is_some() {
        notes.push("Work against precision: no run of the step-size sweep stayed stable, so there is nothing to plot.".to_string());
    }
    if let Some(s) = charts::stability(r) {
        write_chart(&dir, "stability", plots::stability(&s), &s)?;
        let max = r.scan.as_ref().map_or(0, |s| s.max_steps);
        fig("stability", "Stability map", format!("Each cell is one run at h = θ/ω for the scene's duration (at least 30, at most {max} steps): green when it did not blow up and its energy gain E(t) − E(0) did not grow (unstable: the largest gain in the last third of the run is more than twice that of the first third and more than 1% of the scene's energy scale; losses from numerical damping count as stable), red otherwise. Black bars: the textbook limit for an undamped linear oscillator (damping and nonlinearity shift it)."));
    }
    let p = charts::paths(r);
    write_chart(&dir, "paths", plots::paths(&p), &p)?;
    fig("paths", "Trajectories", format!("Paths of the most-travelled free particle(s) in the {}{}-plane (vertical: the axis gravity acts along, if any; else the plane where the reference moves most).", p.axes[0], p.axes[1]));
    if let Some(s) = charts::snapshots(r) {
        write_chart(&dir, "snapshots", plots::snapshots(&s), &s)?;
        fig("snapshots", "Snapshots", "The chain or cloth at a few instants (light to dark), one panel per backend at the same scale.".into());
    }
    let mut sum = scene_summary(r);
    sum.verdict = super::verdict::verdict(&sum, r);
    if let Some(c) = charts::collision(r) {
        write_chart(&dir, "collision", plots::collision(&c), &c)?;
        fig("collision", "Collision", "Left: the gap between the first tracked particle and the obstacle (negative: penetration), with the apex heights h₀·e^(2n) the specified restitution implies. Middle: measured restitution per bounce against the specified one (dashed). Right: deepest penetration per contact.".into());
    } else {
        notes.push("Collision validation: this scene has no obstacles.".to_string());
    }
    if let Some(s) = &r.sweep {
        notes.push(format!("Sweep reference: {}.", s.reference));
    }
    notes.push("Wall times are measured, so they vary from run to run; every other number is reproducible bit for bit.".into());
    write_atomic(
        dir.join("index.html"),
        scene_page(&sum, &figs, &notes).as_bytes(),
    )?;
    write_atomic(
        dir.join("results.json"),
        serde_json::to_string_pretty(&sum)
            .map_err(|e| Error::Write {
                file: dir.join("results.json"),
                source: std::io::Error::other(e),
            })?
            .as_bytes(),
    )?;
    Ok(sum)
}

/// Collects and writes one scene.
pub fn report_scene(scene: &Scenario, opts: &ReportOptions) -> Result<SceneSummary> {
    let (dt, steps) = scene_plan(scene, opts.quick)?;
    let r = collect_scene(scene, dt, steps, &CollectOptions { quick: opts.quick })?;
    write_scene(&r, opts)
}

/// Writes `index.html`, `README.md` and `summary.json` (last, after every scene page).
pub fn write_overview(sum: &Summary, out: &Path) -> Result<()> {
    write_atomic(out.join("index.html"), index_page(sum).as_bytes())?;
    write_atomic(
        out.join("README.md"),
        super::markdown::readme(sum).as_bytes(),
    )?;
    let json = serde_json::to_string_pretty(sum).map_err(|e| Error::Write {
        file: out.join("summary.json"),
        source: std::io::Error::other(e),
    })?;
    write_atomic(out.join("summary.json"), json.as_bytes())?;
    Ok(())
}
