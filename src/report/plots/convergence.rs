//! Convergence: error against dt, log-log, one line per method with its fitted slope in
//! the legend, and reference slopes drawn dashed.

use super::common::{svg_single, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

/// SVG of the error at the end of the sweep (m) against the step (s), log-log.
pub fn convergence(data: &ConvergenceData) -> Result<String> {
    let series: Vec<Series> = data
        .lines
        .iter()
        .map(|l| {
            let mut s = l.series.clone();
            s.label = match l.fitted_slope {
                Some(k) => format!("{} (observed order {k:.2}, theory {})", s.label, l.order),
                None => format!("{} (no asymptotic range, theory {})", s.label, l.order),
            };
            s
        })
        .collect();
    svg_single(
        (900, 560),
        &Panel {
            title: "Convergence against the reference".into(),
            x: Axis::log("time step dt (s)"),
            y: Axis::log("max position error over the run (m)"),
            series: &series,
            guides: &data.guides,
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::LowerRight,
        },
    )
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

/// Convergence lines from the sweep's rows with the sweep's fitted orders and the theoretical
/// orders its plan recorded, and reference slopes dt^p for the orders present.
pub fn from_study(s: &SceneStudy) -> Option<ConvergenceData> {
    let sweep = s.sweep.as_ref()?;
    let summary = sweep.summary.as_ref()?;
    let mut lines = Vec::new();
    for (name, order) in sweep.plan.methods.iter().zip(&sweep.plan.orders) {
        let rows = sweep.rows.iter().filter(|r| &r.method == name);
        let points: Vec<[f64; 2]> = rows
            .clone()
            .filter_map(|r| {
                r.error_max
                    .filter(|e| e.is_finite() && *e > 0.0)
                    .map(|e| [r.dt, e])
            })
            .collect();
        let unstable = rows
            .filter(|r| !r.status.is_ok())
            .map(|r| r.dt)
            .reduce(f64::max);
        let top = points.iter().map(|p| p[1]).reduce(f64::max).unwrap_or(1.0);
        let mut series = Series::new(name.clone(), points);
        series.blowup = unstable.map(|dt| BlowUp { x: dt, y: top });
        let fit = summary.methods.iter().find(|i| &i.method == name);
        let Some(order) = *order else {
            continue;
        };
        lines.push(ConvergenceLine {
            series,
            fitted_slope: fit.and_then(|f| f.observed_order),
            order,
            note: fit.and_then(|f| f.fit.note.clone()),
        });
    }
    let mut orders: Vec<u32> = lines.iter().map(|l| l.order).collect();
    orders.sort();
    orders.dedup();
    let (dt0, dt1) = sweep
        .plan
        .dts
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &d| (a.min(d), b.max(d)));
    let guides = orders
        .iter()
        .filter_map(|&p| {
            let anchor = lines
                .iter()
                .filter(|l| l.order == p)
                .flat_map(|l| l.series.points.iter())
                .min_by(|a, b| a[0].total_cmp(&b[0]))?;
            let c = anchor[1] * 0.5 / anchor[0].powi(p as i32);
            Some(Guide {
                label: format!("reference slope {p} (∝ dt^{p})"),
                points: vec![[dt0, c * dt0.powi(p as i32)], [dt1, c * dt1.powi(p as i32)]],
            })
        })
        .collect();
    Some(ConvergenceData {
        lines,
        guides,
        reference: format!("{} ({})", sweep.reference.kind, sweep.reference.description),
    })
}

impl Chart for ConvergenceData {
    fn stem(&self) -> &'static str {
        "convergence"
    }
    fn svg(&self) -> Result<String> {
        convergence(self)
    }
}

impl PageChart for ConvergenceData {
    fn title(&self) -> &'static str {
        "Convergence"
    }
    fn caption(&self) -> String {
        format!("Largest position error against the step, log-log, against the reference ({}); the legend gives each method's observed order as the sweep fitted it on its asymptotic range (none when that range was not reached), dashed lines are reference slopes. Blow-ups are marked at the coarsest unstable step. {}", self.reference, link("sweep/summary.json, sweep/sweep.csv"))
    }
}
