//! The numbers the tables, the verdict and `summary.json` show, derived from
//! [`SceneResults`]: one row per backend and scene.

use super::finite::finite;
use super::results::{Scan, SceneResults, Sweep};
use crate::run::Status;
use serde::Serialize;

/// Errors below this (m) are round-off, left out of convergence fits.
pub const ROUNDOFF_FLOOR: f64 = 1e-13;

/// One backend's row in a scene's table and in the overview.
#[derive(Debug, Clone, Serialize)]
pub struct BackendSummary {
    /// Integrator or backend name.
    pub backend: String,
    /// Theoretical order.
    pub order: u32,
    /// `ok` or `unstable`.
    pub status: String,
    /// Time of the blow-up (s), when it blew up.
    pub blowup_time: Option<f64>,
    /// Which measure tripped, when it blew up.
    pub blowup_reason: Option<String>,
    /// Largest RMS position error against the reference over the run (m).
    pub max_position_error: Option<f64>,
    /// RMS position error at the last accepted step (m).
    pub final_position_error: Option<f64>,
    /// Largest |E(t) − E(0)| / E_scale over the run.
    pub max_energy_drift: Option<f64>,
    /// (E(end) − E(0)) / E_scale at the last accepted step, signed (gain > 0).
    pub final_energy_change: Option<f64>,
    /// Largest scanned h·ω below which every scanned step stayed bounded.
    pub stable_h_omega: Option<f64>,
    /// The same as a step (s).
    pub stable_dt: Option<f64>,
    /// True when even the smallest scanned step was unstable.
    pub unstable_at_every_scanned_step: bool,
    /// Least-squares convergence slope from the sweep.
    pub convergence_slope: Option<f64>,
    /// Mean measured restitution over impact events (scenes with obstacles).
    pub restitution_measured: Option<f64>,
    /// Mean specified restitution over the same events.
    pub restitution_expected: Option<f64>,
    /// Deepest penetration of any contact (m).
    pub max_penetration: Option<f64>,
    /// Paths that passed through an obstacle between two accepted states.
    pub tunnelling: Option<u64>,
    /// Force evaluations of the comparison run.
    pub force_evals: u64,
    /// Wall time in the integrator (s); varies from run to run.
    pub wall_seconds: f64,
}

/// One scene's summary.
#[derive(Debug, Clone, Serialize)]
pub struct SceneSummary {
    /// Scene name.
    pub scene: String,
    /// Scene description.
    pub description: String,
    /// Step of the comparison (s).
    pub dt: f64,
    /// Simulated time of the comparison (s).
    pub duration: f64,
    /// Reference of the comparison.
    pub reference: String,
    /// Reference of the sweep.
    pub sweep_reference: Option<String>,
    /// ω of the stability scan (rad/s).
    pub omega: Option<f64>,
    /// One row per backend.
    pub backends: Vec<BackendSummary>,
    /// Backends that refused the scene, with the reason.
    pub skipped: Vec<(String, String)>,
    /// The plain-language verdict.
    pub verdict: String,
    /// The scene page, relative to the report root.
    pub page: String,
}

/// The whole report's summary (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Which program wrote it.
    pub generator: String,
    /// True for a `--quick` pass.
    pub quick: bool,
    /// Per scene.
    pub scenes: Vec<SceneSummary>,
    /// Scenario files that could not be loaded, with the error.
    pub failed: Vec<(String, String)>,
}

/// Least-squares slope of log y on log x; `None` with fewer than two points.
pub fn loglog_slope(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx).and_then(finite)
}

/// The fitted convergence slope of one sweep line: stable points above the round-off floor,
/// the three finest (the asymptotic regime).
pub fn sweep_slope(sweep: &Sweep, integrator: &str) -> Option<f64> {
    let line = sweep.lines.iter().find(|l| l.integrator == integrator)?;
    let mut pts: Vec<(f64, f64)> = line
        .points
        .iter()
        .filter_map(|p| p.error.filter(|&e| e > ROUNDOFF_FLOOR).map(|e| (p.dt, e)))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts.truncate(3);
    loglog_slope(&pts)
}

/// (largest contiguous stable h·ω, its dt, unstable even at the smallest scanned step).
pub fn stable_limit(scan: &Scan, integrator: &str) -> (Option<f64>, Option<f64>, bool) {
    let Some(row) = scan.rows.iter().find(|r| r.integrator == integrator) else {
        return (None, None, false);
    };
    let mut best = None;
    for &(th, dt, st) in &row.cells {
        if !st {
            break;
        }
        best = Some((th, dt));
    }
    match best {
        Some((th, dt)) => (Some(th), Some(dt), false),
        None => (None, None, !row.cells.is_empty()),
    }
}

/// The summary of one scene (the verdict is filled in by [`super::verdict`]).
pub fn scene_summary(r: &SceneResults) -> SceneSummary {
    let backends = r
        .runs
        .iter()
        .map(|run| {
            let e0 = run.samples.first().map(|s| s.energy.total);
            let scale = r.energy_scale;
            let rel = |e: f64| e0.and_then(|e0| finite((e - e0) / scale));
            let max_drift = run
                .samples
                .iter()
                .filter_map(|s| rel(s.energy.total).map(f64::abs))
                .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
            let final_change = run.samples.last().and_then(|s| rel(s.energy.total));
            let errs: Vec<f64> = run
                .samples
                .iter()
                .filter_map(|s| s.pos_error.and_then(finite))
                .collect();
            let max_err = errs.iter().copied().reduce(f64::max);
            let final_err = run
                .samples
                .iter()
                .rev()
                .find_map(|s| s.pos_error.and_then(finite));
            let (blowup_time, blowup_reason) = match &run.status {
                Status::Unstable { time, reason, .. } => (Some(*time), Some(reason.clone())),
                Status::Ok => (None, None),
            };
            let (stable_h_omega, stable_dt, never) = r
                .scan
                .as_ref()
                .map_or((None, None, false), |s| stable_limit(s, &run.backend));
            BackendSummary {
                backend: run.backend.clone(),
                order: run.order,
                status: run.status.label().into(),
                blowup_time,
                blowup_reason,
                max_position_error: max_err,
                final_position_error: final_err,
                max_energy_drift: max_drift,
                final_energy_change: final_change,
                stable_h_omega,
                stable_dt,
                unstable_at_every_scanned_step: never,
                convergence_slope: r.sweep.as_ref().and_then(|s| sweep_slope(s, &run.backend)),
                restitution_measured: run
                    .contacts
                    .as_ref()
                    .filter(|c| c.restitution.count > 0)
                    .and_then(|c| finite(c.restitution.mean)),
                restitution_expected: run
                    .contacts
                    .as_ref()
                    .filter(|c| c.expected_restitution.count > 0)
                    .and_then(|c| finite(c.expected_restitution.mean)),
                max_penetration: run
                    .contacts
                    .as_ref()
                    .filter(|c| c.penetration.count > 0)
                    .and_then(|c| finite(c.penetration.max)),
                tunnelling: run.contacts.as_ref().map(|c| c.tunnelling_count),
                force_evals: run.force_evals,
                wall_seconds: run.wall_seconds,
            }
        })
        .collect();
    SceneSummary {
        scene: r.scene.clone(),
        description: r.description.clone(),
        dt: r.dt,
        duration: r.dt * r.steps as f64,
        reference: r.reference.clone(),
        sweep_reference: r.sweep.as_ref().map(|s| s.reference.clone()),
        omega: r.scan.as_ref().map(|s| s.omega),
        backends,
        skipped: r
            .skipped
            .iter()
            .map(|s| (s.backend.clone(), s.reason.clone()))
            .collect(),
        verdict: String::new(),
        page: format!("{}/index.html", r.scene),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_of_an_exact_power_law() {
        // y = 3 x^4 has log-log slope 4 exactly.
        let pts: Vec<(f64, f64)> = [0.1, 0.05, 0.025]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powi(4)))
            .collect();
        assert!((loglog_slope(&pts).unwrap() - 4.0).abs() < 1e-12);
        assert_eq!(loglog_slope(&pts[..1]), None);
    }
}
