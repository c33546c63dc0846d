//! Energy over time per method: the total account, and the individual terms on demand.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

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

/// Energy over time per method: the total account, and optionally the terms of one method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyData {
    /// Total energy account (J) against time (s), one series per method.
    pub totals: Vec<Series>,
    /// Individual terms (kinetic, gravity, elastic, dissipated, …) when asked for.
    pub terms: Vec<Series>,
}

impl ChartCsv for EnergyData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        let rows = self
            .totals
            .iter()
            .flat_map(|s| series_rows("total", s))
            .chain(self.terms.iter().flat_map(|s| series_rows("term", s)));
        csv_bytes(&SERIES_HEADER, rows)
    }
}

/// Energy over time: totals per method, and (when `terms`) the terms of the first method.
pub fn from_study(s: &SceneStudy, terms: bool) -> EnergyData {
    let totals = runs(s)
        .map(|run| time_series(run, |se, k| se.energy[k].total))
        .collect();
    let mut term_series = Vec::new();
    if let Some(run) = runs(s).next().filter(|_| terms) {
        type Term = fn(&crate::run::EnergyRecord) -> f64;
        let all: [(&str, Term); 5] = [
            ("kinetic", |e| e.kinetic),
            ("gravity", |e| e.gravity),
            ("elastic", |e| e.elastic),
            ("dissipated", |e| e.dissipated),
            ("injected", |e| e.injected),
        ];
        for (name, f) in all {
            if run
                .series
                .as_ref()
                .is_some_and(|se| se.energy.iter().any(|e| f(e) != 0.0))
            {
                let mut t = time_series(run, |se, k| f(&se.energy[k]));
                t.label = format!("{name} ({})", run.method);
                term_series.push(t);
            }
        }
    }
    EnergyData {
        totals,
        terms: term_series,
    }
}

impl Chart for EnergyData {
    fn stem(&self) -> &'static str {
        "energy"
    }
    fn svg(&self) -> Result<String> {
        energy(self)
    }
}

impl PageChart for EnergyData {
    fn title(&self) -> &'static str {
        "Energy over time"
    }
    fn caption(&self) -> String {
        format!("The total energy account per method; flat is right. A run that blew up stops at its × marker. {}", link("compare/summary.json"))
    }
}
