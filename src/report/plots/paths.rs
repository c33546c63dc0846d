//! Trajectories: particle paths projected on the scene's main plane, one line per method.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

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

/// Paths of particles projected on the scene's main plane, one series per method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PathData {
    /// Names of the plane's axes ("x", "y").
    pub axes: [String; 2],
    /// One series per method and tracked particle.
    pub series: Vec<Series>,
}

impl ChartCsv for PathData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        csv_bytes(
            &SERIES_HEADER,
            self.series.iter().flat_map(|s| series_rows("path", s)),
        )
    }
}

/// Paths of the tracked particles in the main plane.
pub fn from_study(s: &SceneStudy, plane: [usize; 2]) -> PathData {
    let [a, b] = plane;
    let mut series = Vec::new();
    for run in runs(s) {
        let Some(tr) = &run.trace else { continue };
        for (k, path) in tr.paths.iter().enumerate() {
            let points: Vec<[f64; 2]> = path
                .iter()
                .filter(|p| p[a].is_finite() && p[b].is_finite())
                .map(|p| [p[a], p[b]])
                .collect();
            let label = if tr.tracked.len() > 1 {
                format!("{} particle {}", run.method, tr.tracked[k])
            } else {
                run.method.clone()
            };
            let mut line = Series::new(label, points);
            line.blowup = match (run.unstable_time, line.points.last()) {
                (Some(_), Some(p)) => Some(BlowUp { x: p[0], y: p[1] }),
                _ => None,
            };
            series.push(line);
        }
    }
    PathData {
        axes: [AXES[a].into(), AXES[b].into()],
        series,
    }
}

impl Chart for PathData {
    fn stem(&self) -> &'static str {
        "paths"
    }
    fn svg(&self) -> Result<String> {
        paths(self)
    }
}

impl PageChart for PathData {
    fn title(&self) -> &'static str {
        "Trajectories"
    }
    fn caption(&self) -> String {
        format!("Paths of the most-travelled free particle(s) in the {}{}-plane (vertical: the axis gravity acts along, if any; else the plane where the motion spreads most). {}", self.axes[0], self.axes[1], link("compare/summary.json"))
    }
}
