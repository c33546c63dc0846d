//! The frame-rate section of a scene page: per method, the error of one step per frame and
//! the cost per frame of the fewest substeps that meet the tolerance, against the frame rate,
//! from the very `framerate.json` that `springlab framerate` writes.

use super::finite::cell;
use super::html::esc;
use super::plots::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::measure::framerate::Framerate;
use crate::report::data::{BlowUp, Series};

/// The methods of `fr`, in the order of its entries.
fn methods(fr: &Framerate) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for e in &fr.entries {
        if !names.contains(&e.method.as_str()) {
            names.push(&e.method);
        }
    }
    names
}

/// One line per method: (x = Hz, y) for each rate where `pick` gives a value; a rate where
/// the run at one substep blew up ends the line with a marker at the last point.
fn lines(
    fr: &Framerate,
    pick: impl Fn(&crate::measure::framerate::RateEntry) -> Option<f64>,
) -> Vec<Series> {
    methods(fr)
        .iter()
        .map(|n| {
            let points: Vec<[f64; 2]> = fr
                .entries
                .iter()
                .filter(|e| e.method == *n)
                .filter_map(|e| pick(e).map(|v| [e.hz, v]))
                .collect();
            Series {
                label: n.to_string(),
                points,
                blowup: None::<BlowUp>,
                marker: crate::report::data::Marker::Dot,
            }
        })
        .filter(|s| !s.points.is_empty())
        .collect()
}

fn error_lines(fr: &Framerate) -> Vec<Series> {
    lines(fr, |e| e.one_substep.max_position_error)
}

fn cost_lines(fr: &Framerate) -> Vec<Series> {
    lines(fr, |e| {
        e.fewest.as_ref().and_then(|f| f.modelled_seconds_per_frame)
    })
}

/// The bound every run is held to, in its metric's unit: `0.01 m` for a position metric, else
/// the metric's measure against its bound (`score ≤ 1`: a statistics bound is no length).
fn bound_words(fr: &Framerate) -> String {
    use crate::measure::tolerance::Metric;
    let b = cell(Some(fr.judged.tolerance), 3);
    match fr.judged.metric {
        Metric::Position | Metric::Impacts => format!("{b} m"),
        Metric::Strain => format!("strain error ≤ {b}"),
        Metric::Energy => format!("relative energy error ≤ {b}"),
        Metric::Statistics => format!("statistics score ≤ {b}"),
    }
}

/// The frame-rate chart of a scene: error at one substep and cost at the fewest substeps,
/// against the frame rate.
pub struct FramerateChart<'a>(pub &'a Framerate);

impl super::data::ChartCsv for FramerateChart<'_> {
    fn to_csv(&self) -> Result<Vec<u8>> {
        Ok(chart_csv(self.0).into_bytes())
    }
}

impl super::figures::Chart for FramerateChart<'_> {
    fn stem(&self) -> &'static str {
        "framerate"
    }
    fn svg(&self) -> Result<String> {
        chart(self.0)
    }
}

/// The data behind the chart, as CSV (`group,series,x,y,kind`: panel, method, Hz, value,
/// `point`), written beside the SVG like every chart's data.
fn chart_csv(fr: &Framerate) -> String {
    let mut out = String::from("group,series,x,y,kind\n");
    for (panel, series) in [
        ("error_one_substep_m", error_lines(fr)),
        ("modelled_seconds_per_frame_fewest", cost_lines(fr)),
    ] {
        for s in series {
            for p in s.points {
                out += &format!("{panel},{},{:e},{:e},point\n", s.label, p[0], p[1]);
            }
        }
    }
    out
}

/// The chart (SVG) of `fr`: error at one substep, and modelled time per frame at the fewest
/// substeps meeting the tolerance, both against the frame rate.
fn chart(fr: &Framerate) -> Result<String> {
    let (err, cost) = (error_lines(fr), cost_lines(fr));
    let panel = |title: String, y: &str, series| Panel {
        title,
        x: Axis::log("frame rate (Hz)"),
        y: Axis::log(y),
        series,
        guides: &[],
        dots: true,
        lines: true,
        equal_aspect: false,
        legend: plotters::prelude::SeriesLabelPosition::UpperRight,
    };
    svg_grid(
        (1200, 520),
        2,
        &[
            panel(
                "Error at one step per frame (stable runs)".into(),
                "max position error (m)",
                &err,
            ),
            panel(
                format!("Cost per frame meeting {}", bound_words(fr)),
                "modelled time per frame (s)",
                &cost,
            ),
        ],
    )
}

/// The page section: chart, then per method and rate the run at one substep and the fewest
/// substeps meeting the tolerance with its cost per frame, then `left_out`: the study's notes
/// on the methods it left out (with their modelled time per frame).
pub fn section(fr: &Framerate, note: Option<&str>, left_out: &[String]) -> String {
    let mut rates: Vec<f64> = Vec::new();
    for e in &fr.entries {
        if !rates.contains(&e.hz) {
            rates.push(e.hz);
        }
    }
    let names = methods(fr);
    let mut body = format!(
        "<h2>Frame rates</h2>\n<p class=\"note\">From <a href=\"framerate/framerate.json\">framerate/framerate.json</a> and <a href=\"framerate/framerate.csv\">framerate.csv</a> (re-create with <code>{}</code>): each method at each frame rate over {} s, first one step per frame, then the fewest substeps (searched upwards and then bisected, up to {}; on a scene without contacts or kicks the runs' errors predict the counts tried) that stay stable and meet the bound of the metric against the reference ({}). A cell reads <em>substeps needed · modelled time per frame</em> (counted work, priced; the measured wall times are in the scene's <a href=\"timing.json\">timing.json</a>); “—” where no count up to the limit met it. Events: {}.{}</p>\n<figure><img src=\"framerate.svg\" alt=\"frame rates\"><figcaption>Left: error of one step per frame (unstable runs left out). Right: modelled time per frame at the fewest substeps meeting the tolerance. Log scales.</figcaption></figure>\n<table>\n<tr><th class=\"l\">method</th>",
        esc(&fr.head.command),
        fr.duration,
        fr.max_substeps,
        esc(&bound_words(fr)),
        fr.events,
        note.map_or(String::new(), |n| format!(" {}", esc(n)))
    );
    for hz in &rates {
        body += &format!(
            "<th>{hz} Hz: 1 step</th><th>{hz} Hz: for {}</th>",
            esc(&bound_words(fr))
        );
    }
    body += "</tr>\n";
    for n in &names {
        body += &format!("<tr><td class=\"l\">{}</td>", esc(n));
        for hz in &rates {
            let Some(e) = fr.entries.iter().find(|e| e.method == *n && e.hz == *hz) else {
                body += "<td>—</td><td>—</td>";
                continue;
            };
            let one = if let Some(err) = e.one_substep.max_position_error {
                format!("{err:.2e} m")
            } else {
                format!(
                    "unstable at t = {}",
                    e.one_substep
                        .unstable_time
                        .map_or("?".into(), |t| format!("{t:.3}"))
                )
            };
            let fewest = e.fewest.as_ref().map_or("—".to_string(), |f| {
                format!(
                    "{} · {}",
                    f.substeps,
                    f.modelled_seconds_per_frame
                        .map_or("—".into(), |w| format!("{} ms", cell(Some(w * 1e3), 3)))
                )
            });
            body += &format!("<td>{}</td><td>{}</td>", esc(&one), esc(&fewest));
        }
        body += "</tr>\n";
    }
    body += "</table>\n";
    if !fr.skipped.is_empty() || !left_out.is_empty() {
        body += "<ul class=\"note\">\n";
        for (n, why) in &fr.skipped {
            body += &format!("<li><code>{}</code>: {}</li>\n", esc(n), esc(why));
        }
        for n in left_out {
            body += &format!("<li>{}</li>\n", esc(n));
        }
        body += "</ul>\n";
    }
    body
}
