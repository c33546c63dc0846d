//! Convergence: error against dt, log-log, one line per method with its fitted slope in
//! the legend, and reference slopes drawn dashed.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::report::data::{ConvergenceData, Series};

/// SVG of the error at the end of the sweep (m) against the step (s), log-log.
pub fn convergence(data: &ConvergenceData) -> Result<String> {
    let series: Vec<Series> = data
        .lines
        .iter()
        .map(|l| {
            let mut s = l.series.clone();
            s.label = match l.fitted_slope {
                Some(k) => format!("{} (observed order {k:.2}, theory {})", s.label, l.order),
                None => format!("{} (no asymptotic range, theory {})", s.label, l.order),
            };
            s
        })
        .collect();
    svg_single(
        (900, 560),
        &Panel {
            title: "Convergence against the reference".into(),
            x: Axis::log("time step dt (s)"),
            y: Axis::log("max position error over the run (m)"),
            series: &series,
            guides: &data.guides,
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerRight,
        },
    )
}
