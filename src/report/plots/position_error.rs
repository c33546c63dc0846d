//! Position error against the reference over time (log), one line per method.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::report::data::PositionErrorData;

/// SVG of the largest position error of any particle (m) against time (log y).
pub fn position_error(data: &PositionErrorData) -> Result<String> {
    svg_single(
        (900, 520),
        &Panel {
            title: "Position error against the reference".into(),
            x: Axis::lin("time t (s)"),
            y: Axis::log("max position error (m)"),
            series: &data.series,
            guides: &[],
            dots: false,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        },
    )
}
