//! Stability map: stable and unstable step sizes (h·ω) per integrator, with the textbook
//! boundary of the undamped linear oscillator drawn where it is known.

use super::common::{tick, FONT};
use crate::error::{Error, Result};
use crate::report::data::StabilityData;
use crate::report::finite::plottable;
use plotters::prelude::*;

fn draw_err<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> Error {
    Error::Write {
        file: "<svg>".into(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// SVG of the map: one row per integrator, x = h·ω on a log axis; green cells stayed bounded,
/// red cells blew up; a black bar marks the theoretical limit.
pub fn stability(data: &StabilityData) -> Result<String> {
    let rows = &data.rows;
    let n = rows.len().max(1);
    let names: Vec<String> = rows.iter().map(|r| r.integrator.clone()).collect();
    // Cells as (row, h·ω, stable), through the one finite gate.
    let mut cells: Vec<(usize, f64, f64, bool)> = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let pts: Vec<[f64; 2]> = r
            .cells
            .iter()
            .map(|c| [c.h_omega, if c.stable { 1.0 } else { 0.0 }])
            .collect();
        let ok = plottable(&pts, true, false);
        for (k, &(x, s)) in ok.iter().enumerate() {
            let lo = if k > 0 {
                (ok[k - 1].0 * x).sqrt()
            } else {
                x / (ok.get(1).map_or(2.0, |q| q.0 / x)).sqrt()
            };
            let hi = if k + 1 < ok.len() {
                (ok[k + 1].0 * x).sqrt()
            } else {
                x * (if k > 0 {
                    (x / ok[k - 1].0).sqrt()
                } else {
                    2f64.sqrt()
                })
            };
            cells.push((i, lo, hi, s > 0.5));
        }
    }
    let x0 = cells.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
    let x1 = cells.iter().map(|c| c.2).fold(f64::NEG_INFINITY, f64::max);
    let (x0, x1) = if x0.is_finite() && x1 > x0 {
        (x0, x1)
    } else {
        (0.01, 100.0)
    };
    let height = 140 + 46 * n as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Stability map (ω = {} rad/s: {})",
                    tick(data.omega),
                    data.omega_note
                ),
                (FONT, 16),
            )
            .margin(12)
            .x_label_area_size(46)
            .y_label_area_size(130)
            .build_cartesian_2d((x0..x1).log_scale(), (0..n - 1).into_segmented())
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("dimensionless step h·ω (1)")
            .y_desc("integrator")
            .axis_desc_style((FONT, 14))
            .label_style((FONT, 12))
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) | SegmentValue::Exact(i) => {
                    names.get(*i).cloned().unwrap_or_default()
                }
                SegmentValue::Last => String::new(),
            })
            .y_labels(n)
            .disable_y_mesh()
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(draw_err)?;
        let green = RGBColor(120, 200, 120);
        let red = RGBColor(230, 110, 100);
        chart
            .draw_series(cells.iter().map(|&(i, lo, hi, st)| {
                Rectangle::new(
                    [
                        (lo, SegmentValue::Exact(i)),
                        (hi, SegmentValue::Exact(i + 1)),
                    ],
                    if st { green.filled() } else { red.filled() },
                )
            }))
            .map_err(draw_err)?
            .label("stayed bounded")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], green.filled()));
        chart
            .draw_series(std::iter::empty::<Circle<(f64, SegmentValue<usize>), i32>>())
            .map_err(draw_err)?
            .label("blew up / energy gain grew")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], red.filled()));
        let mut bars = Vec::new();
        let mut notes = Vec::new();
        for (i, r) in rows.iter().enumerate() {
            match r.theory {
                Some(l) if l.is_finite() && l > 0.0 && l > x0 && l < x1 => {
                    bars.push(PathElement::new(
                        vec![(l, SegmentValue::Exact(i)), (l, SegmentValue::Exact(i + 1))],
                        BLACK.stroke_width(4),
                    ))
                }
                Some(l) if l.is_infinite() => notes.push((i, "theory: stable for every h")),
                Some(_) => notes.push((i, "theory: unstable for every h > 0")),
                None => notes.push((i, "theory: no closed-form limit")),
            }
        }
        chart
            .draw_series(bars)
            .map_err(draw_err)?
            .label("textbook limit (undamped oscillator)")
            .legend(|(x, y)| {
                PathElement::new(vec![(x + 8, y - 6), (x + 8, y + 6)], BLACK.stroke_width(4))
            });
        chart
            .draw_series(notes.into_iter().map(|(i, t)| {
                Text::new(
                    t,
                    (x0 * 1.05, SegmentValue::CenterOf(i)),
                    (FONT, 11).into_font(),
                )
            }))
            .map_err(draw_err)?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(150, 150, 150))
            .label_font((FONT, 12))
            .draw()
            .map_err(draw_err)?;
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}
