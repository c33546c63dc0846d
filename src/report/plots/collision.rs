//! Collision: height over time with the e^(2n) apex envelope, measured against specified
//! restitution per bounce, and penetration per contact.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::measure::study::SceneStudy;
use crate::report::charts::*;
use crate::report::data::*;
use crate::report::figures::{link, Chart, PageChart};
use serde::{Deserialize, Serialize};

/// SVG with three panels: height, restitution per bounce, penetration per contact.
pub fn collision(data: &CollisionData) -> Result<String> {
    let mut heights = data.heights.clone();
    let mut env = data.envelope.clone();
    env.label = format!("{} (envelope h₀·e^(2n))", env.label);
    heights.push(env);
    let restitution: Vec<Series> = data
        .bounces
        .iter()
        .map(|(b, bs)| {
            Series::new(
                b.clone(),
                bs.iter().map(|x| [x.n as f64, x.measured]).collect(),
            )
        })
        .collect();
    let specified: Vec<Guide> = data
        .bounces
        .iter()
        .flat_map(|(_, bs)| bs.iter())
        .map(|b| b.specified)
        .next()
        .map(|e| {
            let n = data
                .bounces
                .iter()
                .flat_map(|(_, bs)| bs.iter().map(|b| b.n))
                .max()
                .unwrap_or(1) as f64;
            vec![Guide {
                label: format!("specified e = {e}"),
                points: vec![[1.0, e], [n.max(2.0), e]],
            }]
        })
        .unwrap_or_default();
    let penetration: Vec<Series> = data
        .bounces
        .iter()
        .map(|(b, bs)| {
            Series::new(
                b.clone(),
                bs.iter().map(|x| [x.n as f64, x.penetration]).collect(),
            )
        })
        .collect();
    let panels = [
        Panel {
            title: "Height over time".into(),
            x: Axis::lin("time t (s)"),
            y: Axis::lin("height (m)"),
            series: &heights,
            guides: &[],
            dots: false,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        },
        Panel {
            title: "Restitution per bounce".into(),
            x: Axis::lin("bounce n"),
            y: Axis::lin("restitution e (rebound / impact speed)"),
            series: &restitution,
            guides: &specified,
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        },
        Panel {
            title: "Penetration per contact".into(),
            x: Axis::lin("contact n"),
            y: Axis::lin("deepest penetration (m)"),
            series: &penetration,
            guides: &[],
            dots: true,
            lines: true,
            equal_aspect: false,
            legend: plotters::prelude::SeriesLabelPosition::UpperRight,
        },
    ];
    svg_grid((1600, 520), 3, &panels)
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

/// Height over time, the h₀·e^(2n) envelope and per-bounce restitution and penetration, for
/// scenes with obstacles (the first tracked particle of each method's contact metrics).
pub fn from_study(s: &SceneStudy) -> Option<CollisionData> {
    let mut heights = Vec::new();
    let mut bounces = Vec::new();
    let mut envelope = None;
    for run in runs(s) {
        let Some(c) = &run.contacts else { continue };
        let Some(pb) = c.bounces.first() else {
            continue;
        };
        let mut h = Series::new(run.method.clone(), pb.heights.clone());
        h.blowup = blowup_at(run, h.points.last().copied());
        heights.push(h);
        if envelope.is_none() && pb.apexes.len() > 1 {
            envelope = Some(Series::new(
                format!("particle {}", pb.particle),
                pb.apexes.iter().map(|a| [a.t, a.predicted]).collect(),
            ));
        }
        let list: Vec<Bounce> = c
            .events
            .iter()
            .filter(|e| e.particle == pb.particle)
            .enumerate()
            .filter_map(|(k, e)| {
                e.restitution.map(|m| Bounce {
                    n: k as u32 + 1,
                    measured: m,
                    specified: e.expected_restitution,
                    penetration: e.max_penetration,
                })
            })
            .collect();
        bounces.push((run.method.clone(), list));
    }
    if heights.is_empty() {
        return None;
    }
    Some(CollisionData {
        heights,
        envelope: envelope.unwrap_or_else(|| Series::new("no apex", Vec::new())),
        bounces,
    })
}

impl Chart for CollisionData {
    fn stem(&self) -> &'static str {
        "collision"
    }
    fn svg(&self) -> Result<String> {
        collision(self)
    }
}

impl PageChart for CollisionData {
    fn title(&self) -> &'static str {
        "Collision"
    }
    fn caption(&self) -> String {
        format!("Left: the gap between the first tracked particle and the obstacle (negative: penetration), with the apex heights h₀·e^(2n) the specified restitution implies. Middle: measured restitution per bounce against the specified one (dashed). Right: deepest penetration per contact. {}", link("compare/contacts.json"))
    }
}
