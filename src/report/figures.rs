//! The scene page's charts: each written as SVG beside the CSV behind it, with its figure
//! (title and caption) in page order, and a note for each chart the scene has nothing to draw in.

use super::charts;
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

/// Writes a chart as `<stem>.csv` and `<stem>.svg` in `dir`.
fn write_chart(dir: &Path, stem: &str, svg: Result<String>, data: &dyn ChartCsv) -> Result<()> {
    write_atomic(dir.join(format!("{stem}.csv")), &data.to_csv()?)?;
    write_atomic(dir.join(format!("{stem}.svg")), svg?.as_bytes())?;
    Ok(())
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
    let link = |k: &str| format!("Document: <code>{k}</code>.");
    let mut figures = Vec::new();
    let mut notes = Vec::new();
    let mut fig = |stem: &str, title: &str, caption: String| {
        figures.push(Figure {
            stem: stem.into(),
            title: title.into(),
            caption,
        })
    };
    let e = charts::energy(s, energy_terms);
    write_chart(dir, "energy", plots::energy(&e), &e)?;
    fig("energy", "Energy over time", format!("The total energy account per method; flat is right. A run that blew up stops at its × marker. {}", link("compare/summary.json")));
    let ee = charts::energy_error(s);
    write_chart(dir, "energy_error", plots::energy_error(&ee), &ee)?;
    fig(
        "energy_error",
        "Relative energy error",
        format!(
            "|E(t) − E(0)| relative to {}, log scale. {}",
            ee.scale_note,
            link("compare/summary.json")
        ),
    );
    let pe = charts::position_error(s);
    write_chart(dir, "position_error", plots::position_error(&pe), &pe)?;
    fig(
        "position_error",
        "Position error against the reference",
        format!(
            "Largest distance of any particle from the reference ({}), log scale. {}",
            pe.reference,
            link("compare/summary.json")
        ),
    );
    if let Some(c) = charts::convergence(s) {
        write_chart(dir, "convergence", plots::convergence(&c), &c)?;
        fig("convergence", "Convergence", format!("Largest position error against the step, log-log, against the reference ({}); the legend gives each method's observed order as the sweep fitted it on its asymptotic range (none when that range was not reached), dashed lines are reference slopes. Blow-ups are marked at the coarsest unstable step. {}", c.reference, link("sweep/summary.json, sweep/sweep.csv")));
    }
    if let Some(w) = charts::work_precision(s) {
        write_chart(dir, "work_precision", plots::work_precision(&w), &w)?;
        fig("work_precision", "Work against precision", format!("The same sweep as cost: lower-left is better. Each engine (Rapier, not swept) is one point: its comparison run at the scene's step, same duration and error. Modelled time is the runs' counted work priced per item, the same on every run (the measured wall times are in timing.json); force evaluations count one kind of that work (an engine has none, so it is absent from that panel). {}", link("sweep/sweep.csv")));
    } else if s.sweep.is_some() {
        notes.push("Work against precision: no run of the step-size sweep stayed stable, so there is nothing to plot.".to_string());
    }
    let p = charts::paths(s, plane);
    write_chart(dir, "paths", plots::paths(&p), &p)?;
    fig("paths", "Trajectories", format!("Paths of the most-travelled free particle(s) in the {}{}-plane (vertical: the axis gravity acts along, if any; else the plane where the motion spreads most). {}", p.axes[0], p.axes[1], link("compare/summary.json")));
    if let Some(sn) = charts::snapshots(s, &scene.blocks, plane) {
        write_chart(dir, "snapshots", plots::snapshots(&sn), &sn)?;
        fig("snapshots", "Snapshots", "The chain or cloth at a few instants (light to dark), one panel per method at the same scale.".into());
    }
    if let Some(c) = charts::collision(s) {
        write_chart(dir, "collision", plots::collision(&c), &c)?;
        fig("collision", "Collision", format!("Left: the gap between the first tracked particle and the obstacle (negative: penetration), with the apex heights h₀·e^(2n) the specified restitution implies. Middle: measured restitution per bounce against the specified one (dashed). Right: deepest penetration per contact. {}", link("compare/contacts.json")));
        if let Some(i) = charts::impacts(s) {
            write_chart(dir, "impacts", plots::impacts(&i), &i)?;
            fig("impacts", "Restitution per impact", format!("Left: measured restitution e = v_out/|v_in| of every impact faster than the run's summary floor, against its approach speed, with the expected e (dashed: the obstacle's; for penalty contacts the contact equation's with gravity, which varies with speed). Right: measured − expected per impact over time. At most {} impacts per method. {}", charts::MAX_IMPACT_POINTS, link("compare/contacts.json")));
        }
    } else {
        notes.push("Collision validation: this scene has no obstacles.".to_string());
    }
    Ok(Figures { figures, notes })
}
