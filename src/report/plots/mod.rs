//! The scene page's charts, one module each: its data and CSV, how the data is drawn from a
//! scene's study (`from_study`), its drawing as an SVG document (plotters' SVG backend: text as
//! `<text>` elements, no font files), its heading and caption; and `page_charts`, the page's
//! list of them in order. A chart is one module here and one entry in that list.

pub mod collision;
pub mod common;
pub mod convergence;
pub mod energy;
pub mod energy_error;
pub mod impacts;
pub mod paths;
pub mod position_error;
pub mod snapshots;
pub mod work_precision;

pub use collision::collision;
pub use convergence::convergence;
pub use energy::energy;
pub use energy_error::energy_error;
pub use impacts::impacts;
pub use paths::paths;
pub use position_error::position_error;
pub use snapshots::snapshots;
pub use work_precision::work_precision;

use super::figures::PageChart;
use crate::measure::study::SceneStudy;
use crate::scenario::Scenario;

/// What a scene page's charts are drawn from.
pub(in crate::report) struct Page<'a> {
    /// The scene.
    pub scene: &'a Scenario,
    /// Its study.
    pub study: &'a SceneStudy,
    /// Draw the energy terms of one method beside the totals.
    pub energy_terms: bool,
    /// The plane trajectories and snapshots are drawn in.
    pub plane: [usize; 2],
}

/// The page's charts in page order, and a note for each chart the scene has nothing to draw
/// in.
pub(in crate::report) fn page_charts(p: &Page<'_>) -> (Vec<Box<dyn PageChart>>, Vec<String>) {
    let s = p.study;
    let mut list: Vec<Box<dyn PageChart>> = vec![
        Box::new(energy::from_study(s, p.energy_terms)),
        Box::new(energy_error::from_study(s)),
        Box::new(position_error::from_study(s)),
    ];
    let mut notes = Vec::new();
    if let Some(c) = convergence::from_study(s) {
        list.push(Box::new(c));
    }
    if let Some(w) = work_precision::from_study(s) {
        list.push(Box::new(w));
    } else if s.sweep.is_some() {
        notes.push("Work against precision: no run of the step-size sweep stayed stable, so there is nothing to plot.".to_string());
    }
    list.push(Box::new(paths::from_study(s, p.plane)));
    if let Some(sn) = snapshots::from_study(s, &p.scene.blocks, p.plane) {
        list.push(Box::new(sn));
    }
    if let Some(c) = collision::from_study(s) {
        list.push(Box::new(c));
        if let Some(i) = impacts::from_study(s) {
            list.push(Box::new(i));
        }
    } else {
        notes.push("Collision validation: this scene has no obstacles.".to_string());
    }
    (list, notes)
}
