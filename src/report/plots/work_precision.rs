//! Work-precision: error against modelled time ([`crate::run::cost`]) and against force
//! evaluations, log-log.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

/// SVG with two panels: error against modelled time, and error against force evaluations.
pub fn work_precision(data: &WorkPrecisionData) -> Result<String> {
    let by = |f: &dyn Fn(&crate::report::data::WorkPoint) -> f64| -> Vec<Series> {
        data.lines
            .iter()
            .map(|l| {
                Series::new(
                    l.label.clone(),
                    l.points.iter().map(|p| [f(p), p.error]).collect(),
                )
            })
            .collect()
    };
    let modelled = by(&|p| p.modelled_seconds);
    let evals = by(&|p| p.force_evals as f64);
    let panels = [
        Panel {
            title: "Error against modelled time".into(),
            x: Axis::log("modelled time (s): counted work, priced"),
            y: Axis::log("RMS position error at the end (m)"),
            series: &modelled,
            guides: &[],
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerRight,
        },
        Panel {
            title: "Error against force evaluations".into(),
            x: Axis::log("force evaluations (count)"),
            y: Axis::log("RMS position error at the end (m)"),
            series: &evals,
            guides: &[],
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerRight,
        },
    ];
    svg_grid((1500, 560), 2, &panels)
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

/// Work-precision lines from the sweep's stable rows, and each engine's compare run at the
/// scene's step as one point beside them (same duration, same error measure; an engine is
/// not swept); `None` when no sweep run was stable.
pub fn from_study(s: &SceneStudy) -> Option<WorkPrecisionData> {
    let sweep = s.sweep.as_ref()?;
    let registry = crate::method::Registry::builtin();
    let engines = runs(s)
        .filter(|r| registry.info(&r.method).is_ok_and(|m| m.engine))
        .map(|r| WorkLine {
            label: r.method.clone(),
            points: r
                .metrics
                .as_ref()
                .map(|m| m.error_max)
                .filter(|e| e.is_finite() && *e > 0.0 && r.status.is_ok())
                .map(|e| WorkPoint {
                    dt: r.dt,
                    error: e,
                    modelled_seconds: r.modelled_seconds,
                    force_evals: r.force_evals,
                })
                .into_iter()
                .collect(),
        });
    let lines: Vec<WorkLine> = sweep
        .plan
        .methods
        .iter()
        .map(|name| WorkLine {
            label: name.clone(),
            points: sweep
                .rows
                .iter()
                .filter(|r| &r.method == name)
                .filter_map(|r| {
                    r.error_max
                        .filter(|e| e.is_finite() && *e > 0.0)
                        .map(|e| WorkPoint {
                            dt: r.dt,
                            error: e,
                            modelled_seconds: r.modelled_seconds,
                            force_evals: r.force_evals,
                        })
                })
                .collect(),
        })
        .chain(engines)
        .collect();
    lines
        .iter()
        .any(|l| !l.points.is_empty())
        .then_some(WorkPrecisionData { lines })
}

impl Chart for WorkPrecisionData {
    fn stem(&self) -> &'static str {
        "work_precision"
    }
    fn svg(&self) -> Result<String> {
        work_precision(self)
    }
}

impl PageChart for WorkPrecisionData {
    fn title(&self) -> &'static str {
        "Work against precision"
    }
    fn caption(&self) -> String {
        format!("The same sweep as cost: lower-left is better. Each engine (Rapier, not swept) is one point: its comparison run at the scene's step, same duration and error. Modelled time is the runs' counted work priced per item, the same on every run (the measured wall times are in timing.json); force evaluations count one kind of that work (an engine has none, so it is absent from that panel). {}", link("sweep/sweep.csv"))
    }
}
