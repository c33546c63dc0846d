//! Shared drawing for every chart: axes (linear or log) fitted to the data, lines, dashed
//! guides, blow-up markers, legends, stable colours per method, SVG to a string.
//! Every point passes `report::finite::plottable` here, and only here.

use crate::error::{Error, Result};
use crate::report::data::{Guide, Marker, Series};
use crate::report::finite::{drawable, plottable};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Font family for every label: the viewer's own sans-serif (SVG `<text>`, no font files).
pub const FONT: &str = "sans-serif";

/// One axis: its label with units and whether it is logarithmic.
#[derive(Debug, Clone)]
pub struct Axis {
    /// Label with units, e.g. "time t (s)".
    pub label: String,
    /// Logarithmic scale.
    pub log: bool,
}

impl Axis {
    /// A linear axis.
    pub fn lin(label: impl Into<String>) -> Self {
        Axis {
            label: label.into(),
            log: false,
        }
    }
    /// A logarithmic axis.
    pub fn log(label: impl Into<String>) -> Self {
        Axis {
            label: label.into(),
            log: true,
        }
    }
}

/// What one panel draws.
#[derive(Debug, Clone)]
pub struct Panel<'a> {
    /// Caption above the plot.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Solid lines (with blow-up markers).
    pub series: &'a [Series],
    /// Dashed reference lines.
    pub guides: &'a [Guide],
    /// Draw a dot at every point (sweeps with few points).
    pub dots: bool,
    /// Join the points by lines (false: a scatter of dots, for points that are not a curve).
    pub lines: bool,
    /// Keep x and y at the same scale (trajectories in a plane).
    pub equal_aspect: bool,
    /// Where the legend goes (away from the data).
    pub legend: SeriesLabelPosition,
}

/// A colour per method that stays the same across every chart of the report: the registry's
/// own for a method (no two alike); a label that is no method (the reference, a user's method
/// without one) takes one of three greys, by a hash of its name.
pub fn color_for(label: &str) -> RGBColor {
    const GREYS: [RGBColor; 3] = [
        RGBColor(60, 60, 60),
        RGBColor(110, 110, 110),
        RGBColor(160, 160, 160),
    ];
    let key = label.split_whitespace().next().unwrap_or(label);
    match crate::method::Registry::builtin()
        .find(key)
        .and_then(|m| m.info.colour)
    {
        Some([r, g, b]) => RGBColor(r, g, b),
        None => {
            let h = key
                .bytes()
                .fold(7usize, |h, b| h.wrapping_mul(31) ^ b as usize);
            GREYS[h % GREYS.len()]
        }
    }
}

/// A tick label: plain decimals in [1e-3, 1e4), else compact scientific (`1e-6`, `2.5e7`).
pub fn tick(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&a) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    } else {
        let s = format!("{v:.1e}");
        s.replace(".0e", "e")
    }
}

fn draw_err<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> Error {
    Error::Write {
        file: "<svg>".into(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// The range of `vals` on an axis, padded; logarithmic ranges pad by a factor.
fn range(vals: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals.filter(|&v| drawable(v, log)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let pad = ((h - l) * 0.05).max(0.15);
        (10f64.powf(l - pad), 10f64.powf(h + pad))
    } else {
        let span = hi - lo;
        let pad = if span > 0.0 {
            span * 0.05
        } else {
            lo.abs().max(1.0) * 0.1
        };
        (lo - pad, hi + pad)
    }
}

/// Draws a scatter series' points with its marker ([`Marker`]), labelled in the legend.
fn draw_markers<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    s: &Series,
    sp: &[(f64, f64)],
    c: RGBColor,
) -> Result<()>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let label = s.label.clone();
    // A series without points is a legend entry only (what a shape means): neutral grey.
    let c = if s.points.is_empty() {
        RGBColor(90, 90, 90)
    } else {
        c
    };
    match s.marker {
        Marker::Dot => {
            chart
                .draw_series(sp.iter().map(|&q| Circle::new(q, 4, c.filled())))
                .map_err(draw_err)?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
        }
        Marker::Triangle => {
            chart
                .draw_series(sp.iter().map(|&q| TriangleMarker::new(q, 7, c.filled())))
                .map_err(draw_err)?
                .label(label)
                .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, c.filled()));
        }
        Marker::TaggedDot | Marker::TaggedTriangle => {
            // Labels in dark grey (readable whatever the method's colour), to the left of a
            // point in the right half of the plot so they stay inside it.
            let ink = RGBColor(50, 50, 50);
            let (x_px, _) = chart.plotting_area().get_pixel_range();
            let mid = (x_px.start + x_px.end) / 2;
            for &q in sp {
                let right = chart.backend_coord(&q).0 > mid;
                let (anchor, dx) = if right {
                    (HPos::Right, -8)
                } else {
                    (HPos::Left, 8)
                };
                let style = (FONT, 11)
                    .into_font()
                    .color(&ink)
                    .pos(Pos::new(anchor, VPos::Bottom));
                if s.marker == Marker::TaggedDot {
                    chart
                        .draw_series([Circle::new(q, 4, c.filled())])
                        .map_err(draw_err)?;
                } else {
                    chart
                        .draw_series([TriangleMarker::new(q, 7, c.filled())])
                        .map_err(draw_err)?;
                }
                chart
                    .draw_series([EmptyElement::at(q) + Text::new(label.clone(), (dx, -4), style)])
                    .map_err(draw_err)?;
            }
        }
        Marker::Ring => {
            chart
                .draw_series(
                    sp.iter()
                        .map(|&q| Circle::new(q, 11, BLACK.stroke_width(2))),
                )
                .map_err(draw_err)?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 10, y), 6, BLACK.stroke_width(2)));
        }
    }
    Ok(())
}

/// Renders panels side by side (`cols` per row) into one SVG document.
pub fn svg_grid(size: (u32, u32), cols: usize, panels: &[Panel]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let cols = cols.max(1);
        let rows = panels.len().div_ceil(cols).max(1);
        let areas = root.split_evenly((rows, cols));
        for (p, area) in panels.iter().zip(areas.iter()) {
            draw_panel(area, p)?;
        }
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Renders one panel as a whole SVG document.
pub fn svg_single(size: (u32, u32), panel: &Panel) -> Result<String> {
    svg_grid(size, 1, std::slice::from_ref(panel))
}

/// Draws a panel into `area`, choosing linear or log coordinates per axis.
pub fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Result<()> {
    let pts: Vec<Vec<(f64, f64)>> = p
        .series
        .iter()
        .map(|s| plottable(&s.points, p.x.log, p.y.log))
        .collect();
    // A blow-up whose last value cannot sit on a log axis (zero error before the first step)
    // is still marked: at the bottom of the axis, placed once the range is known.
    let floor_marks: Vec<Option<f64>> = p
        .series
        .iter()
        .map(|s| {
            s.blowup
                .filter(|b| drawable(b.x, p.x.log) && b.y.is_finite() && !drawable(b.y, p.y.log))
                .map(|b| b.x)
        })
        .collect();
    let mut marks: Vec<Option<(f64, f64)>> = p
        .series
        .iter()
        .map(|s| {
            s.blowup
                .filter(|b| drawable(b.x, p.x.log) && drawable(b.y, p.y.log))
                .map(|b| (b.x, b.y))
        })
        .collect();
    let guides: Vec<Vec<(f64, f64)>> = p
        .guides
        .iter()
        .map(|g| plottable(&g.points, p.x.log, p.y.log))
        .collect();
    let all = || {
        pts.iter()
            .flatten()
            .copied()
            .chain(marks.iter().flatten().copied())
    };
    let (mut x0, mut x1) = range(all().map(|q| q.0), p.x.log);
    let (mut y0, mut y1) = range(all().map(|q| q.1), p.y.log);
    for (m, fx) in marks.iter_mut().zip(&floor_marks) {
        if let Some(x) = fx {
            *m = Some((*x, y0));
        }
    }
    if p.equal_aspect && !p.x.log && !p.y.log {
        let (w, h) = (x1 - x0, y1 - y0);
        let (aw, ah) = area.dim_in_pixel();
        let ratio = (ah as f64 - 60.0).max(1.0) / (aw as f64 - 80.0).max(1.0);
        if h / w < ratio {
            let extra = (w * ratio - h) / 2.0;
            y0 -= extra;
            y1 += extra;
        } else {
            let extra = (h / ratio - w) / 2.0;
            x0 -= extra;
            x1 += extra;
        }
    }
    let gated = Gated {
        pts: &pts,
        marks: &marks,
        guides: &guides,
    };
    match (p.x.log, p.y.log) {
        (false, false) => draw_in(area, p, &gated, x0..x1, y0..y1),
        (false, true) => draw_in(area, p, &gated, x0..x1, (y0..y1).log_scale()),
        (true, false) => draw_in(area, p, &gated, (x0..x1).log_scale(), y0..y1),
        (true, true) => draw_in(area, p, &gated, (x0..x1).log_scale(), (y0..y1).log_scale()),
    }
}

/// A panel's points through the finite gate, in the panel's order: its series, their blow-up
/// markers (placed) and its guide lines. Bundled because they are drawn together, one entry
/// per series or guide of the panel.
struct Gated<'a> {
    pts: &'a [Vec<(f64, f64)>],
    marks: &'a [Option<(f64, f64)>],
    guides: &'a [Vec<(f64, f64)>],
}

/// Draws panel `p` into `area`: its series, blow-up markers and guide lines as `gated` holds
/// them, over the ranges `xr` × `yr`.
fn draw_in<DB, X, Y>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
    gated: &Gated<'_>,
    xr: X,
    yr: Y,
) -> Result<()>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let Gated { pts, marks, guides } = *gated;
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, 17))
        .margin(12)
        .x_label_area_size(46)
        .y_label_area_size(74)
        .build_cartesian_2d(xr, yr)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc(&p.x.label)
        .y_desc(&p.y.label)
        .axis_desc_style((FONT, 14))
        .label_style((FONT, 12))
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(210, 210, 210))
        .x_labels(8)
        .y_labels(8)
        .draw()
        .map_err(draw_err)?;
    for (g, gp) in p.guides.iter().zip(guides) {
        if gp.len() < 2 {
            continue;
        }
        let style = RGBColor(110, 110, 110).stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new(gp.iter().copied(), 6, 4, style))
            .map_err(draw_err)?
            .label(g.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 8, y)], RGBColor(110, 110, 110))
            });
    }
    let mut any_blowup = false;
    for ((s, sp), mark) in p.series.iter().zip(pts).zip(marks) {
        let c = color_for(&s.label);
        let style = c.stroke_width(2);
        if p.lines {
            chart
                .draw_series(LineSeries::new(sp.iter().copied(), style))
                .map_err(draw_err)?
                .label(s.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(3))
                });
        } else {
            draw_markers(&mut chart, s, sp, c)?;
        }
        if p.dots && p.lines {
            chart
                .draw_series(sp.iter().map(|&q| Circle::new(q, 3, c.filled())))
                .map_err(draw_err)?;
        }
        if let Some(m) = *mark {
            any_blowup = true;
            chart
                .draw_series([Cross::new(m, 7, c.stroke_width(3))])
                .map_err(draw_err)?;
            chart
                .draw_series([Text::new("blow-up", m, (FONT, 12).into_font().color(&c))])
                .map_err(draw_err)?;
        }
    }
    if any_blowup {
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(draw_err)?
            .label("× run blew up here")
            .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(p.legend.clone())
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(150, 150, 150))
        .label_font((FONT, 12))
        .draw()
        .map_err(draw_err)?;
    Ok(())
}
