//! Relative energy error on a log scale, one line per method.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::report::data::EnergyErrorData;

/// SVG of |E(t) − E(0)| / E_scale against time (log y).
pub fn energy_error(data: &EnergyErrorData) -> Result<String> {
    svg_single(
        (900, 520),
        &Panel {
            title: "Relative energy error".into(),
            x: Axis::lin("time t (s)"),
            y: Axis::log(format!("|E(t) − E(0)| / {} (1)", data.scale_note)),
            series: &data.series,
            guides: &[],
            dots: false,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        },
    )
}
