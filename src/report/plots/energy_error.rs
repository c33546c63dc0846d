//! Relative energy error on a log scale, one line per method.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

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

/// Relative energy error |E(t) − E(0)| / E_scale against time, one series per method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyErrorData {
    /// One series per method.
    pub series: Vec<Series>,
    /// What the error is relative to, in words (goes into the axis label).
    pub scale_note: String,
}

impl ChartCsv for EnergyErrorData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        csv_bytes(
            &SERIES_HEADER,
            self.series
                .iter()
                .flat_map(|s| series_rows("rel_energy_error", s)),
        )
    }
}

/// Relative energy error per method, as compare's metrics define it.
pub fn from_study(s: &SceneStudy) -> EnergyErrorData {
    EnergyErrorData {
        series: runs(s)
            .map(|run| time_series(run, |se, k| se.energy_error[k].abs()))
            .collect(),
        scale_note: "the scene's energy scale (compare's definition)".into(),
    }
}

impl Chart for EnergyErrorData {
    fn stem(&self) -> &'static str {
        "energy_error"
    }
    fn svg(&self) -> Result<String> {
        energy_error(self)
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
