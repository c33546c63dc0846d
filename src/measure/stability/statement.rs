//! One statement per method: what the spectral radius says, what the empirical runs saw, which
//! of the two decides, and, where they differ, why.
//!
//! Where linear theory applies the spectral radius decides: it is the limit as the run length
//! grows, which is what "bounded" means. The empirical runs see growth only once it passes the
//! verdict's thresholds within the horizon, so they can read bounded past the limit (a radius
//! of 1 + 1e-6 multiplies the energy by e² only after a million steps), and, on a scene whose
//! linearisation changes as it moves, they can read unstable below it.

use super::empirical::Empirical;
use super::theory::{rho, Limit};
use super::{Modes, Verdict};
use crate::method::{Method, MethodOptions};

/// Relative difference between the two limits that counts as agreement: the empirical
/// bisection stops at 0.1 %, and the verdict needs some growth before it fires.
pub const AGREE: f64 = 0.1;

/// The statement for `method` from its theory limit, its empirical search and the trial length
/// (`steps_at`: the steps a trial of step h runs).
pub fn statement(
    method: &Method,
    opts: &MethodOptions,
    ms: &Modes,
    theory: Option<Limit>,
    empirical: Option<&Empirical>,
    steps_at: impl Fn(f64) -> u64,
) -> String {
    let e = |x: f64| format!("{x:.3e} s");
    let Some((tv, tdt)) = theory else {
        return match empirical {
            Some(em) => format!(
                "the empirical search decides: {}",
                said(em.verdict, em.max_stable_dt)
            ),
            None => "not analysed: no linear theory applies and no empirical search ran".into(),
        };
    };
    let head = format!("the spectral radius decides: {}", said(tv, tdt));
    let Some(em) = empirical else {
        return format!("{head} (no empirical search ran)");
    };
    // The growth the trials would have seen at the empirical limit, by the spectral radius.
    let growth = |h: f64| {
        let r = ms
            .modes
            .iter()
            .map(|&m| rho(method, opts, m, h))
            .fold(0.0, f64::max);
        (r, r.powf(2.0 * steps_at(h) as f64))
    };
    match (tv, tdt, em.verdict, em.max_stable_dt) {
        (Verdict::StableBelow, Some(t), Verdict::StableBelow, Some(x))
            if (x / t - 1.0).abs() <= AGREE =>
        {
            format!("{head}; the empirical search agrees ({})", e(x))
        }
        (_, _, Verdict::StableBelow, Some(x))
            if tdt.is_none_or(|t| x > t) && tv != Verdict::UnconditionallyStable =>
        {
            let (r, g) = growth(x);
            format!(
                "{head}; the empirical runs read bounded up to {} only because the growth there did not show within a trial (ρ = 1 + {:.2e} at t = 0: ×{g:.3e} in a mode's energy over its {} steps, from a start where that mode holds little, or on a mode the scene leaves as it moves)",
                e(x),
                r - 1.0,
                steps_at(x)
            )
        }
        (Verdict::UnconditionallyStable, _, Verdict::UnconditionallyStable, _)
        | (Verdict::UnstableForAllDt, _, Verdict::UnstableForAllDt, _) => {
            format!("{head}; the empirical search agrees")
        }
        (_, _, Verdict::UnconditionallyStable, _) => format!(
            "{head}; the empirical runs read bounded at every step tried: growth at a radius close to 1 did not pass the verdict's thresholds within a trial"
        ),
        (_, _, ev, x) => format!(
            "{head}; the empirical runs read {}: their verdict fires where the linearisation at t = 0 no longer holds along the run (a nonlinear scene) or where a bounded swing near the limit passes its thresholds",
            said(ev, x)
        ),
    }
}

/// A verdict in words.
fn said(v: Verdict, dt: Option<f64>) -> String {
    match (v, dt) {
        (Verdict::StableBelow, Some(h)) => format!("stable below {h:.3e} s"),
        (Verdict::UnconditionallyStable, _) => "stable at every step tried".into(),
        (Verdict::UnstableForAllDt, _) => "unstable at every step".into(),
        _ => "not analysed".into(),
    }
}
