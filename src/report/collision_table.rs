//! The collision-validation table of an obstacle scene's page: per method, measured against
//! expected restitution per impact, penetration, friction (slides against Coulomb's law) and
//! the energy booked per impact, all read from compare's `contacts.json` (one computation:
//! [`crate::measure::contacts`]).

use super::html::esc;
use crate::measure::case::CaseResult;
use crate::measure::contacts::{differences, ContactReport};
use crate::measure::study::SceneStudy;

fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4}")
    } else {
        "—".into()
    }
}

fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "—".into()
    }
}

/// The section, or `None` for a scene without obstacles.
pub fn section(st: &SceneStudy) -> Option<String> {
    let runs: Vec<_> = st
        .compare
        .entries
        .iter()
        .filter_map(|e| e.result.as_ref())
        .filter_map(|r| r.contacts.as_ref().map(|c| (r, c)))
        .collect();
    if runs.is_empty() {
        return None;
    }
    let mut body = String::from("<h2>Collision validation</h2>\n<p class=\"note\">From <a href=\"compare/contacts.json\">compare/contacts.json</a>, per method at the comparison's step. Restitution: impacts approaching faster than the stated floor (1 % of the fastest), measured e = v_out/v_in against the expected e (the specified one; for penalty contacts, the contact equation's with gravity along the normal), mean and worst deviation; in/out speeds are carried from the samples to the surface under gravity alone, so for particles held by springs or constraints, whose pull acts over that stretch too, slow impacts can deviate far (the chart shows which). Penetration: deepest measured against the deepest expected. Friction: slides in resting contact of particles on which only gravity, the contact and friction act, measured deceleration against the point-mass Coulomb law (worst relative deviation); particles held by springs or constraints are not measured (their Coulomb law has the spring forces in it). Energy per impact: mean work booked as dissipated, and the energy any contact created (should be 0).</p>\n<table>\n<tr><th class=\"l\">method</th><th>impacts (floor m/s)</th><th>mean e measured</th><th>mean e expected</th><th>worst e − expected</th><th>deepest penetration (m)</th><th>deepest expected (m)</th><th>slides</th><th>worst friction deviation</th><th>dissipated per impact (J)</th><th>created (J)</th><th>tunnelling</th></tr>\n");
    for &(r, c) in &runs {
        let expected_pen = c
            .events
            .iter()
            .map(|e| e.expected_penetration)
            .fold(f64::NEG_INFINITY, f64::max);
        let friction = c
            .slides
            .iter()
            .filter(|s| s.expected_acceleration.abs() > 0.0)
            .map(|s| ((s.acceleration - s.expected_acceleration) / s.expected_acceleration).abs())
            .fold(f64::NEG_INFINITY, f64::max);
        let n = c.events.len().max(1) as f64;
        let dissipated: f64 = c.events.iter().map(|e| e.energy_dissipated).sum::<f64>() / n;
        let created: f64 = c.events.iter().map(|e| e.energy_created).sum();
        let has_e = c.restitution.count > 0;
        body += &format!(
            "<tr><td class=\"l\">{}</td><td>{} ({})</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            esc(&r.method),
            c.restitution.count,
            sci(c.impact_speed_floor),
            if has_e { num(c.restitution.mean) } else { "—".into() },
            if has_e { num(c.expected_restitution.mean) } else { "—".into() },
            if has_e { num(c.restitution_worst_deviation) } else { "—".into() },
            sci(c.penetration_max()),
            sci(expected_pen),
            if c.slides_unmeasured.is_some() {
                "no free slides".to_string()
            } else {
                c.slides.len().to_string()
            },
            if friction.is_finite() { format!("{:.2} %", 100.0 * friction) } else { "—".into() },
            if c.events.is_empty() { "—".into() } else { sci(dissipated) },
            sci(created),
            c.tunnelling_count
        );
    }
    body += "</table>\n";
    body += &first_impacts(&runs);
    body += &rapier_differences(&runs);
    Some(body)
}

/// Impacts per method in the first-impacts table.
pub const FIRST_IMPACTS: usize = 3;

/// The first [`FIRST_IMPACTS`] impacts of each method above its summary floor, in time order:
/// measured e against the expected one, impact by impact.
fn first_impacts(runs: &[(&CaseResult, &ContactReport)]) -> String {
    let mut rows = String::new();
    for (r, c) in runs {
        let mut list: Vec<_> = c.summary_impacts().collect();
        list.sort_by(|a, b| a.0.t_in.total_cmp(&b.0.t_in));
        for (k, (e, m)) in list.iter().take(FIRST_IMPACTS).enumerate() {
            rows += &format!(
                "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                esc(&r.method),
                k + 1,
                e.particle,
                num(e.t_in),
                num(e.v_in.abs()),
                num(*m),
                num(e.expected_restitution),
                sci(m - e.expected_restitution)
            );
        }
    }
    if rows.is_empty() {
        return String::new();
    }
    format!("<h3>First impacts</h3>\n<p class=\"note\">Each method's first {FIRST_IMPACTS} impacts above its floor, in time order: approach speed carried to the surface, measured e = v_out/|v_in| against the expected e.</p>\n<table>\n<tr><th class=\"l\">method</th><th>impact</th><th>particle</th><th>t (s)</th><th>|v_in| (m/s)</th><th>e measured</th><th>e expected</th><th>measured − expected</th></tr>\n{rows}</table>\n")
}

/// Rapier's documented contact differences, each with what this scene's Rapier runs measured
/// of it; empty when no Rapier method ran.
fn rapier_differences(runs: &[(&CaseResult, &ContactReport)]) -> String {
    if !runs.iter().any(|(r, _)| differences::is_rapier(&r.method)) {
        return String::new();
    }
    let response = runs.first().map(|(_, c)| c.response);
    let mut items = String::new();
    for d in differences::DIFFERENCES
        .iter()
        .filter(|d| response.is_some_and(|r| d.applies_to(r)))
    {
        let figures: Vec<String> = runs
            .iter()
            .filter_map(|(r, c)| {
                differences::measured(d, &r.method, c)
                    .map(|f| format!("{}: {}", esc(&r.method), esc(&f)))
            })
            .collect();
        let measured = if figures.is_empty() {
            "not measured by this scene's runs".to_string()
        } else {
            format!("measured here: {}", figures.join("; "))
        };
        items += &format!(
            "<li><b>{}</b>: {}. <i>{measured}</i> (test <code>{}</code>)</li>\n",
            esc(d.title),
            esc(d.text),
            esc(d.test)
        );
    }
    format!("<h3>Rapier's contact model: documented differences</h3>\n<ul>\n{items}</ul>\n")
}
