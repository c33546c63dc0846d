//! The scene page's charts: each written as SVG beside the CSV behind it, with its figure
//! (title and caption) in page order, and a note for each chart the scene has nothing to draw in.

use super::charts;
use super::data::{
    ChartCsv, CollisionData, ConvergenceData, EnergyData, EnergyErrorData, ImpactData, PathData,
    PositionErrorData, SnapshotData, WorkPrecisionData,
};
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
trait PageChart: Chart {
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
fn link(k: &str) -> String {
    format!("Document: <code>{k}</code>.")
}

impl Chart for EnergyData {
    fn stem(&self) -> &'static str {
        "energy"
    }
    fn svg(&self) -> Result<String> {
        plots::energy(self)
    }
}

impl PageChart for EnergyData {
    fn title(&self) -> &'static str {
        "Energy over time"
    }
    fn caption(&self) -> String {
        format!("The total energy account per method; flat is right. A run that blew up stops at its × marker. {}", link("compare/summary.json"))
    }
}

impl Chart for EnergyErrorData {
    fn stem(&self) -> &'static str {
        "energy_error"
    }
    fn svg(&self) -> Result<String> {
        plots::energy_error(self)
    }
}

impl PageChart for EnergyErrorData {
    fn title(&self) -> &'static str {
        "Relative energy error"
    }
    fn caption(&self) -> String {
        format!(
            "|E(t) − E(0)| relative to {}, log scale. {}",
            self.scale_note,
            link("compare/summary.json")
        )
    }
}

impl Chart for PositionErrorData {
    fn stem(&self) -> &'static str {
        "position_error"
    }
    fn svg(&self) -> Result<String> {
        plots::position_error(self)
    }
}

impl PageChart for PositionErrorData {
    fn title(&self) -> &'static str {
        "Position error against the reference"
    }
    fn caption(&self) -> String {
        format!(
            "Largest distance of any particle from the reference ({}), log scale. {}",
            self.reference,
            link("compare/summary.json")
        )
    }
}

impl Chart for ConvergenceData {
    fn stem(&self) -> &'static str {
        "convergence"
    }
    fn svg(&self) -> Result<String> {
        plots::convergence(self)
    }
}

impl PageChart for ConvergenceData {
    fn title(&self) -> &'static str {
        "Convergence"
    }
    fn caption(&self) -> String {
        format!("Largest position error against the step, log-log, against the reference ({}); the legend gives each method's observed order as the sweep fitted it on its asymptotic range (none when that range was not reached), dashed lines are reference slopes. Blow-ups are marked at the coarsest unstable step. {}", self.reference, link("sweep/summary.json, sweep/sweep.csv"))
    }
}

impl Chart for WorkPrecisionData {
    fn stem(&self) -> &'static str {
        "work_precision"
    }
    fn svg(&self) -> Result<String> {
        plots::work_precision(self)
    }
}

impl PageChart for WorkPrecisionData {
    fn title(&self) -> &'static str {
        "Work against precision"
    }
    fn caption(&self) -> String {
        format!("The same sweep as cost: lower-left is better. Each engine (Rapier, not swept) is one point: its comparison run at the scene's step, same duration and error. Modelled time is the runs' counted work priced per item, the same on every run (the measured wall times are in timing.json); force evaluations count one kind of that work (an engine has none, so it is absent from that panel). {}", link("sweep/sweep.csv"))
    }
}

impl Chart for PathData {
    fn stem(&self) -> &'static str {
        "paths"
    }
    fn svg(&self) -> Result<String> {
        plots::paths(self)
    }
}

impl PageChart for PathData {
    fn title(&self) -> &'static str {
        "Trajectories"
    }
    fn caption(&self) -> String {
        format!("Paths of the most-travelled free particle(s) in the {}{}-plane (vertical: the axis gravity acts along, if any; else the plane where the motion spreads most). {}", self.axes[0], self.axes[1], link("compare/summary.json"))
    }
}

impl Chart for SnapshotData {
    fn stem(&self) -> &'static str {
        "snapshots"
    }
    fn svg(&self) -> Result<String> {
        plots::snapshots(self)
    }
}

impl PageChart for SnapshotData {
    fn title(&self) -> &'static str {
        "Snapshots"
    }
    fn caption(&self) -> String {
        "The chain or cloth at a few instants (light to dark), one panel per method at the same scale.".into()
    }
}

impl Chart for CollisionData {
    fn stem(&self) -> &'static str {
        "collision"
    }
    fn svg(&self) -> Result<String> {
        plots::collision(self)
    }
}

impl PageChart for CollisionData {
    fn title(&self) -> &'static str {
        "Collision"
    }
    fn caption(&self) -> String {
        format!("Left: the gap between the first tracked particle and the obstacle (negative: penetration), with the apex heights h₀·e^(2n) the specified restitution implies. Middle: measured restitution per bounce against the specified one (dashed). Right: deepest penetration per contact. {}", link("compare/contacts.json"))
    }
}

impl Chart for ImpactData {
    fn stem(&self) -> &'static str {
        "impacts"
    }
    fn svg(&self) -> Result<String> {
        plots::impacts(self)
    }
}

impl PageChart for ImpactData {
    fn title(&self) -> &'static str {
        "Restitution per impact"
    }
    fn caption(&self) -> String {
        format!("Left: measured restitution e = v_out/|v_in| of every impact faster than the run's summary floor, against its approach speed, with the expected e (dashed: the obstacle's; for penalty contacts the contact equation's with gravity, which varies with speed). Right: measured − expected per impact over time. At most {} impacts per method. {}", charts::MAX_IMPACT_POINTS, link("compare/contacts.json"))
    }
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
    let mut list: Vec<Box<dyn PageChart>> = vec![
        Box::new(charts::energy(s, energy_terms)),
        Box::new(charts::energy_error(s)),
        Box::new(charts::position_error(s)),
    ];
    let mut notes = Vec::new();
    if let Some(c) = charts::convergence(s) {
        list.push(Box::new(c));
    }
    if let Some(w) = charts::work_precision(s) {
        list.push(Box::new(w));
    } else if s.sweep.is_some() {
        notes.push("Work against precision: no run of the step-size sweep stayed stable, so there is nothing to plot.".to_string());
    }
    list.push(Box::new(charts::paths(s, plane)));
    if let Some(sn) = charts::snapshots(s, &scene.blocks, plane) {
        list.push(Box::new(sn));
    }
    if let Some(c) = charts::collision(s) {
        list.push(Box::new(c));
        if let Some(i) = charts::impacts(s) {
            list.push(Box::new(i));
        }
    } else {
        notes.push("Collision validation: this scene has no obstacles.".to_string());
    }
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
