//! The rows the pages, the verdict and `summary.json` show, read off a [`SceneStudy`]: each
//! number is the one its document holds (compare's metrics, the stability report's limit, the
//! sweep's fitted order, the advice's pick), never recomputed here.

use super::finite::finite;
use crate::measure::metric_table::RowMetrics;
use crate::measure::stability::Verdict;
use crate::measure::study::SceneStudy;
use crate::method::{Order, Registry};
use serde::{Deserialize, Serialize};

/// One method's row in a scene's table and in the overview.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MethodRow {
    /// Method name.
    #[serde(alias = "backend")]
    pub method: String,
    /// Theoretical order: a number, or `"exact"`.
    pub order: Order,
    /// `ok` or `unstable`.
    pub status: crate::run::RunStatus,
    /// Time of the blow-up (s), when it blew up.
    pub blowup_time: Option<f64>,
    /// Which measure tripped, when it blew up.
    pub blowup_reason: Option<String>,
    /// The run's values of the metrics table's row metrics ([`RowMetrics`]: largest and
    /// final position error, energy error, drift rate, strain, penetration, rest jitter),
    /// each under its own key.
    #[serde(flatten)]
    pub metrics: RowMetrics,
    /// The stability report's verdict, when it was analysed.
    pub stability: Option<Verdict>,
    /// The stability report's largest stable step (s).
    pub stable_dt: Option<f64>,
    /// The same as h·ω_max.
    pub stable_h_omega: Option<f64>,
    /// How the stability limit was decided (`spectral_radius`, `empirical_bisection`, ...).
    #[serde(alias = "stability_method")]
    pub stability_decided_by: Option<String>,
    /// For an empirical "stable at every step", the largest step the search tried (s): the
    /// claim holds up to there, not beyond.
    pub stable_up_to_tried: Option<f64>,
    /// The sweep's observed order (null when the asymptotic range was not reached).
    pub observed_order: Option<f64>,
    /// Why there is no observed order, when the sweep ran this method.
    pub order_note: Option<String>,
    /// Mean measured restitution over impact events (scenes with obstacles).
    pub restitution_measured: Option<f64>,
    /// Mean specified restitution over the same events.
    pub restitution_expected: Option<f64>,
    /// Paths that passed through an obstacle between two accepted states.
    pub tunnelling: Option<u64>,
    /// Force evaluations of the comparison run (null for methods that never evaluate ours).
    pub force_evals: Option<u64>,
    /// Modelled seconds of the comparison run ([`crate::run::cost`]); 0 in a summary read
    /// back from before it was recorded.
    #[serde(default)]
    pub modelled_seconds: f64,
    /// Stepping wall time (s); varies from run to run, so documents keep it in
    /// `timing.json` (0 when that file is gone).
    #[serde(default)]
    pub wall_seconds: f64,
}

/// A document of the scene folder, the command that re-creates it, and what it holds.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Document {
    /// File name in the scene folder.
    pub file: String,
    /// The command line that re-creates it.
    pub command: String,
}

/// One scene's summary.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SceneSummary {
    /// Scene name.
    pub scene: String,
    /// Scene description.
    pub description: String,
    /// Step of the comparison (s).
    pub dt: f64,
    /// Simulated time of the comparison (s).
    pub duration: f64,
    /// Reference of the comparison, in words.
    pub reference: String,
    /// Highest linearised frequency (rad/s), when the scene has one.
    pub omega_max: Option<f64>,
    /// What to use, at a free step and at the game's frame rate (the study's
    /// [`crate::measure::answer`]); null only in rows of an older report.
    #[serde(default)]
    pub answer: Option<crate::measure::answer::Answer>,
    /// One row per method that ran.
    #[serde(alias = "backends")]
    pub methods: Vec<MethodRow>,
    /// Methods that refused the scene, with the reason.
    pub skipped: Vec<(String, String)>,
    /// The plain-language verdict.
    pub verdict: String,
    /// The scene page, relative to the report root.
    pub page: String,
    /// The documents behind the page.
    pub documents: Vec<Document>,
    /// What took part where, and what was left out.
    pub notes: Vec<String>,
    /// Wall time of each part of the study (s): where the report's time went (documents keep
    /// it in `timing.json`).
    #[serde(default, rename = "wall_seconds", alias = "seconds")]
    pub seconds: crate::measure::study::StudySeconds,
    /// The scenario file's name, by which a later report recognises the scene if it cannot
    /// load it.
    #[serde(default)]
    pub file: String,
    /// Set when the latest report could not study the scene and kept this earlier row and
    /// folder: why it failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failed_this_time: Option<String>,
    /// The chart of every method at the game rate (error against cost, Rapier marked, the
    /// answer ringed), relative to the report root; `None` without a frame-rate table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub game_rate_chart: Option<String>,
}

/// The whole report's summary (`summary.json`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Summary {
    /// Which program wrote it.
    pub generator: String,
    /// True for a `--quick` pass.
    pub quick: bool,
    /// Per scene.
    pub scenes: Vec<SceneSummary>,
    /// Scenario files that could not be loaded, with the error.
    pub failed: Vec<(String, String)>,
    /// The Small Steps page, when the report has one.
    #[serde(default)]
    pub small_steps: Option<SmallStepsLink>,
}

/// The reference of a comparison in words: its kind and description.
pub fn reference_words(s: &SceneStudy) -> String {
    let r = &s.compare.reference;
    format!("{} ({})", r.kind, r.description)
}

/// The summary of one scene's study (the verdict is filled in by `report::verdict`).
pub fn scene_summary(
    s: &SceneStudy,
    registry: &Registry,
    documents: Vec<Document>,
) -> crate::error::Result<SceneSummary> {
    let mut methods = Vec::new();
    let mut skipped = Vec::new();
    for e in &s.compare.entries {
        let Some(r) = &e.result else {
            skipped.push((e.method.clone(), e.skip_reason.clone().unwrap_or_default()));
            continue;
        };
        // Every compared method came from this registry; a mismatch is the caller's error.
        let info = registry.info(&r.method)?;
        let stab = s.stability.methods.iter().find(|i| i.method == r.method);
        let fit = s.sweep.as_ref().and_then(|sw| {
            sw.summary
                .as_ref()?
                .methods
                .iter()
                .find(|i| i.method == r.method)
        });
        let contacts = r.contacts.as_ref();
        methods.push(MethodRow {
            method: r.method.clone(),
            order: info.order,
            status: r.status,
            blowup_time: r.unstable_time,
            blowup_reason: r.unstable_reason.clone(),
            metrics: RowMetrics::of(r.metrics.as_ref()),
            stability: stab.map(|i| i.verdict),
            stable_dt: stab.and_then(|i| i.max_stable_dt),
            stable_h_omega: stab.and_then(|i| i.h_omega),
            stability_decided_by: stab.map(|i| i.decided_by.name().to_string()),
            stable_up_to_tried: stab
                .filter(|i| {
                    i.decided_by == crate::measure::stability::DecidedBy::EmpiricalBisection
                        && i.verdict == Verdict::UnconditionallyStable
                })
                .map(|_| s.stability.empirical_criterion.dt_max),
            observed_order: fit.and_then(|f| f.observed_order),
            order_note: fit.and_then(|f| f.fit.note.clone()),
            restitution_measured: contacts
                .filter(|c| c.restitution.count > 0)
                .and_then(|c| finite(c.restitution.mean)),
            restitution_expected: contacts
                .filter(|c| c.expected_restitution.count > 0)
                .and_then(|c| finite(c.expected_restitution.mean)),
            tunnelling: contacts.map(|c| c.tunnelling_count),
            force_evals: (info.cost == crate::method::CostUnit::ForceEvaluations)
                .then_some(r.force_evals),
            modelled_seconds: r.modelled_seconds,
            wall_seconds: r.wall_seconds,
        });
    }
    Ok(SceneSummary {
        scene: s.scenario.clone(),
        description: s.description.clone(),
        dt: s.compare.dt,
        duration: s.compare.duration,
        reference: reference_words(s),
        omega_max: (s.stability.omega_max > 0.0).then_some(s.stability.omega_max),
        answer: Some(s.answer.clone()),
        methods,
        skipped,
        verdict: String::new(),
        page: format!("{}/index.html", s.scenario),
        documents,
        notes: s.notes.iter().chain(&s.framerate_notes).cloned().collect(),
        seconds: s.seconds,
        file: String::new(),
        failed_this_time: None,
        game_rate_chart: s
            .framerate
            .as_ref()
            .map(|_| format!("{}/{}.svg", s.scenario, super::game_rate::GAME_RATE_STEM)),
    })
}

/// What the overview says of the Small Steps page.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SmallStepsLink {
    /// The page, relative to the report root.
    pub page: String,
    /// One verdict per scene.
    pub verdicts: Vec<String>,
}
