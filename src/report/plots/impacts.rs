//! Restitution per impact: measured against expected e over approach speed, and the deviation
//! over impact time, one series per method.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::report::data::{Guide, ImpactData};

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
