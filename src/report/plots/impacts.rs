//! Restitution per impact: measured against expected e over approach speed, and the deviation
//! over impact time, one series per method.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

/// SVG with two panels: e against approach speed (expected dashed), e − expected against time.
pub fn impacts(data: &ImpactData) -> Result<String> {
    let (t0, t1) = data
        .deviation
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p[0]))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
            (a.min(t), b.max(t))
        });
    let zero = if t0.is_finite() {
        vec![Guide {
            label: "measured = expected".into(),
            points: vec![[t0, 0.0], [t1.max(t0 + 1e-9), 0.0]],
        }]
    } else {
        Vec::new()
    };
    let panels = [
        Panel {
            title: "Restitution per impact".into(),
            x: Axis::lin("approach speed |v_in| (m/s)"),
            y: Axis::lin("restitution e (rebound / impact speed)"),
            series: &data.measured,
            guides: &data.expected,
            dots: true,
            lines: false,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerRight,
        },
        Panel {
            title: "Measured − expected e per impact".into(),
            x: Axis::lin("impact time t (s)"),
            y: Axis::lin("e measured − e expected"),
            series: &data.deviation,
            guides: &zero,
            dots: true,
            lines: false,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        },
    ];
    svg_grid((1200, 480), 2, &panels)
}

/// Restitution per impact: measured against the expected e over approach speed, and the
/// deviation over impact time (the impacts above each run's summary floor).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactData {
    /// Measured e against approach speed |v_in| (m/s), one series per method.
    pub measured: Vec<Series>,
    /// Expected e against approach speed, one line per obstacle met.
    pub expected: Vec<Guide>,
    /// Measured − expected e against impact time (s), one series per method.
    pub deviation: Vec<Series>,
}

impl ChartCsv for ImpactData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        let guides = self
            .expected
            .iter()
            .map(|g| Series::new(g.label.clone(), g.points.clone()));
        let guides: Vec<Series> = guides.collect();
        let rows = self
            .measured
            .iter()
            .flat_map(|s| series_rows("measured", s))
            .chain(guides.iter().flat_map(|s| series_rows("expected", s)))
            .chain(
                self.deviation
                    .iter()
                    .flat_map(|s| series_rows("deviation", s)),
            );
        csv_bytes(&SERIES_HEADER, rows)
    }
}

/// Most impacts drawn per method (evenly strided in time order beyond that).
pub const MAX_IMPACT_POINTS: usize = 300;

/// Measured against expected restitution per impact (the impacts each run's contact summary
/// covers: approaching faster than its floor), for scenes with obstacles and impacts.
pub fn from_study(s: &SceneStudy) -> Option<ImpactData> {
    let mut measured = Vec::new();
    let mut deviation = Vec::new();
    // (obstacle, speed, expected) of every impact drawn, for the expected lines.
    let mut expected: Vec<(usize, f64, f64)> = Vec::new();
    for run in runs(s) {
        let Some(c) = &run.contacts else { continue };
        let list: Vec<_> = c
            .summary_impacts()
            .filter(|(e, m)| m.is_finite() && e.expected_restitution.is_finite())
            .collect();
        if list.is_empty() {
            continue;
        }
        let stride = list.len().div_ceil(MAX_IMPACT_POINTS).max(1);
        let drawn: Vec<_> = list.into_iter().step_by(stride).collect();
        let mut by_speed: Vec<[f64; 2]> = drawn.iter().map(|(e, m)| [e.v_in.abs(), *m]).collect();
        by_speed.sort_by(|a, b| a[0].total_cmp(&b[0]));
        measured.push(Series::new(run.method.clone(), by_speed));
        deviation.push(Series::new(
            run.method.clone(),
            drawn
                .iter()
                .map(|(e, m)| [e.t_in, m - e.expected_restitution])
                .collect(),
        ));
        expected.extend(
            drawn
                .iter()
                .map(|(e, _)| (e.obstacle, e.v_in.abs(), e.expected_restitution)),
        );
    }
    if measured.is_empty() {
        return None;
    }
    expected.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut lines: Vec<Guide> = Vec::new();
    for (k, v, e) in expected {
        let label = format!("expected e, obstacle {k}");
        match lines.last_mut() {
            Some(g) if g.label == label => g.points.push([v, e]),
            _ => lines.push(Guide {
                label,
                points: vec![[v, e]],
            }),
        }
    }
    for g in &mut lines {
        // A guide needs two points: widen a single impact speed into a short flat line.
        if g.points.len() == 1 {
            let [v, e] = g.points[0];
            g.points = vec![[0.95 * v, e], [1.05 * v, e]];
        }
    }
    Some(ImpactData {
        measured,
        expected: lines,
        deviation,
    })
}

impl Chart for ImpactData {
    fn stem(&self) -> &'static str {
        "impacts"
    }
    fn svg(&self) -> Result<String> {
        impacts(self)
    }
}

impl PageChart for ImpactData {
    fn title(&self) -> &'static str {
        "Restitution per impact"
    }
    fn caption(&self) -> String {
        format!("Left: measured restitution e = v_out/|v_in| of every impact faster than the run's summary floor, against its approach speed, with the expected e (dashed: the obstacle's; for penalty contacts the contact equation's with gravity, which varies with speed). Right: measured − expected per impact over time. At most {} impacts per method. {}", MAX_IMPACT_POINTS, link("compare/contacts.json"))
    }
}
