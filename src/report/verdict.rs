//! The one-paragraph, plain-language verdict of a scene, written from its summary's numbers
//! only (which are its documents' numbers).

use super::finite::cell;
use super::summary::{BackendSummary, SceneSummary};
use crate::measure::stability::Verdict;

/// A step as people write it: `1/60 s` when 1/dt is a whole number, else decimals.
pub fn dt_words(dt: f64) -> String {
    let inv = 1.0 / dt;
    if inv.is_finite() && inv >= 1.0 && (inv - inv.round()).abs() < 1e-6 * inv {
        format!("1/{} s", inv.round() as u64)
    } else {
        format!("{} s", cell(Some(dt), 3))
    }
}

fn pct(v: f64) -> String {
    format!("{}%", cell(Some(100.0 * v), 2))
}

/// A stability limit in words: `dt ≤ 0.0249 s`, `any step` (theory), `every step tried (up to
/// … s)` (an empirical search), `no step`, or `not analysed`.
pub fn limit_words(b: &BackendSummary) -> String {
    match (b.stability, b.stable_dt) {
        (Some(Verdict::StableBelow), Some(dt)) => format!("dt ≤ {} s", cell(Some(dt), 3)),
        (Some(Verdict::UnconditionallyStable), _) => match b.stable_up_to_tried {
            Some(t) => format!("every step tried (up to {} s)", cell(Some(t), 3)),
            None => "any step".into(),
        },
        (Some(Verdict::UnstableForAllDt), _) => "no step".into(),
        _ => "not analysed".into(),
    }
}

/// The sentence that answers "what should I use here?".
pub fn pick_sentence(s: &SceneSummary) -> Option<String> {
    let Some(p) = s.pick.as_ref() else {
        return s.advice_note.as_ref().map(|n| format!("No advice: {n}."));
    };
    Some(match (&p.integrator, p.dt) {
        (Some(m), Some(dt)) => format!(
            "Use {m} at dt = {} for a position error within {} m over {} s (verified: {} m, at {} s of wall time per simulated second).",
            dt_words(dt),
            cell(Some(p.tolerance), 2),
            cell(Some(p.horizon), 3),
            cell(p.verified_error, 2),
            cell(p.wall_per_second, 2)
        ),
        _ => format!(
            "No method meets a position error of {} m over {} s on the advice grid.",
            cell(Some(p.tolerance), 2),
            cell(Some(p.horizon), 3)
        ),
    })
}

/// A scene's answer on the front page, as plain text: what to use, each analysed method's
/// stable step, and what blew up at the scene's step. The HTML and Markdown overviews both
/// render this one row.
#[derive(Debug, Clone, PartialEq)]
pub struct FrontRow {
    /// The advised method and step at the stated tolerance, or why there is none.
    pub pick: String,
    /// `method: limit` per analysed method.
    pub limits: Vec<String>,
    /// `method at t = … s` per run that blew up.
    pub blew: Vec<String>,
}

/// The front-page row of a scene.
pub fn front_row(s: &SceneSummary) -> FrontRow {
    let pick = match &s.pick {
        Some(p) => match (&p.integrator, p.dt) {
            (Some(m), Some(dt)) => format!(
                "{m} at dt = {} (error {} m ≤ {} m over {} s)",
                dt_words(dt),
                cell(p.verified_error, 2),
                cell(Some(p.tolerance), 2),
                cell(Some(p.horizon), 3)
            ),
            _ => format!("nothing meets {} m on the grid", cell(Some(p.tolerance), 2)),
        },
        None => format!(
            "no advice: {}",
            s.advice_note.as_deref().unwrap_or("none was measured")
        ),
    };
    let pick = match &s.failed_this_time {
        Some(_) => format!("(from the previous report; this one failed on the scene) {pick}"),
        None => pick,
    };
    FrontRow {
        pick,
        limits: s
            .backends
            .iter()
            .filter(|b| b.stability.is_some())
            .map(|b| format!("{}: {}", b.backend, limit_words(b)))
            .collect(),
        blew: s
            .backends
            .iter()
            .filter(|b| b.status != "ok")
            .map(|b| format!("{} at t = {} s", b.backend, cell(b.blowup_time, 3)))
            .collect(),
    }
}

/// The paragraph for one scene.
pub fn verdict(s: &SceneSummary) -> String {
    let mut out = Vec::new();
    if let Some(p) = pick_sentence(s) {
        out.push(p);
    }
    let bs = &s.backends;
    let unstable: Vec<String> = bs
        .iter()
        .filter(|b| b.status != "ok")
        .map(|b| {
            format!(
                "{} (t = {} s: {})",
                b.backend,
                cell(b.blowup_time, 3),
                b.blowup_reason.as_deref().unwrap_or("unstable")
            )
        })
        .collect();
    let mut first = format!(
        "At dt = {} over {} s",
        dt_words(s.dt),
        cell(Some(s.duration), 3)
    );
    let mut acc: Vec<(&str, f64)> = bs
        .iter()
        .filter(|b| b.status == "ok" && b.order != crate::method::Order::Exact)
        .filter_map(|b| b.max_position_error.map(|e| (b.backend.as_str(), e)))
        .collect();
    acc.sort_by(|a, b| a.1.total_cmp(&b.1));
    match (acc.first(), acc.last()) {
        (Some(best), Some(worst)) if best.0 != worst.0 => {
            first += &format!(
                ", against the reference ({}), {} is the most accurate (position error at most {} m) and {} the least ({} m).",
                s.reference.split(" (").next().unwrap_or(""),
                best.0,
                cell(Some(best.1), 2),
                worst.0,
                cell(Some(worst.1), 2)
            )
        }
        (Some(best), _) => {
            first += &format!(
                ", {}'s position error stays below {} m.",
                best.0,
                cell(Some(best.1), 2)
            )
        }
        _ => first += ", no method ran to the end.",
    }
    out.push(first);
    if !unstable.is_empty() {
        out.push(format!("Blew up: {}.", unstable.join("; ")));
    }
    let drift = bs
        .iter()
        .filter(|b| b.status == "ok")
        .filter_map(|b| b.max_energy_drift.map(|d| (b, d)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((b, d)) = drift.filter(|(_, d)| *d > 0.01) {
        out.push(format!(
            "{} moves its energy account by up to {} of the scene's energy scale.",
            b.backend,
            pct(d)
        ));
    }
    let lims: Vec<String> = bs
        .iter()
        .filter(|b| b.stability.is_some())
        .map(|b| format!("{} {}", b.backend, limit_words(b)))
        .collect();
    if !lims.is_empty() {
        out.push(format!("Stable steps: {}.", lims.join("; ")));
    }
    let contacts: Vec<String> = bs
        .iter()
        .filter_map(|b| match (b.restitution_measured, b.restitution_expected) {
            (Some(m), Some(e)) => Some(format!(
                "{} {} (specified {})",
                b.backend,
                cell(Some(m), 3),
                cell(Some(e), 3)
            )),
            _ => None,
        })
        .collect();
    if !contacts.is_empty() {
        out.push(format!("Measured restitution: {}.", contacts.join("; ")));
    }
    let tunnel: Vec<String> = bs
        .iter()
        .filter(|b| b.tunnelling.is_some_and(|t| t > 0))
        .map(|b| format!("{} ({})", b.backend, b.tunnelling.unwrap_or(0)))
        .collect();
    if !tunnel.is_empty() {
        out.push(format!("Paths through an obstacle: {}.", tunnel.join(", ")));
    }
    if !s.skipped.is_empty() {
        let names: Vec<&str> = s.skipped.iter().map(|(n, _)| n.as_str()).collect();
        out.push(format!("Not applicable here: {}.", names.join(", ")));
    }
    out.join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_read_as_fractions() {
        assert_eq!(dt_words(1.0 / 60.0), "1/60 s");
        assert_eq!(dt_words(0.01), "1/100 s");
        assert_eq!(dt_words(0.003), "0.00300 s");
    }
}
