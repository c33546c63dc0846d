//! Work-precision: error against modelled time ([`crate::run::cost`]) and against force
//! evaluations, log-log.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::report::data::{Series, WorkPrecisionData};

/// SVG with two panels: error against modelled time, and error against force evaluations.
pub fn work_precision(data: &WorkPrecisionData) -> Result<String> {
    let by = |f: &dyn Fn(&crate::report::data::WorkPoint) -> f64| -> Vec<Series> {
        data.lines
            .iter()
            .map(|l| {
                Series::new(
                    l.label.clone(),
                    l.points.iter().map(|p| [f(p), p.error]).collect(),
                )
            })
            .collect()
    };
    let modelled = by(&|p| p.modelled_seconds);
    let evals = by(&|p| p.force_evals as f64);
    let panels = [
        Panel {
            title: "Error against modelled time".into(),
            x: Axis::log("modelled time (s): counted work, priced"),
            y: Axis::log("RMS position error at the end (m)"),
            series: &modelled,
            guides: &[],
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerRight,
        },
        Panel {
            title: "Error against force evaluations".into(),
            x: Axis::log("force evaluations (count)"),
            y: Axis::log("RMS position error at the end (m)"),
            series: &evals,
            guides: &[],
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerRight,
        },
    ];
    svg_grid((1500, 560), 2, &panels)
}
