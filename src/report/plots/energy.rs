//! Energy over time per method: the total account, and the individual terms on demand.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::report::data::EnergyData;

/// SVG of the total energy account (J) against time (s) for every method; when `data.terms`
/// is not empty a second panel shows them.
pub fn energy(data: &EnergyData) -> Result<String> {
    let mut panels = vec![Panel {
        title: "Total energy account K + G + E + dissipated − injected".into(),
        x: Axis::lin("time t (s)"),
        y: Axis::lin("total energy (J)"),
        series: &data.totals,
        guides: &[],
        dots: false,
        lines: true,
        equal_aspect: false,
        legend: plotters::prelude::SeriesLabelPosition::UpperRight,
    }];
    if !data.terms.is_empty() {
        panels.push(Panel {
            title: "Energy terms".into(),
            x: Axis::lin("time t (s)"),
            y: Axis::lin("energy (J)"),
            series: &data.terms,
            guides: &[],
            dots: false,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        });
    }
    let w = 900 * panels.len() as u32;
    svg_grid((w.min(1600), 500), panels.len(), &panels)
}
