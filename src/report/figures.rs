//! The scene page's charts: each written as SVG beside the CSV behind it, with its figure
//! (title and caption) in page order, and a note for each chart the scene has nothing to draw in.

use super::data::ChartCsv;
use super::html::Figure;
use super::plots;
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::output::write_atomic;
use crate::scenario::Scenario;
use std::path::Path;

/// A scene page's charts as written: what the page shows of them and what it says instead.
pub(super) struct Figures {
    /// The figures, in page order.
    pub figures: Vec<Figure>,
    /// One note per chart the scene has nothing to draw in, in page order.
    pub notes: Vec<String>,
}

/// One chart of a scene: the data behind it (its CSV) and its drawing (SVG), both written by
/// [`write_chart`].
pub(super) trait Chart: ChartCsv {
    /// File stem: `<stem>.svg` beside `<stem>.csv`.
    fn stem(&self) -> &'static str;
    /// The drawing.
    fn svg(&self) -> Result<String>;
}

/// A chart among the page's figures: with its heading and caption.
pub(super) trait PageChart: Chart {
    /// The figure's heading.
    fn title(&self) -> &'static str;
    /// What the chart shows and how to read it.
    fn caption(&self) -> String;
}

/// Writes a chart as `<stem>.csv` and `<stem>.svg` in `dir`.
pub(super) fn write_chart<C: Chart + ?Sized>(dir: &Path, chart: &C) -> Result<()> {
    write_atomic(dir.join(format!("{}.csv", chart.stem())), &chart.to_csv()?)?;
    write_atomic(
        dir.join(format!("{}.svg", chart.stem())),
        chart.svg()?.as_bytes(),
    )?;
    Ok(())
}

/// The document a chart's caption names.
pub(super) fn link(k: &str) -> String {
    format!("Document: <code>{k}</code>.")
}

/// Writes a scene's charts into `dir` (trajectories and snapshots drawn in the motion's
/// `plane`) and returns their figures, in page order, with the notes for charts left out.
pub(super) fn write_figures(
    dir: &Path,
    scene: &Scenario,
    s: &SceneStudy,
    energy_terms: bool,
    plane: [usize; 2],
) -> Result<Figures> {
    let (list, notes) = plots::page_charts(&plots::Page {
        scene,
        study: s,
        energy_terms,
        plane,
    });
    let mut figures = Vec::new();
    for chart in &list {
        write_chart(dir, chart.as_ref())?;
        figures.push(Figure {
            stem: chart.stem().into(),
            title: chart.title().into(),
            caption: chart.caption(),
        });
    }
    Ok(Figures { figures, notes })
}
