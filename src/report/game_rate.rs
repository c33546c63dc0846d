//! How Rapier fares at a scene's game rate, as a picture read at a glance: every method of the
//! frame-rate table one point (modelled cost per frame, error), the engines as triangles, the
//! answer ringed, the bound dashed; and the front page's words for the best engine. Both read
//! [`crate::measure::engine_fare`], so the chart, the sentence and `framerate.json` agree.

use super::data::{Guide, Marker, Series};
use super::plots::common::{svg_single, Axis, Panel};
use crate::error::{significant, Result};
use crate::measure::answer::GameRate;
use crate::measure::engine_fare::{EngineFare, GamePoint};

/// One series per method (a single point each), then the ring around the answer.
fn series(points: &[GamePoint], game: &GameRate) -> Vec<Series> {
    let at = |p: &GamePoint| -> Vec<[f64; 2]> {
        match (p.modelled_seconds_per_frame, p.error) {
            (Some(c), Some(e)) => vec![[c, e]],
            _ => Vec::new(),
        }
    };
    let mut out: Vec<Series> = points
        .iter()
        .map(|p| {
            let points = at(p);
            // A run that stopped has no error to plot: the legend names it instead.
            let (marker, label) = match (points.is_empty(), p.engine) {
                (false, true) => (Marker::TaggedTriangle, String::new()),
                (false, false) => (Marker::TaggedDot, String::new()),
                (true, true) => (Marker::Triangle, ": run stopped, no error".to_string()),
                (true, false) => (Marker::Dot, ": run stopped, no error".to_string()),
            };
            Series {
                marker,
                ..Series::new(format!("{} × {}{label}", p.method, p.substeps), points)
            }
        })
        .collect();
    // The legend says what the shapes mean; each point carries its own label.
    for (label, marker) in [
        ("springlab method × substeps", Marker::Dot),
        ("Rapier method × substeps", Marker::Triangle),
    ] {
        out.push(Series {
            marker,
            ..Series::new(label, Vec::new())
        });
    }
    if let Some(p) = points.iter().find(|p| {
        game.meets && Some(&p.method) == game.method.as_ref() && Some(p.substeps) == game.substeps
    }) {
        out.push(Series {
            marker: Marker::Ring,
            ..Series::new("the answer", at(p))
        });
    }
    out
}

/// The game-rate chart of a scene: every method's point at the game rate, and the answer.
pub struct GameRateChart<'a> {
    /// The points (one per method and substep count tried).
    pub points: Vec<GamePoint>,
    /// The game-rate answer, ringed on the chart.
    pub game: &'a GameRate,
}

impl super::data::ChartCsv for GameRateChart<'_> {
    fn to_csv(&self) -> Result<Vec<u8>> {
        Ok(chart_csv(&self.points, self.game).into_bytes())
    }
}

impl super::figures::Chart for GameRateChart<'_> {
    fn stem(&self) -> &'static str {
        GAME_RATE_STEM
    }
    fn svg(&self) -> Result<String> {
        chart(&self.points, self.game)
    }
}

/// File stem of a scene's game-rate chart: `game_rate.svg` beside its page, its data in
/// `game_rate.csv`.
pub const GAME_RATE_STEM: &str = "game_rate";

/// The data behind the chart, as CSV, written beside the SVG like every chart's data.
fn chart_csv(points: &[GamePoint], game: &GameRate) -> String {
    let mut out =
        String::from("method,engine,substeps,modelled_seconds_per_frame,error,meets,answer\n");
    let num = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
    for p in points {
        let answer = game.meets
            && Some(&p.method) == game.method.as_ref()
            && Some(p.substeps) == game.substeps;
        out += &format!(
            "{},{},{},{},{},{},{answer}\n",
            p.method,
            p.engine,
            p.substeps,
            num(p.modelled_seconds_per_frame),
            num(p.error),
            p.meets
        );
    }
    out
}

/// The chart (SVG): error against modelled cost per frame at `game.hz`, log-log, with the
/// bound as a dashed line.
fn chart(points: &[GamePoint], game: &GameRate) -> Result<String> {
    let series = series(points, game);
    let costs = points.iter().filter_map(|p| p.modelled_seconds_per_frame);
    let (lo, hi) = costs.fold((f64::INFINITY, 0.0_f64), |(a, b), c| (a.min(c), b.max(c)));
    let guides = if lo.is_finite() && hi > 0.0 {
        vec![Guide {
            label: format!("bound {}", significant(game.tolerance, 2)),
            points: vec![[lo, game.tolerance], [hi, game.tolerance]],
        }]
    } else {
        Vec::new()
    };
    svg_single(
        (640, 460),
        &Panel {
            title: format!(
                "At {} Hz: error against cost (▲ Rapier)",
                if game.hz.fract() == 0.0 && game.hz < 1e6 {
                    format!("{:.0}", game.hz)
                } else {
                    significant(game.hz, 3)
                }
            ),
            x: Axis::log("modelled time per frame (s)"),
            y: Axis::log(format!("error ({})", game.metric.unit())),
            series: &series,
            guides: &guides,
            dots: true,
            lines: false,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerLeft,
        },
    )
}

/// The best engine at the game rate in words, beside the answer: its substeps, error, cost
/// per frame and, where both meet the bound, its cost over the answer's.
pub fn words(fare: &EngineFare, game: &GameRate) -> String {
    let b = &fare.best;
    let err = b
        .error
        .map_or("no error (the run stopped)".to_string(), |e| {
            format!("error {} {}", significant(e, 2), game.metric.unit())
        });
    let cost = b.modelled_seconds_per_frame.map_or(String::new(), |c| {
        format!(", {} ms per frame, modelled", significant(c * 1e3, 2))
    });
    let verdict = if b.meets {
        format!("{} × {} meets the bound: {err}{cost}", b.method, b.substeps)
    } else {
        format!(
            "no Rapier method met the bound (best: {} × {}, {err}{cost})",
            b.method, b.substeps
        )
    };
    match fare.cost_ratio {
        Some(r) => format!("{verdict}; {}× the answer's cost", significant(r, 2)),
        None => verdict,
    }
}
