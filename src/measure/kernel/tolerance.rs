//! The tolerance a scene's answers are held to, and the metrics an answer can be judged by.
//!
//! Tolerance: the scene's `[run] tolerance` (m of position error) when it gives one, else
//! [`RELATIVE_TOLERANCE`] (1 %) of its motion scale: the largest displacement of any particle
//! from its start over the run, as the reference measures it. The motion, not the geometry,
//! because an error is seen against what moves: a 1 mm oscillation of a 1 m spring held to
//! 1 cm would pass any method that kept it still.
//!
//! Metrics ([`Metric`]), each giving one error per run from its [`Metrics`]:
//! - `position`: the largest position error before the reference's predictability horizon
//!   (all of the run where it is predictable), m, against the tolerance;
//! - `strain`: |strain max − the solution's strain max|, against the tolerance relative to the
//!   motion scale (1 % by default): over- or under-stretching;
//! - `energy`: the largest |relative energy error|, against the relative tolerance;
//! - `impacts`: on a scene with obstacles and gravity, the largest |apex height − the
//!   reference's| over matched bounces (m; [`crate::measure::apexes`]), against the tolerance: a
//!   bounce a little early or late, which moves position error at equal times by twice the
//!   impact speed times the lag, costs nothing if it reaches the right height;
//! - `statistics`: the worst of (position error before the horizon / tolerance) and every
//!   observable's score against the reference's ensemble past it
//!   ([`crate::measure::statistics`]), against 1: what can be verified of a chaotic scene over its
//!   whole duration.
//!
//! Past the horizon position error measures the chaos, not the method, so [`default_metric`]
//! is `statistics` where the reference has a horizon before the run's end, `impacts` on other
//! scenes with obstacles and gravity, and `position` elsewhere.

use crate::error::{Error, Result};
use crate::measure::metrics::Metrics;
use crate::measure::reference::ReferenceInfo;
use serde::Serialize;

pub use crate::measure::observables::RELATIVE_TOLERANCE;

/// What an answer is judged by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// Largest position error over the predictable range (m).
    Position,
    /// |strain max − the solution's|.
    Strain,
    /// Largest |relative energy error|.
    Energy,
    /// Position before the horizon and the ensemble's statistics past it (scores, ≤ 1).
    Statistics,
    /// Apex heights bounce by bounce (m).
    Impacts,
}

impl Metric {
    /// The name used in flags and documents.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Position => "position",
            Metric::Strain => "strain",
            Metric::Energy => "energy",
            Metric::Statistics => "statistics",
            Metric::Impacts => "impacts",
        }
    }

    /// The error of a run's metrics by this metric, with the position tolerance `tolerance`
    /// (m); None where the metric cannot be read (statistics without an ensemble window).
    pub fn error(self, m: &Metrics, tolerance: f64) -> Option<f64> {
        match self {
            Metric::Position => Some(m.error_max_predictable),
            Metric::Strain => Some(m.strain_error),
            Metric::Energy => Some(m.energy_error_max),
            // Nothing bounced: nothing hides behind an impact's timing.
            Metric::Impacts => Some(m.apex_error.unwrap_or(m.error_max_predictable)),
            Metric::Statistics => {
                let stats = m.statistics.as_ref()?;
                Some(
                    (m.error_max_predictable / tolerance)
                        .max(crate::measure::statistics::worst_score(stats)),
                )
            }
        }
    }

    /// The bound the error is held to, given the position tolerance (m) and the motion scale
    /// (m).
    pub fn bound(self, tolerance: f64, motion_scale: f64) -> f64 {
        match self {
            Metric::Position | Metric::Impacts => tolerance,
            Metric::Strain | Metric::Energy => tolerance / motion_scale,
            Metric::Statistics => 1.0,
        }
    }

    /// The bound's unit, for documents.
    pub fn unit(self) -> &'static str {
        match self {
            Metric::Position | Metric::Impacts => "m",
            Metric::Strain => "strain",
            Metric::Energy => "relative energy",
            Metric::Statistics => "score (1 = the ensemble's allowance)",
        }
    }
}

impl std::str::FromStr for Metric {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "position" => Ok(Metric::Position),
            "strain" => Ok(Metric::Strain),
            "energy" => Ok(Metric::Energy),
            "statistics" => Ok(Metric::Statistics),
            "impacts" => Ok(Metric::Impacts),
            _ => Err(Error::option(
                "--metric",
                format!("expected position, strain, energy, statistics or impacts, got '{s}'"),
            )),
        }
    }
}

/// The metric an answer uses unless asked: `statistics` past a predictability horizon before
/// the run's end, else `impacts` on a `bouncing` scene (obstacles and gravity), else
/// `position`.
pub fn default_metric(reference: &ReferenceInfo, bouncing: bool) -> Metric {
    match reference.predictability_horizon {
        Some(h) if h < reference.horizon => Metric::Statistics,
        _ if bouncing => Metric::Impacts,
        _ => Metric::Position,
    }
}

/// A resolved position tolerance and where it came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tolerance {
    /// Position tolerance (m).
    pub value: f64,
    /// Where it came from, in words.
    pub source: String,
}

/// The tolerance of a scene: `asked` (a flag), else `scene` (`[run] tolerance`), else
/// [`RELATIVE_TOLERANCE`] × `motion_scale`.
pub fn resolve(asked: Option<f64>, scene: Option<f64>, motion_scale: f64) -> Tolerance {
    match (asked, scene) {
        (Some(v), _) => Tolerance {
            value: v,
            source: "--tolerance".into(),
        },
        (None, Some(v)) => Tolerance {
            value: v,
            source: "the scene's [run] tolerance".into(),
        },
        (None, None) => Tolerance {
            value: RELATIVE_TOLERANCE * motion_scale,
            source: format!(
                "{} % of the motion scale {} m (the largest displacement of any particle over the run, by the reference)",
                RELATIVE_TOLERANCE * 100.0,
                crate::error::significant(motion_scale, 3)
            ),
        },
    }
}

/// Checks a tolerance flag's value.
pub fn check(asked: Option<f64>) -> Result<()> {
    match asked {
        Some(t) if !(t.is_finite() && t > 0.0) => Err(Error::option(
            "--tolerance",
            format!("must be a finite number > 0, got {}", crate::error::num(t)),
        )),
        _ => Ok(()),
    }
}

/// What a document's answers were judged by, as every judging document writes it (flattened
/// into `advice.json` and `framerate.json`): the bound, the metric, the position tolerance and
/// why the metric is not the default one, when it is not.
#[derive(Debug, Clone, Serialize)]
pub struct JudgedBy {
    /// The bound every run's error is held to, in the metric's unit ([`Judge::bound`]).
    pub tolerance: f64,
    /// The metric that decided.
    pub metric: Metric,
    /// The position tolerance (m) and where it came from.
    pub position_tolerance: Tolerance,
    /// Why the metric differs from the default one, when it does (an ensemble that could not
    /// be made).
    pub metric_note: Option<String>,
}

impl JudgedBy {
    /// The sentence every command prints: "judged by statistics (bound 1 score; position
    /// tolerance 0.02285 m: 1 % of the motion scale …)", its figures with four significant
    /// digits.
    pub fn describe(&self) -> String {
        format!(
            "judged by {} (bound {} {}; position tolerance {} m: {})",
            self.metric.name(),
            crate::error::significant(self.tolerance, 4),
            self.metric.unit(),
            crate::error::significant(self.position_tolerance.value, 4),
            self.position_tolerance.source
        )
    }

    /// What `judge` judged by, with the metric's note.
    pub fn of(judge: &Judge, metric_note: Option<String>) -> Self {
        JudgedBy {
            tolerance: judge.bound,
            metric: judge.metric,
            position_tolerance: judge.tolerance.clone(),
            metric_note,
        }
    }
}

/// How runs are judged: a metric, the position tolerance and the bound the metric's error is
/// held to. One value carried through a command, so every run of it is judged alike.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Judge {
    /// The metric.
    pub metric: Metric,
    /// The position tolerance and where it came from.
    pub tolerance: Tolerance,
    /// The bound the metric's error is held to ([`Metric::bound`]), in [`Judge::unit`].
    pub bound: f64,
    /// The bound's unit.
    pub unit: &'static str,
}

impl Judge {
    /// The judge of `metric` (default [`default_metric`]) at tolerance `asked` (else the
    /// scene's, else the default) on a scene whose reference is `reference`; `bouncing` as
    /// [`crate::measure::metrics::bouncing`].
    pub fn new(
        metric: Option<Metric>,
        asked: Option<f64>,
        scene: Option<f64>,
        reference: &ReferenceInfo,
        bouncing: bool,
    ) -> Self {
        let metric = metric.unwrap_or_else(|| default_metric(reference, bouncing));
        // Never 0: the reference's motion scale is 1 m where nothing moves.
        let motion = reference.motion_scale;
        let tolerance = resolve(asked, scene, motion);
        Judge {
            metric,
            bound: metric.bound(tolerance.value, motion),
            unit: metric.unit(),
            tolerance,
        }
    }

    /// The error of a run by the metric; None for a run that is not ok or where the metric
    /// cannot be read.
    pub fn error(&self, c: &crate::measure::case::CaseResult) -> Option<f64> {
        c.metrics
            .as_ref()
            .and_then(|m| self.metric.error(m, self.tolerance.value))
    }

    /// The part of the judgement a run can fail before it ends, as `(divisor, bound)`: the
    /// largest position error before the predictability horizon, over `divisor`, must stay
    /// within `bound`; it only grows, so a run past it is failed for good
    /// (`MetricsObserver::stop_past`). `None` where the error can still fall
    /// (strain, energy, apex heights).
    pub fn position_stop(&self) -> Option<(f64, f64)> {
        match self.metric {
            Metric::Position => Some((1.0, self.bound)),
            Metric::Statistics => Some((self.tolerance.value, self.bound)),
            Metric::Strain | Metric::Energy | Metric::Impacts => None,
        }
    }

    /// True when the run is ok and its error is within the bound.
    pub fn meets(&self, c: &crate::measure::case::CaseResult) -> bool {
        self.error(c).is_some_and(|e| e <= self.bound)
    }

    /// One line for people: metric, bound and where the tolerance came from.
    pub fn describe(&self) -> String {
        match self.metric {
            Metric::Position => format!(
                "position error within {} m ({})",
                crate::error::significant(self.bound, 3),
                self.tolerance.source
            ),
            Metric::Impacts => format!(
                "apex heights bounce by bounce within {} m of the reference's ({})",
                crate::error::significant(self.bound, 3),
                self.tolerance.source
            ),
            Metric::Statistics => format!(
                "position error within {} m before the predictability horizon and every observable within the reference ensemble's allowance past it (tolerance: {})",
                crate::error::significant(self.tolerance.value, 3),
                self.tolerance.source
            ),
            m => format!(
                "{} error within {} (the tolerance {} m over the motion scale; {})",
                m.name(),
                crate::error::significant(self.bound, 3),
                crate::error::significant(self.tolerance.value, 3),
                self.tolerance.source
            ),
        }
    }
}

/// The judge of a command on `reference` (of `scene`'s `sys` from `s0`), giving the reference
/// the scene's ensemble the statistics metric needs: `prepared` when the caller has the one
/// made on the scene's grid over this horizon, else computed. With the metric left to its default, a scene whose ensemble cannot be made
/// is judged by position over its predictable range, and the returned note says why; asked
/// for by name, statistics without an ensemble is an error.
pub fn decide(
    metric: Option<Metric>,
    asked: Option<f64>,
    scene: &crate::scenario::Scenario,
    reference: &mut crate::measure::reference::Reference,
    sys: &crate::model::System,
    s0: &crate::model::State,
    prepared: Option<&crate::measure::statistics::Ensemble>,
) -> Result<(Judge, Option<String>)> {
    let scene_tolerance = scene.run.tolerance;
    let bouncing = crate::measure::observables::bouncing(sys);
    let judge = Judge::new(metric, asked, scene_tolerance, &reference.info, bouncing);
    if judge.metric == Metric::Impacts && !bouncing {
        return Err(Error::option(
            "--metric",
            "impacts need a scene with obstacles and gravity (bounces to compare)",
        ));
    }
    if judge.metric != Metric::Statistics {
        return Ok((judge, None));
    }
    // An ensemble made beforehand serves when it is the scene's on the same grid.
    let scene_grid = crate::measure::grid::scene_grid(scene, sys.len(), reference.info.horizon)?;
    match prepared.filter(|e| e.grid == Some(scene_grid)) {
        Some(e) => reference.use_ensemble(e, judge.tolerance.value),
        None => reference.add_ensemble(sys, s0, judge.tolerance.value, scene_grid)?,
    }
    if reference.ensemble.is_some() {
        return Ok((judge, None));
    }
    let why = reference
        .info
        .ensemble
        .clone()
        .unwrap_or_else(|| "the reference is predictable over the whole run".into());
    if metric.is_some() {
        return Err(Error::option(
            "--metric",
            format!(
                "statistics need an ensemble past the reference's predictability horizon: {why}"
            ),
        ));
    }
    let fallback = if bouncing {
        Metric::Impacts
    } else {
        Metric::Position
    };
    let judge = Judge::new(
        Some(fallback),
        asked,
        scene_tolerance,
        &reference.info,
        bouncing,
    );
    Ok((
        judge,
        Some(format!("{} instead of statistics: {why}", fallback.name())),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the derived tolerance of a 2.285 m motion, 1 % of it, as `resolve` gives it
    // (0.02285174991857634 m), and the rule of `error::significant`: four digits, plain
    // between 1e-3 and 1e5.
    #[test]
    fn the_judged_sentence_prints_four_significant_digits() {
        let judged = JudgedBy {
            tolerance: 1.0,
            metric: Metric::Position,
            position_tolerance: resolve(None, None, 2.285174991857634),
            metric_note: None,
        };
        let s = judged.describe();
        assert!(s.contains("position tolerance 0.02285 m"), "{s}");
        assert!(!s.contains("0.0228517"), "{s}");
    }
}
