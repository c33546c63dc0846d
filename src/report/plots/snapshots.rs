//! Chain and cloth snapshots side by side, one panel per method, at the same scale.

use super::common::{tick, FONT};
use crate::error::{Error, Result};
use crate::report::data::{SnapshotData, SnapshotPanel};
use crate::report::finite::plottable;
use plotters::coord::Shift;
use plotters::prelude::*;
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
