//! The report's Small Steps page (Macklin et al., SCA 2019, replicated): xpbd's n substeps ×
//! 1 iteration against 1 step × n iterations at 60 Hz on the stiff chain and the cloth, from
//! the very documents `springlab small-steps` writes (`small_steps.json`, `small_steps.csv`).

use super::html::{esc, page};
use super::plots::common::{svg_grid, Axis, Panel};
pub use super::summary::SmallStepsLink;
use crate::error::Result;
use crate::measure::small_steps::{write_small_steps, SmallSteps};
use crate::output::{write_atomic, Transaction};
use crate::report::data::Series;
use std::path::Path;

/// Writes `out/small_steps/` (documents, chart, page) for `doc`, measured on scenes whose
/// inputs are `inputs` ([`super::reuse::small_steps_inputs`]), as one transaction; the page's
/// link for the overview.
pub fn write_page(out: &Path, doc: &SmallSteps, inputs: &str) -> Result<SmallStepsLink> {
    // The page and its documents are replaced together (see [`Transaction`]).
    let mut tx = Transaction::new(out)?;
    let dir = tx.stage_dir("small_steps")?;
    write_small_steps(&dir, doc)?;
    write_atomic(dir.join("small_steps.svg"), chart(doc)?.as_bytes())?;
    write_atomic(dir.join("index.html"), html(doc).as_bytes())?;
    super::reuse::write_inputs(&dir, inputs)?;
    tx.commit()?;
    Ok(SmallStepsLink {
        page: "small_steps/index.html".into(),
        verdicts: doc
            .scenes
            .iter()
            .map(|s| format!("{}: {}", s.scene, s.verdict))
            .collect(),
    })
}

fn chart(doc: &SmallSteps) -> Result<String> {
    type Pick = fn(&crate::measure::small_steps::SplitRun) -> Option<f64>;
    let lines = |s: &crate::measure::small_steps::SceneSmallSteps, pick: Pick| {
        [
            ("n substeps × 1 iteration", true),
            ("1 step × n iterations", false),
        ]
        .into_iter()
        .map(|(label, sub)| {
            let points = s
                .budgets
                .iter()
                .filter_map(|b| {
                    let r = if sub { &b.substeps } else { &b.iterations };
                    pick(r).map(|v| [b.n as f64, v])
                })
                .collect();
            Series::new(label, points)
        })
        .collect::<Vec<_>>()
    };
    let data: Vec<(String, Vec<Series>, Vec<Series>)> = doc
        .scenes
        .iter()
        .map(|s| {
            (
                s.scene.clone(),
                lines(s, |r| r.error_max),
                lines(s, |r| r.stretch_error),
            )
        })
        .collect();
    let panel = |title: String, y: &str, series| Panel {
        title,
        x: Axis::log("constraint sweeps per frame n"),
        y: Axis::log(y),
        series,
        guides: &[],
        dots: true,
        lines: true,
        equal_aspect: false,
        legend: plotters::prelude::SeriesLabelPosition::LowerLeft,
    };
    let panels: Vec<Panel> = data
        .iter()
        .flat_map(|(name, err, stretch)| {
            [
                panel(
                    format!("{name}: position error"),
                    "max position error (m)",
                    err,
                ),
                panel(
                    format!("{name}: stretch error"),
                    "|stretch − reference stretch|",
                    stretch,
                ),
            ]
        })
        .collect();
    svg_grid((1200, 480 * data.len().max(1) as u32), 2, &panels)
}

fn html(doc: &SmallSteps) -> String {
    let mut body = String::from("<p><a href=\"../index.html\">← all scenes</a></p>\n<h1>Small Steps, replicated</h1>\n<p>Macklin et al., “Small Steps in Physics Simulation” (SCA 2019): at equal cost in constraint sweeps, n substeps with one XPBD iteration each should beat one step with n iterations. Measured with <code>xpbd</code> at 60 Hz against each scene's reference, over the frames the reference can vouch for.</p>\n");
    body += &format!(
        "<p class=\"note\">Documents: <a href=\"small_steps.json\">small_steps.json</a>, <a href=\"small_steps.csv\">small_steps.csv</a>; re-create with <code>{}</code>.</p>\n",
        esc(&doc.command)
    );
    body += "<figure><img src=\"small_steps.svg\" alt=\"Small Steps\"><figcaption>Largest position error and stretch error against the sweeps per frame, both splits, log-log.</figcaption></figure>\n";
    let f = |v: Option<f64>| v.map_or("—".to_string(), |x| format!("{x:.3e}"));
    for s in &doc.scenes {
        body += &format!(
            "<h2>{}</h2>\n<p class=\"verdict\">{}</p>\n<p class=\"note\">dt = {:.6} s over {} s, {} frames compared; the reference stretches at most {}.</p>\n<table>\n<tr><th>n</th><th>error, n substeps (m)</th><th>error, n iterations (m)</th><th>stretch error, n substeps</th><th>stretch error, n iterations</th></tr>\n",
            esc(&s.scene),
            esc(&s.verdict),
            s.frame_dt,
            s.duration,
            s.compared_frames,
            crate::error::significant(s.reference_stretch_max, 4)
        );
        for b in &s.budgets {
            body += &format!(
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                b.n,
                f(b.substeps.error_max),
                f(b.iterations.error_max),
                f(b.substeps.stretch_error),
                f(b.iterations.stretch_error),
            );
        }
        body += "</table>\n";
    }
    body += "<p class=\"note\">Wall times are measured and vary from run to run, so they are kept apart, in timing.json; every other number is reproducible from the command above.</p>\n";
    page("springlab: Small Steps", &body)
}

/// The link to a Small Steps page already written under `out` (by shard 0 of a sharded
/// report), read back from its document; `None` when there is none.
pub fn read_link(out: &Path) -> Option<SmallStepsLink> {
    let text = crate::output::read_document(out.join("small_steps/small_steps.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    let verdicts = v["scenes"]
        .as_array()?
        .iter()
        .map(|s| {
            format!(
                "{}: {}",
                s["scene"].as_str().unwrap_or(""),
                s["verdict"].as_str().unwrap_or("")
            )
        })
        .collect();
    Some(SmallStepsLink {
        page: "small_steps/index.html".into(),
        verdicts,
    })
}
