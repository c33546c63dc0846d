//! Trajectories: particle paths projected on the scene's main plane, one line per method.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::report::data::PathData;

/// SVG of the tracked particles' paths in the plane (equal scales on both axes).
pub fn paths(data: &PathData) -> Result<String> {
    svg_single(
        (900, 700),
        &Panel {
            title: "Particle paths in the scene's main plane".into(),
            x: Axis::lin(format!("{} (m)", data.axes[0])),
            y: Axis::lin(format!("{} (m)", data.axes[1])),
            series: &data.series,
            guides: &[],
            dots: false,
            lines: true,
            equal_aspect: true,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        },
    )
}
