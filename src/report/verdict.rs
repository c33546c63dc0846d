//! The one-paragraph, plain-language verdict of a scene, written from its summary's numbers
//! only (which are its documents' numbers).

use super::finite::{cell, percent};
use super::summary::{MethodRow, SceneSummary};
use crate::measure::answer::{FreeStep, GameRate};
use crate::measure::metric_table::{MAX_ENERGY_DRIFT, MAX_POSITION_ERROR};
use crate::measure::stability::Verdict;
use crate::measure::tolerance::Metric;

/// A step as people write it: `1/60 s` when 1/dt is a whole number, else decimals.
pub fn dt_words(dt: f64) -> String {
    let inv = 1.0 / dt;
    if inv.is_finite() && inv >= 1.0 && (inv - inv.round()).abs() < 1e-6 * inv {
        format!("1/{} s", inv.round() as u64)
    } else {
        format!("{} s", cell(Some(dt), 3))
    }
}

/// A frame rate as people write it: `60` for a whole number, else three significant digits.
fn hz_words(hz: f64) -> String {
    if hz.fract() == 0.0 && hz.abs() < 1e9 {
        format!("{hz:.0}")
    } else {
        cell(Some(hz), 3)
    }
}

/// A stability limit in words: `dt ≤ 0.0249 s`, `any step` (theory), `every step tried (up to
/// … s)` (an empirical search), `no step`, or `not analysed`.
pub fn limit_words(b: &MethodRow) -> String {
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

/// An answer's error against its bound, in words: `position error 2.1e-3 m ≤ 1.0e-2 m`, or for
/// statistics the score and what it stands for.
fn judged(metric: Metric, error: Option<f64>, bound: f64, position_tolerance: f64) -> String {
    let rel = match error {
        Some(e) if e <= bound => "≤",
        Some(_) => ">",
        None => "vs",
    };
    match metric {
        Metric::Position => format!(
            "position error {} m {rel} {} m",
            cell(error, 2),
            cell(Some(bound), 2)
        ),
        Metric::Statistics => format!(
            "statistics score {} {rel} 1: positions within {} m before the predictability horizon, every observable within the reference ensemble's spread after it",
            cell(error, 2),
            cell(Some(position_tolerance), 2)
        ),
        Metric::Impacts => format!(
            "apex heights, bounce by bounce, within {} m {rel} {} m of the reference's",
            cell(error, 2),
            cell(Some(bound), 2)
        ),
        m @ (Metric::Strain | Metric::Energy) => format!(
            "{} error {} {rel} {}",
            m.name(),
            cell(error, 2),
            cell(Some(bound), 2)
        ),
    }
}

/// How the front page's answers are judged, one sentence per rule (the HTML and Markdown
/// overviews both list these).
pub fn judging_notes(max_substeps: u64) -> Vec<String> {
    vec![
        format!("Tolerance: the scene's [run] tolerance, else {} % of its motion scale (the largest displacement of any particle over the run, as the reference measures it).", crate::measure::tolerance::RELATIVE_TOLERANCE * 100.0),
        "Position: the largest position error against the reference over its predictable range.".into(),
        format!("Statistics (chaotic scenes): past the reference's predictability horizon two correct solvers part by macroscopic amounts, so each run is compared with an ensemble of {} references started at the reference's own uncertainty: its time-mean centre of mass, radius of gyration, kinetic energy and largest strain must each lie within {} ensemble spreads plus what the tolerance allows (score ≤ 1), and its positions before the horizon within the tolerance.", crate::measure::statistics::ENSEMBLE_SIZE, crate::measure::statistics::SPREADS),
        "Impacts (scenes with obstacles and gravity): apex heights, bounce by bounce, against the reference's. A bounce a little early or late would show at equal times as about twice the impact speed times the lag; here it costs nothing if it reaches the right height, while a wrong restitution or a lost bounce does. Sliding across gravity is not judged by it (compare's position error shows it).".into(),
        format!("Game rate: the cheapest method and fewest substeps per frame (up to {max_substeps}) at {} Hz, or the scene's [run] hz, meeting the same bound. \"Stable only\" marks an answer where nothing met the bound: it shows the most accurate stable run and its error instead.", crate::measure::answer::GAME_HZ),
    ]
}

/// The free-step answer in words, labelled where it only reports what was verified.
pub fn free_words(a: &FreeStep) -> String {
    match (&a.method, a.dt) {
        (Some(m), Some(dt)) if a.meets => format!(
            "{m} at dt = {} ({})",
            dt_words(dt),
            judged(a.metric, a.error, a.tolerance, a.position_tolerance)
        ),
        (Some(m), Some(dt)) => format!(
            "{}: {m} at dt = {} ({})",
            a.verified,
            dt_words(dt),
            judged(a.metric, a.error, a.tolerance, a.position_tolerance)
        ),
        _ => a.verified.clone(),
    }
}

/// The game-rate answer in words, labelled where it only reports what was verified.
pub fn game_words(a: &GameRate) -> String {
    let per_frame = a.modelled_seconds_per_frame.map_or(String::new(), |w| {
        format!("; {} ms per frame, modelled", cell(Some(w * 1e3), 2))
    });
    match (&a.method, a.substeps) {
        (Some(m), Some(n)) if a.meets => format!(
            "{m} × {n} substep{} at {} Hz ({}{per_frame})",
            if n == 1 { "" } else { "s" },
            hz_words(a.hz),
            judged(a.metric, a.error, a.tolerance, a.position_tolerance)
        ),
        (Some(m), Some(n)) => format!(
            "{}: {m} × {n} at {} Hz ({}{per_frame})",
            a.verified,
            hz_words(a.hz),
            judged(a.metric, a.error, a.tolerance, a.position_tolerance)
        ),
        _ => a.verified.clone(),
    }
}

/// The sentence that answers "what should I use here?".
pub fn pick_sentence(s: &SceneSummary) -> Option<String> {
    let a = s.answer.as_ref()?;
    Some(format!(
        "With a free step: {}. At {} Hz: {}.",
        free_words(&a.free_step),
        hz_words(a.game_rate.hz),
        game_words(&a.game_rate)
    ))
}

/// A scene's answer on the front page, as plain text: what to use at a free step and at the
/// game rate, each analysed method's stable step, and what blew up at the scene's step. The
/// HTML and Markdown overviews both render this one row.
#[derive(Debug, Clone, PartialEq)]
pub struct FrontRow {
    /// The free-step answer.
    pub free: String,
    /// The game-rate answer.
    pub game: String,
    /// `method: limit` per analysed method.
    pub limits: Vec<String>,
    /// `method at t = … s` per run that blew up.
    pub blew: Vec<String>,
    /// How the best Rapier method fares at the game rate beside the answer.
    pub rapier: String,
}

/// The front-page row of a scene.
pub fn front_row(s: &SceneSummary) -> FrontRow {
    let (free, game) = match &s.answer {
        Some(a) => (free_words(&a.free_step), game_words(&a.game_rate)),
        None => ("not measured".into(), "not measured".into()),
    };
    let stale = |t: String| match &s.failed_this_time {
        Some(_) => format!("(from the previous report; this one failed on the scene) {t}"),
        None => t,
    };
    let rapier = match &s.answer {
        Some(a) => match &a.engine {
            Some(f) => super::game_rate::words(f, &a.game_rate),
            None => "no Rapier method ran at this rate".into(),
        },
        None => "not measured".into(),
    };
    FrontRow {
        free: stale(free),
        game: stale(game),
        rapier: stale(rapier),
        limits: s
            .methods
            .iter()
            .filter(|b| b.stability.is_some())
            .map(|b| format!("{}: {}", b.method, limit_words(b)))
            .collect(),
        blew: s
            .methods
            .iter()
            .filter(|b| !b.status.is_ok())
            .map(|b| format!("{} at t = {} s", b.method, cell(b.blowup_time, 3)))
            .collect(),
    }
}

/// The paragraph for one scene: its sentences in order, each from one part of the summary.
pub fn verdict(s: &SceneSummary) -> String {
    let bs = &s.methods;
    [
        pick_sentence(s),
        judged_by_sentence(s).map(String::from),
        Some(accuracy_sentence(s)),
        blew_up_sentence(bs),
        drift_sentence(bs),
        stable_steps_sentence(bs),
        restitution_sentence(bs),
        tunnelling_sentence(bs),
        not_applicable_sentence(s),
    ]
    .into_iter()
    .flatten()
    .collect::<Vec<_>>()
    .join(" ")
}

/// What accuracy is judged by, on a scene where it is not position at equal times.
fn judged_by_sentence(s: &SceneSummary) -> Option<&'static str> {
    match s.answer.as_ref().map(|a| a.free_step.metric) {
        Some(Metric::Impacts) => Some("On this bouncing scene accuracy is judged by apex heights, bounce by bounce, against the reference's, not by position at equal times: a bounce a little early or late would dominate that (about twice the impact speed times the lag) while reaching the right height."),
        Some(Metric::Statistics) => Some("This scene is chaotic: past the reference's predictability horizon position error measures the chaos, not the method, so each run is judged there by its time-mean centre of mass, radius of gyration, kinetic energy and strain against an ensemble of references."),
        _ => None,
    }
}

/// The most and least accurate methods that ran to the end at the scene's step.
fn accuracy_sentence(s: &SceneSummary) -> String {
    let mut first = format!(
        "At dt = {} over {} s",
        dt_words(s.dt),
        cell(Some(s.duration), 3)
    );
    let mut acc: Vec<(&str, f64)> = s
        .methods
        .iter()
        .filter(|b| b.status.is_ok() && b.order != crate::method::Order::Exact)
        .filter_map(|b| {
            b.metrics
                .get(MAX_POSITION_ERROR)
                .map(|e| (b.method.as_str(), e))
        })
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
    first
}

/// The runs that blew up, with when and why.
fn blew_up_sentence(bs: &[MethodRow]) -> Option<String> {
    let unstable: Vec<String> = bs
        .iter()
        .filter(|b| !b.status.is_ok())
        .map(|b| {
            format!(
                "{} (t = {} s: {})",
                b.method,
                cell(b.blowup_time, 3),
                b.blowup_reason.as_deref().unwrap_or("unstable")
            )
        })
        .collect();
    (!unstable.is_empty()).then(|| format!("Blew up: {}.", unstable.join("; ")))
}

/// The largest energy drift of a run that ended, when it passes 1 % of the energy scale.
fn drift_sentence(bs: &[MethodRow]) -> Option<String> {
    let drift = bs
        .iter()
        .filter(|b| b.status.is_ok())
        .filter_map(|b| b.metrics.get(MAX_ENERGY_DRIFT).map(|d| (b, d)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    drift.filter(|(_, d)| *d > 0.01).map(|(b, d)| {
        format!(
            "{} moves its energy account by up to {} of the scene's energy scale.",
            b.method,
            percent(Some(d), 2)
        )
    })
}

/// Each analysed method's stable step.
fn stable_steps_sentence(bs: &[MethodRow]) -> Option<String> {
    let lims: Vec<String> = bs
        .iter()
        .filter(|b| b.stability.is_some())
        .map(|b| format!("{} {}", b.method, limit_words(b)))
        .collect();
    (!lims.is_empty()).then(|| format!("Stable steps: {}.", lims.join("; ")))
}

/// Each method's measured restitution beside the specified one.
fn restitution_sentence(bs: &[MethodRow]) -> Option<String> {
    let contacts: Vec<String> = bs
        .iter()
        .filter_map(|b| match (b.restitution_measured, b.restitution_expected) {
            (Some(m), Some(e)) => Some(format!(
                "{} {} (specified {})",
                b.method,
                cell(Some(m), 3),
                cell(Some(e), 3)
            )),
            _ => None,
        })
        .collect();
    (!contacts.is_empty()).then(|| format!("Measured restitution: {}.", contacts.join("; ")))
}

/// The methods with paths through an obstacle, and how many each.
fn tunnelling_sentence(bs: &[MethodRow]) -> Option<String> {
    let tunnel: Vec<String> = bs
        .iter()
        .filter(|b| b.tunnelling.is_some_and(|t| t > 0))
        .map(|b| format!("{} ({})", b.method, b.tunnelling.unwrap_or(0)))
        .collect();
    (!tunnel.is_empty()).then(|| format!("Paths through an obstacle: {}.", tunnel.join(", ")))
}

/// The methods that do not apply to the scene.
fn not_applicable_sentence(s: &SceneSummary) -> Option<String> {
    (!s.skipped.is_empty()).then(|| {
        let names: Vec<&str> = s.skipped.iter().map(|(n, _)| n.as_str()).collect();
        format!("Not applicable here: {}.", names.join(", "))
    })
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
