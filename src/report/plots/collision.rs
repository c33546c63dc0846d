//! Collision: height over time with the e^(2n) apex envelope, measured against specified
//! restitution per bounce, and penetration per contact.

use super::common::{svg_grid, Axis, Panel};
use crate::error::Result;
use crate::report::data::{CollisionData, Guide, Series};

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
