//! Chain and cloth snapshots side by side, one panel per method, at the same scale.

use super::common::{tick, FONT};
use crate::error::{Error, Result};
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{Chart, PageChart};
use crate::report::finite::plottable;
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use std::ops::Range;

fn draw_err<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> Error {
    Error::Write {
        file: "<svg>".into(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// A snapshot's time and its polylines, ready to draw.
type TimedLines = (f64, Vec<Vec<(f64, f64)>>);

/// Shade for the k-th of `n` snapshots: light (early) to dark (late).
fn shade(k: usize, n: usize) -> RGBColor {
    let f = if n > 1 {
        k as f64 / (n - 1) as f64
    } else {
        1.0
    };
    let lerp = |a: f64, b: f64| (a + (b - a) * f) as u8;
    RGBColor(lerp(150.0, 8.0), lerp(190.0, 48.0), lerp(240.0, 107.0))
}

/// SVG with one panel per method showing the chain or cloth at a few instants.
pub fn snapshots(data: &SnapshotData) -> Result<String> {
    let panels = gated(data);
    let (xr, yr) = shared_square(&panels);
    let cols = panels.len().clamp(1, 4);
    let rows = panels.len().div_ceil(cols).max(1);
    let size = (380 * cols as u32, 400 * rows as u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let areas = root.split_evenly((rows, cols));
        for ((p, lines), area) in data.panels.iter().zip(&panels).zip(areas.iter()) {
            let frame = Frame {
                axes: &data.axes,
                xr: xr.clone(),
                yr: yr.clone(),
            };
            draw_panel(area, p, lines, frame)?;
        }
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Every panel's polylines through the finite gate, per snapshot with its time.
fn gated(data: &SnapshotData) -> Vec<Vec<TimedLines>> {
    data.panels
        .iter()
        .map(|p| {
            p.snapshots
                .iter()
                .map(|s| {
                    (
                        s.t,
                        s.lines.iter().map(|l| plottable(l, false, false)).collect(),
                    )
                })
                .collect()
        })
        .collect()
}

/// One square x and y range around every point of every panel, with a margin, so panels
/// compare directly; the unit square when there is no point.
fn shared_square(panels: &[Vec<TimedLines>]) -> (Range<f64>, Range<f64>) {
    let all = panels
        .iter()
        .flatten()
        .flat_map(|(_, ls)| ls.iter().flatten());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !(x0.is_finite() && y0.is_finite()) {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let span = (x1 - x0).max(y1 - y0).max(1e-9) * 1.08;
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    (
        cx - span / 2.0..cx + span / 2.0,
        cy - span / 2.0..cy + span / 2.0,
    )
}

/// The frame every panel shares: the names of the plane's axes and their ranges (m).
struct Frame<'a> {
    axes: &'a [String; 2],
    xr: Range<f64>,
    yr: Range<f64>,
}

/// Draws panel `p`'s snapshots `lines` into `area` in the shared `frame`, light (early) to
/// dark (late), with a legend of their times.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &SnapshotPanel,
    lines: &[TimedLines],
    frame: Frame<'_>,
) -> Result<()> {
    let title = match p.blowup_time {
        Some(t) => format!("{} (blew up at t = {} s)", p.label, tick(t)),
        None => p.label.clone(),
    };
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 15))
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(frame.xr, frame.yr)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc(format!("{} (m)", frame.axes[0]))
        .y_desc(format!("{} (m)", frame.axes[1]))
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .x_labels(5)
        .y_labels(5)
        .light_line_style(RGBColor(240, 240, 240))
        .draw()
        .map_err(draw_err)?;
    let n = lines.len();
    for (k, (t, ls)) in lines.iter().enumerate() {
        let c = shade(k, n);
        let mut first = true;
        for l in ls {
            let a = chart
                .draw_series(LineSeries::new(l.iter().copied(), c.stroke_width(1)))
                .map_err(draw_err)?;
            if first {
                a.label(format!("t = {} s", tick(*t)))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(3))
                    });
                first = false;
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(150, 150, 150))
        .label_font((FONT, 11))
        .draw()
        .map_err(draw_err)?;
    Ok(())
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

/// Polylines of a chain or cloth block (cloth rows and columns, at most 9 of each).
fn block_lines(
    block: &crate::scenario::Block,
    x: &[[f64; 3]],
    plane: [usize; 2],
) -> Vec<Vec<[f64; 2]>> {
    let [nx, ny] = block.shape;
    let at = |ix: usize, iy: usize| {
        let p = x[block.first + iy * nx + ix];
        [p[plane[0]], p[plane[1]]]
    };
    let pick = |n: usize| -> Vec<usize> {
        let step = n.div_ceil(8).max(1);
        let mut v: Vec<usize> = (0..n).step_by(step).collect();
        if v.last() != Some(&(n - 1)) {
            v.push(n - 1);
        }
        v
    };
    let mut lines = Vec::new();
    for iy in pick(ny) {
        lines.push((0..nx).map(|ix| at(ix, iy)).collect());
    }
    if ny > 1 {
        for ix in pick(nx) {
            lines.push((0..ny).map(|iy| at(ix, iy)).collect());
        }
    }
    lines
}

/// Snapshots of the scene's chains and cloths per method, if it has any.
pub fn from_study(
    s: &SceneStudy,
    blocks: &[crate::scenario::Block],
    plane: [usize; 2],
) -> Option<SnapshotData> {
    if blocks.is_empty() {
        return None;
    }
    let panels = runs(s)
        .map(|run| SnapshotPanel {
            label: run.method.clone(),
            snapshots: run
                .trace
                .iter()
                .flat_map(|tr| tr.snapshots.iter())
                .map(|(t, x)| Snapshot {
                    t: *t,
                    lines: blocks
                        .iter()
                        .flat_map(|b| block_lines(b, x, plane))
                        .collect(),
                })
                .collect(),
            blowup_time: run.unstable_time,
        })
        .collect();
    Some(SnapshotData {
        axes: [AXES[plane[0]].into(), AXES[plane[1]].into()],
        panels,
    })
}

impl Chart for SnapshotData {
    fn stem(&self) -> &'static str {
        "snapshots"
    }
    fn svg(&self) -> Result<String> {
        snapshots(self)
    }
}

impl PageChart for SnapshotData {
    fn title(&self) -> &'static str {
        "Snapshots"
    }
    fn caption(&self) -> String {
        "The chain or cloth at a few instants (light to dark), one panel per method at the same scale.".into()
    }
}
