//! Plain chart data: what each plot draws, independent of how the numbers were computed.
//!
//! Every chart function in [`super::plots`] takes one of these structs; each struct can write
//! itself as CSV (the data behind the plot, saved next to the SVG with the same stem).

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

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

/// Energy over time per method: the total account, and optionally the terms of one method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyData {
    /// Total energy account (J) against time (s), one series per method.
    pub totals: Vec<Series>,
    /// Individual terms (kinetic, gravity, elastic, dissipated, …) when asked for.
    pub terms: Vec<Series>,
}

/// Relative energy error |E(t) − E(0)| / E_scale against time, one series per method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyErrorData {
    /// One series per method.
    pub series: Vec<Series>,
    /// What the error is relative to, in words (goes into the axis label).
    pub scale_note: String,
}

/// RMS position error against the reference over time, one series per method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PositionErrorData {
    /// One series per method (m against s).
    pub series: Vec<Series>,
    /// The reference, in words ("analytic", "rk4 at dt/16 (stand-in)").
    pub reference: String,
}

/// One method's convergence line: error against dt with its fitted slope.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergenceLine {
    /// The points (dt in s, error in m); blow-ups are marked.
    pub series: Series,
    /// Least-squares slope of log(error) on log(dt) over the fitted points.
    pub fitted_slope: Option<f64>,
    /// The method's theoretical order.
    pub order: u32,
    /// Why there is no fitted slope (the sweep's reason), when there is none.
    pub note: Option<String>,
}

/// Error against dt, log-log, one line per method, with reference slopes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergenceData {
    /// One line per method.
    pub lines: Vec<ConvergenceLine>,
    /// Reference slopes (dt¹, dt², dt⁴ …) drawn dashed.
    pub guides: Vec<Guide>,
    /// The reference, in words.
    pub reference: String,
}

/// One run of a work-precision sweep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WorkPoint {
    /// Step size (s).
    pub dt: f64,
    /// Error against the reference (m).
    pub error: f64,
    /// Modelled seconds of the run ([`crate::run::cost`]).
    pub modelled_seconds: f64,
    /// Force evaluations.
    pub force_evals: u64,
}

/// One method's work-precision points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkLine {
    /// Method name.
    pub label: String,
    /// Stable runs only, coarsest dt first.
    pub points: Vec<WorkPoint>,
}

/// Error against modelled time and against force evaluations (log-log), the speed–accuracy
/// trade.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkPrecisionData {
    /// One line per method.
    pub lines: Vec<WorkLine>,
}

/// One bounce of a collision test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bounce {
    /// Bounce number (1 = first contact).
    pub n: u32,
    /// Measured restitution (rebound speed / impact speed).
    pub measured: f64,
    /// Restitution the scene specifies.
    pub specified: f64,
    /// Deepest penetration during the contact (m).
    pub penetration: f64,
}

/// Height over time with the e^(2n) envelope, restitution per bounce, penetration per contact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CollisionData {
    /// Height (m) against time (s), one series per method.
    pub heights: Vec<Series>,
    /// Apex heights h₀·e^(2n) the specified restitution implies, as a step line.
    pub envelope: Series,
    /// Bounces per method: (method, bounces).
    pub bounces: Vec<(String, Vec<Bounce>)>,
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

/// Paths of particles projected on the scene's main plane, one series per method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PathData {
    /// Names of the plane's axes ("x", "y").
    pub axes: [String; 2],
    /// One series per method and tracked particle.
    pub series: Vec<Series>,
}

/// One snapshot of a chain or cloth: polylines (chain, cloth rows and columns) in the plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Time (s).
    pub t: f64,
    /// Polylines of projected positions.
    pub lines: Vec<Vec<[f64; 2]>>,
}

/// One method's snapshots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SnapshotPanel {
    /// Method name.
    pub label: String,
    /// Snapshots in time order.
    pub snapshots: Vec<Snapshot>,
    /// Blow-up time, if the run blew up before the last snapshot.
    pub blowup_time: Option<f64>,
}

/// Chain and cloth snapshots side by side per method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SnapshotData {
    /// Names of the plane's axes.
    pub axes: [String; 2],
    /// One panel per method.
    pub panels: Vec<SnapshotPanel>,
}

/// Writes rows to CSV bytes (header first).
fn csv_bytes(header: &[&str], rows: impl IntoIterator<Item = Vec<String>>) -> Result<Vec<u8>> {
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

fn series_rows<'a>(group: &'a str, s: &'a Series) -> impl Iterator<Item = Vec<String>> + 'a {
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
fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.9e}")
    } else {
        String::new()
    }
}

const SERIES_HEADER: [&str; 5] = ["group", "series", "x", "y", "kind"];

/// The data behind a chart as CSV.
pub trait ChartCsv {
    /// CSV bytes with a header row.
    fn to_csv(&self) -> Result<Vec<u8>>;
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

impl ChartCsv for PathData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        csv_bytes(
            &SERIES_HEADER,
            self.series.iter().flat_map(|s| series_rows("path", s)),
        )
    }
}

impl ChartCsv for ConvergenceData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        let rows = self.lines.iter().flat_map(|l| {
            let slope = l.fitted_slope.map(num).unwrap_or_default();
            let order = l.order.to_string();
            series_rows("convergence", &l.series).map(move |mut r| {
                r.push(order.clone());
                r.push(slope.clone());
                r
            })
        });
        let guides = self.guides.iter().flat_map(|g| {
            g.points.iter().map(move |p| {
                vec![
                    "guide".into(),
                    g.label.clone(),
                    num(p[0]),
                    num(p[1]),
                    "guide".into(),
                    String::new(),
                    String::new(),
                ]
            })
        });
        csv_bytes(
            &[
                "group",
                "series",
                "dt",
                "error",
                "kind",
                "order",
                "fitted_slope",
            ],
            rows.chain(guides),
        )
    }
}

impl ChartCsv for WorkPrecisionData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        let rows = self.lines.iter().flat_map(|l| {
            l.points.iter().map(move |p| {
                vec![
                    l.label.clone(),
                    num(p.dt),
                    num(p.error),
                    num(p.modelled_seconds),
                    p.force_evals.to_string(),
                ]
            })
        });
        csv_bytes(
            &["method", "dt", "error", "modelled_seconds", "force_evals"],
            rows,
        )
    }
}

impl ChartCsv for CollisionData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        let mut rows: Vec<Vec<String>> = Vec::new();
        for s in &self.heights {
            for r in series_rows("height", s) {
                rows.push(r);
            }
        }
        rows.extend(series_rows("envelope", &self.envelope));
        for (method, bs) in &self.bounces {
            for b in bs {
                rows.push(vec![
                    "bounce".into(),
                    method.clone(),
                    b.n.to_string(),
                    num(b.measured),
                    format!(
                        "specified={};penetration={}",
                        num(b.specified),
                        num(b.penetration)
                    ),
                ]);
            }
        }
        csv_bytes(&SERIES_HEADER, rows)
    }
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

impl ChartCsv for SnapshotData {
    fn to_csv(&self) -> Result<Vec<u8>> {
        let mut rows = Vec::new();
        for p in &self.panels {
            for s in &p.snapshots {
                for (li, line) in s.lines.iter().enumerate() {
                    for (k, q) in line.iter().enumerate() {
                        rows.push(vec![
                            p.label.clone(),
                            num(s.t),
                            li.to_string(),
                            k.to_string(),
                            num(q[0]),
                            num(q[1]),
                        ]);
                    }
                }
            }
        }
        csv_bytes(&["method", "t", "line", "index", "u", "v"], rows)
    }
}
