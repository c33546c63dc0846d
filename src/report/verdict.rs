//! The one-paragraph, plain-language verdict of a scene, generated from its numbers only.

use super::finite::cell;
use super::results::SceneResults;
use super::summary::{BackendSummary, SceneSummary};

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

fn is_reference(s: &SceneSummary, b: &BackendSummary) -> bool {
    // Only an exact reference run at the same step is the reference itself.
    s.reference.starts_with(&format!("{} (exact", b.backend))
}

/// Force evaluations a line needs to reach `target` error, interpolated log-log between the
/// sweep points that bracket it; `None` when the line never gets that low.
fn evals_for(points: &[(f64, f64)], target: f64) -> Option<f64> {
    // points: (evals, error), sorted by evals.
    if points.iter().all(|p| p.1 > target) {
        return None;
    }
    if points[0].1 <= target {
        return Some(points[0].0);
    }
    points.windows(2).find_map(|w| {
        let ((e0, r0), (e1, r1)) = (w[0], w[1]);
        (r1 <= target && r0 > target).then(|| {
            let f = (target.ln() - r0.ln()) / (r1.ln() - r0.ln());
            (e0.ln() + f * (e1.ln() - e0.ln())).exp()
        })
    })
}

/// The sentence on cost: who reaches a small error with the fewest force evaluations.
fn work_sentence(r: &SceneResults) -> Option<String> {
    let sweep = r.sweep.as_ref()?;
    let lines: Vec<(String, Vec<(f64, f64)>)> = sweep
        .lines
        .iter()
        .map(|l| {
            let mut p: Vec<(f64, f64)> = l
                .points
                .iter()
                .filter_map(|p| {
                    p.error
                        .filter(|e| e.is_finite() && *e > 0.0)
                        .map(|e| (p.force_evals as f64, e))
                })
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            (l.integrator.clone(), p)
        })
        .filter(|(_, p)| !p.is_empty())
        .collect();
    // The smallest decade of error at least two integrators reach.
    let mut target = None;
    for k in (-14..=1).map(|k| 10f64.powi(k)) {
        if lines
            .iter()
            .filter(|(_, p)| evals_for(p, k).is_some())
            .count()
            >= 2
        {
            target = Some(k);
            break;
        }
    }
    let target = target?;
    let mut costs: Vec<(&str, f64)> = lines
        .iter()
        .filter_map(|(n, p)| evals_for(p, target).map(|e| (n.as_str(), e)))
        .collect();
    costs.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (best, e) = costs[0];
    let (second, e2) = costs[1];
    Some(format!(
        "To reach an end-point error of {} m over {} s, {best} needs the fewest force evaluations (about {}, against {} for {second}).",
        cell(Some(target), 1),
        cell(Some(sweep.duration), 3),
        cell(Some(e), 2),
        cell(Some(e2), 2)
    ))
}

/// The paragraph for one scene.
pub fn verdict(s: &SceneSummary, r: &SceneResults) -> String {
    let mut out = Vec::new();
    let bs: Vec<&BackendSummary> = s.backends.iter().collect();
    // Energy.
    let worst = bs
        .iter()
        .filter_map(|b| b.final_energy_change.map(|c| (b, c)))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
    let steadiest = bs
        .iter()
        .filter(|b| !is_reference(s, b) && b.status == "ok")
        .filter_map(|b| b.max_energy_drift.map(|d| (b, d)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let mut first = format!(
        "At dt = {} over {} s",
        dt_words(s.dt),
        cell(Some(s.duration), 3)
    );
    match (worst, steadiest) {
        (Some((w, c)), Some((b, d))) if w.backend != b.backend => {
            first += &format!(
                ", {} {} {} of the energy scale{}; {} {} {}.",
                w.backend,
                if c >= 0.0 { "gains" } else { "loses" },
                pct(c.abs()),
                w.blowup_time.map_or(String::new(), |t| format!(
                    " before it blows up at t = {} s",
                    cell(Some(t), 3)
                )),
                b.backend,
                if d < 0.1 {
                    "stays within"
                } else {
                    "is the steadiest and still moves it by"
                },
                pct(d)
            )
        }
        (_, Some((b, d))) => {
            first += &format!(
                ", every backend keeps its energy account within {} ({} best).",
                pct(bs
                    .iter()
                    .filter_map(|b| b.max_energy_drift)
                    .fold(d, f64::max)),
                b.backend
            )
        }
        _ => first += ", no backend ran to completion.",
    }
    out.push(first);
    // Blow-ups.
    let unstable: Vec<&&BackendSummary> = bs.iter().filter(|b| b.status != "ok").collect();
    if !unstable.is_empty() {
        let names: Vec<String> = unstable
            .iter()
            .map(|b| format!("{} (t = {} s)", b.backend, cell(b.blowup_time, 3)))
            .collect();
        out.push(format!("Blew up: {}.", names.join(", ")));
    }
    // Accuracy.
    let mut acc: Vec<(&str, f64)> = bs
        .iter()
        .filter(|b| !is_reference(s, b) && b.status == "ok")
        .filter_map(|b| b.max_position_error.map(|e| (b.backend.as_str(), e)))
        .collect();
    acc.sort_by(|a, b| a.1.total_cmp(&b.1));
    if let (Some(best), Some(worst)) = (acc.first(), acc.last()) {
        if best.0 != worst.0 {
            out.push(format!(
                "Against {}, {} is the most accurate (position error at most {} m) and {} the least ({} m).",
                s.reference, best.0, cell(Some(best.1), 2), worst.0, cell(Some(worst.1), 2)
            ));
        } else {
            out.push(format!(
                "Against {}, {}'s position error stays below {} m.",
                s.reference,
                best.0,
                cell(Some(best.1), 2)
            ));
        }
    }
    if let Some(w) = work_sentence(r) {
        out.push(w);
    }
    // Stability.
    if let Some(scan) = &r.scan {
        let lims: Vec<String> = bs
            .iter()
            .filter(|b| scan.rows.iter().any(|row| row.integrator == b.backend))
            .map(|b| {
                let theory = super::collect::theory_limit(&b.backend);
                let th = match theory {
                    Some(l) if l.is_infinite() => " (theory: any)".to_string(),
                    Some(0.0) => " (theory: none)".to_string(),
                    Some(l) => format!(" (theory {})", cell(Some(l), 3)),
                    None => String::new(),
                };
                match (b.stable_h_omega, b.unstable_at_every_scanned_step) {
                    (Some(h), _) => format!("{} up to {}{th}", b.backend, cell(Some(h), 2)),
                    (None, true) => format!("{} at no scanned step{th}", b.backend),
                    (None, false) => format!("{} not scanned", b.backend),
                }
            })
            .collect();
        if !lims.is_empty() {
            out.push(format!(
                "With ω = {} rad/s, runs stay bounded for h·ω: {}.",
                cell(Some(scan.omega), 3),
                lims.join("; ")
            ));
        }
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

    #[test]
    fn evals_interpolate_log_log() {
        // error ∝ evals^-2: 1e-2 at 10, 1e-4 at 100 → 1e-3 at √1000 ≈ 31.6.
        let p = [(10.0, 1e-2), (100.0, 1e-4)];
        assert!((evals_for(&p, 1e-3).unwrap() - 1000f64.sqrt()).abs() < 1e-9);
        assert_eq!(evals_for(&p, 1e-5), None);
    }
}
