//! Writing the report: per scene, a study's documents, written with the commands' own writers
//! and names → charts (SVG + CSV) → page; then the overview, the Markdown README and
//! `summary.json` ([`crate::pipeline`] runs the studies and calls these). Every file is
//! written atomically, scene pages before the overview, so an interrupted run leaves every
//! earlier file whole.

use super::charts;
use super::figures::write_figures;
use super::html::{index_page, scene_page};
use super::summary::{scene_summary, Document, SceneSummary, Summary};
use crate::error::{Error, Result};
use crate::measure::study::SceneStudy;
use crate::method::Registry;
use crate::output::{write_atomic, Transaction};
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
    /// The methods (built-ins unless a library user added theirs).
    pub registry: Registry,
    /// Blow-up factor of every run (see [`crate::run::verdict`]).
    pub blowup_factor: f64,
    /// Study every scene again even where its folder's inputs are unchanged
    /// ([`super::reuse`]).
    pub no_cache: bool,
}

/// The scenario files of a directory (`*.toml`), sorted by name; a path that is not a
/// readable directory is an error naming `--scenarios`, the flag every command that lists
/// scenarios reads it from.
pub fn scenario_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let bad = |why: String| Error::option("--scenarios", format!("{}: {why}", dir.display()));
    if dir.is_file() {
        return Err(bad(
            "is a file; give the folder of scenarios (every *.toml in it is read)".into(),
        ));
    }
    let rd = std::fs::read_dir(dir).map_err(|e| bad(format!("cannot list the folder: {e}")))?;
    let mut files: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    Ok(files)
}

/// Writes a study's documents into sub-folders of `dir` with the commands' writers (same
/// names, same schemas, each with the `"command"` that re-creates it) and lists them with
/// paths relative to `dir`.
pub fn write_documents(dir: &Path, s: &SceneStudy) -> Result<Vec<Document>> {
    use crate::measure::command::with_out;
    let mut docs = Vec::new();
    // Each folder's timing.json is the measurement beside its documents, not a document a
    // command re-creates: it is named on the page, not listed.
    let mut add = |sub: &str, files: Vec<PathBuf>, command: &str| {
        for f in files
            .into_iter()
            .filter(|f| !f.ends_with(crate::output::TIMING_FILE))
        {
            let name = f
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            docs.push(Document {
                file: format!("{sub}/{name}"),
                command: with_out(command, &dir.join(sub)),
            });
        }
    };
    let d = dir.join("compare");
    add(
        "compare",
        crate::measure::compare::write_compare(&d, &s.compare)?,
        &s.compare.command,
    );
    if let Some(sw) = &s.sweep {
        let d = dir.join("sweep");
        let files = crate::measure::sweep::write_sweep(&d, sw)?;
        let command = sw.summary.as_ref().map_or("", |x| x.command.as_str());
        add("sweep", files, command);
    }
    let d = dir.join("stability");
    add(
        "stability",
        vec![crate::measure::stability::write_stability(
            &d,
            &s.stability,
        )?],
        &s.stability.command,
    );
    if let Some(fr) = &s.framerate {
        let d = dir.join("framerate");
        let files = crate::measure::framerate::write_framerate(&d, fr)?;
        add("framerate", files, &fr.head.command);
    }
    if let Some(a) = &s.advice {
        let d = dir.join("advise");
        add(
            "advise",
            crate::measure::advise::write_advice(&d, a)?,
            &a.head.command,
        );
    }
    Ok(docs)
}

/// Writes the frame-rate section's charts into `dir`, each as SVG beside its CSV: error
/// against cost per frame at the game rate, and error and cost against the frame rate.
fn write_framerate_charts(
    dir: &Path,
    s: &SceneStudy,
    fr: &crate::measure::framerate::Framerate,
    registry: &Registry,
) -> Result<()> {
    let game = &s.answer.game_rate;
    let points = crate::measure::engine_fare::game_points(fr, game.hz, registry);
    let game_chart = super::game_rate::GameRateChart { points, game };
    super::figures::write_chart(dir, &game_chart)?;
    super::figures::write_chart(dir, &super::framerate::FramerateChart(fr))?;
    Ok(())
}

/// Writes one scene's documents, charts and page under `out/<scene>/` and returns its summary.
/// The folder is staged and swapped in whole ([`Transaction`]): it never keeps a file of an
/// earlier report that this one did not write, and a scene that fails or is killed while being
/// written leaves its earlier folder as it was.
pub fn write_scene(scene: &Scenario, s: &SceneStudy, opts: &ReportOptions) -> Result<SceneSummary> {
    let mut tx = Transaction::new(&opts.out)?;
    let dir = tx.stage_dir(&s.scenario)?;
    let docs = write_documents(&dir, s)?;
    // The frame-rate section says itself what it left out; the rest are page notes.
    let (framerate_notes, mut notes) = (s.framerate_notes.clone(), s.notes.clone());
    let plane = charts::main_plane(s, scene.raw.world.gravity);
    let figures = write_figures(&dir, scene, s, opts.energy_terms, plane)?;
    notes.extend(figures.notes);
    notes.push("Costs on this page are modelled: each run's counted work (force evaluations, solver iterations, link updates, contact passes; an engine's frames from what it builds) priced per item, the same on every run. Measured wall times vary from run to run, so they are kept apart, in the scene's timing.json (one for all its folders); every other number is reproducible bit for bit from the command beside its document.".into());
    let mut sections = Vec::new();
    sections.extend(super::collision_table::section(s));
    match &s.framerate {
        Some(fr) => {
            write_framerate_charts(&dir, s, fr, &opts.registry)?;
            sections.push(super::framerate::section(
                fr,
                s.framerate_note.as_deref(),
                &framerate_notes,
            ));
        }
        None => {
            notes.push(format!(
                "Frame rates: {}.",
                s.framerate_note.as_deref().unwrap_or("not measured")
            ));
            notes.extend(framerate_notes);
        }
    }
    match super::playback::playback(s, scene, plane) {
        Some((js, html)) => {
            write_atomic(dir.join("playback.js"), js.as_bytes())?;
            sections.push(html);
        }
        None => notes.push(
            "Playback: a scene of one particle has nothing to watch beyond its trajectory above."
                .to_string(),
        ),
    }
    let mut sum = scene_summary(s, &opts.registry, docs)?;
    sum.verdict = super::verdict::verdict(&sum);
    sum.file = super::overview::file_key(&scene.source);
    write_atomic(
        dir.join("index.html"),
        scene_page(&sum, s, &figures.figures, &sections, &notes).as_bytes(),
    )?;
    crate::output::write_document(
        dir.join("results.json"),
        serde_json::to_string_pretty(&sum)
            .map_err(|e| Error::Write {
                file: dir.join("results.json"),
                source: std::io::Error::other(e),
            })?
            .as_bytes(),
    )?;
    // One timing document for the scene: its folders' wall times gathered beside the page.
    crate::output::timing::gather(&dir)?;
    super::reuse::write_inputs(&dir, &super::reuse::scene_inputs(scene, opts))?;
    tx.commit()?;
    Ok(sum)
}

/// Writes `index.html`, `README.md` and `summary.json` (last, after every scene page), as one
/// transaction: the three always come from the same report.
pub fn write_overview(sum: &Summary, out: &Path) -> Result<()> {
    let json = serde_json::to_string_pretty(sum).map_err(|e| Error::Write {
        file: out.join("summary.json"),
        source: std::io::Error::other(e),
    })?;
    let mut tx = Transaction::new(out)?;
    tx.stage_file("index.html", index_page(sum).as_bytes())?;
    tx.stage_file("README.md", super::markdown::readme(sum).as_bytes())?;
    // The scenes' part timings go to the folder's timing.json, beside the summary without them.
    // Staged even when empty, so no earlier timing.json outlives the summary it described.
    let (doc, timing) = crate::output::timing::split("summary.json", json.as_bytes());
    tx.stage_file("summary.json", &doc)?;
    let docs = timing
        .map(|t| ("summary.json".to_string(), t))
        .into_iter()
        .collect();
    tx.stage_file(
        crate::output::TIMING_FILE,
        &crate::output::timing::timing_text(docs),
    )?;
    tx.commit()
}
