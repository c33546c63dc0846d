//! The pieces every chart's plain data is made of (series, guides, blow-up markers) and the
//! CSV it writes of itself ([`ChartCsv`], saved next to the SVG with the same stem). Each
//! chart's own data struct lives with its drawing in [`super::plots`] and is re-exported here.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

pub use super::plots::collision::{Bounce, CollisionData};
pub use super::plots::convergence::{ConvergenceData, ConvergenceLine};
/// Each chart's data, declared beside its drawing in [`super::plots`].
pub use super::plots::energy::EnergyData;
pub use super::plots::energy_error::EnergyErrorData;
pub use super::plots::impacts::ImpactData;
pub use super::plots::paths::PathData;
pub use super::plots::position_error::PositionErrorData;
pub use super::plots::snapshots::{Snapshot, SnapshotData, SnapshotPanel};
pub use super::plots::work_precision::{WorkLine, WorkPoint, WorkPrecisionData};

/// Where a run blew up: the last accepted point and the time of the rejected step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BlowUp {
    /// x of the marker (the blow-up time, or the step size in sweeps).
    pub x: f64,
    /// y of the marker (the last finite value of the series).
    pub y: f64,
}

/// How a scatter (a panel without lines) draws a series' points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Marker {
    /// A filled dot (a native method).
    #[default]
    Dot,
    /// A filled triangle (an engine, set apart at a glance).
    Triangle,
    /// An open ring around the point (the answer, drawn over its method's marker).
    Ring,
    /// A filled dot with the series' label written beside it instead of in the legend (a
    /// small chart whose every point is a method).
    TaggedDot,
    /// A filled triangle with its label beside it (an engine on such a chart).
    TaggedTriangle,
}

/// One labelled line of (x, y) points, optionally ending at a blow-up marker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// Legend label (usually the method name).
    pub label: String,
    /// Points in drawing order.
    pub points: Vec<[f64; 2]>,
    /// Where the run blew up, if it did; the line is drawn up to here and marked.
    pub blowup: Option<BlowUp>,
    /// How a scatter draws the points.
    #[serde(default)]
    pub marker: Marker,
}

impl Series {
    /// A series without a blow-up marker.
    pub fn new(label: impl Into<String>, points: Vec<[f64; 2]>) -> Self {
        Series {
            label: label.into(),
            points,
            blowup: None,
            marker: Marker::Dot,
        }
    }
}

/// A straight line on the plot (a reference slope, a theoretical limit) drawn dashed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Guide {
    /// Legend label.
    pub label: String,
    /// Two or more points of the line.
    pub points: Vec<[f64; 2]>,
}

/// Writes rows to CSV bytes (header first).
pub(crate) fn csv_bytes(
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<String>>,
) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| Error::Write {
        file: "<csv>".into(),
        source: std::io::Error::other(e.to_string()),
    };
    w.write_record(header).map_err(err)?;
    for r in rows {
        w.write_record(&r).map_err(err)?;
    }
    w.into_inner().map_err(|e| Error::Write {
        file: "<csv>".into(),
        source: std::io::Error::other(e.to_string()),
    })
}

pub(crate) fn series_rows<'a>(
    group: &'a str,
    s: &'a Series,
) -> impl Iterator<Item = Vec<String>> + 'a {
    let pts = s.points.iter().map(move |p| {
        vec![
            group.to_string(),
            s.label.clone(),
            num(p[0]),
            num(p[1]),
            "point".into(),
        ]
    });
    let mark = s.blowup.iter().map(move |b| {
        vec![
            group.to_string(),
            s.label.clone(),
            num(b.x),
            num(b.y),
            "blowup".into(),
        ]
    });
    pts.chain(mark)
}

/// A CSV cell for a number: shortest round-trip form; non-finite values never appear in chart
/// data (they are filtered at construction), but would be written as empty cells.
pub(crate) fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.9e}")
    } else {
        String::new()
    }
}

pub(crate) const SERIES_HEADER: [&str; 5] = ["group", "series", "x", "y", "kind"];

/// The data behind a chart as CSV.
pub trait ChartCsv {
    /// CSV bytes with a header row.
    fn to_csv(&self) -> Result<Vec<u8>>;
}
