//! Position error against the reference over time (log), one line per method.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

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

/// RMS position error against the reference over time, one series per method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PositionErrorData {
    /// One series per method (m against s).
    pub series: Vec<Series>,
    /// The reference, in words ("analytic", "rk4 at dt/16 (stand-in)").
    pub reference: String,
}

impl ChartCsv for PositionErrorData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        csv_bytes(
            &SERIES_HEADER,
            self.series
                .iter()
                .flat_map(|s| series_rows("position_error", s)),
        )
    }
}

/// Position error per method, leaving out the run of the method that is the reference itself
/// (the closed form's own run: zero error, nothing to plot).
pub fn from_study(s: &SceneStudy) -> PositionErrorData {
    let registry = crate::method::Registry::builtin();
    let closed_form =
        s.compare.reference.kind == crate::measure::reference::ReferenceKind::Analytic;
    PositionErrorData {
        series: runs(s)
            .filter(|run| {
                !(closed_form
                    && registry
                        .info(&run.method)
                        .is_ok_and(|m| m.order == crate::method::Order::Exact))
            })
            .map(|run| time_series(run, |se, k| se.position_error[k]))
            .collect(),
        reference: crate::report::summary::reference_words(s),
    }
}

impl Chart for PositionErrorData {
    fn stem(&self) -> &'static str {
        "position_error"
    }
    fn svg(&self) -> Result<String> {
        position_error(self)
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
