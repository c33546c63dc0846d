//! Observed order of convergence: the least-squares slope of log(error) against log(dt) over
//! the asymptotic range at the small-step end only.
//!
//! Points are excluded when the run was unstable, when the error is at the measurement floor
//! (the caller's per-point floor: the reference's accuracy or round-off), or when it is
//! saturated (above the caller's saturation bound: not small enough to be asymptotic).
//!
//! The window always starts at the smallest usable step (the finest stable point above the
//! floor): a curve that is straight at large steps but still bending at the small end is
//! pre-asymptotic, and its large-step slope is not the order. The finest three usable points
//! must (a) have errors that fall strictly as dt shrinks and (b) have local slopes
//! d log e / d log dt that agree within [`SLOPE_TOL`] (steady). The window then grows toward
//! larger steps while each added point keeps the errors monotone, its local slope within
//! [`SLOPE_TOL`] of the finest one, and the fit's R² ≥ [`MIN_R2`] (the finest three must also fit a power law with R² ≥ [`MIN_R2`]
//! and slope ≥ [`MIN_ORDER`]). The order is the
//! least-squares slope over that window. When the method's theoretical order p is known, a
//! steady slope more than [`ORDER_TOL`] away from p is not printed either: a slope that is
//! steady over a factor of 4 in dt can still be a pre-asymptotic plateau (or a defect), and
//! the note gives the measured slopes so either can be seen. Otherwise the order is null and
//! [`OrderFit::reason`] / [`OrderFit::note`] say why, with the local slopes measured.

use crate::error::significant;
use serde::{Deserialize, Serialize};

/// Minimum R² for a window to count as asymptotic.
pub const MIN_R2: f64 = 0.99;
/// Largest difference between local slopes that still counts as steady.
pub const SLOPE_TOL: f64 = 0.1;
/// Largest distance of a steady slope from the theoretical order that is printed as the
/// observed order.
pub const ORDER_TOL: f64 = 0.15;
/// Smallest slope accepted as an order: a convergent method's error falls at least like dt.
pub const MIN_ORDER: f64 = 0.5;

/// Why an order fit gave no order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitReason {
    /// Fewer than three usable points.
    TooFewPoints,
    /// The error does not fall strictly at every refinement of the finest three points.
    NotMonotone,
    /// The local slopes at the small-step end still change by more than [`SLOPE_TOL`].
    SlopesNotSteady,
    /// The slopes are steady but more than [`ORDER_TOL`] from the theoretical order.
    OrderMismatch,
    /// The finest three points are not a power law (R² < [`MIN_R2`]) or their slope is below
    /// [`MIN_ORDER`]: the error barely falls with the step.
    NoConvergence,
}

/// The result of an order fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrderFit {
    /// The slope d log(error) / d log(dt), if the small-step end is asymptotic.
    pub observed_order: Option<f64>,
    /// R² of the fit.
    pub r_squared: Option<f64>,
    /// Largest |residual| of the fit in decades.
    pub max_residual_decades: Option<f64>,
    /// Smallest and largest dt used.
    pub dt_range: Option<[f64; 2]>,
    /// Points used.
    pub points_used: usize,
    /// Points excluded as unstable.
    pub excluded_unstable: usize,
    /// Points excluded at the measurement floor.
    pub excluded_floor: usize,
    /// Points excluded as saturated.
    pub excluded_saturated: usize,
    /// Points stable and in range but outside the chosen window.
    pub excluded_preasymptotic: usize,
    /// Local slopes between consecutive usable points, from the smallest step up (at most
    /// the finest five): the evidence for the verdict.
    pub local_slopes: Vec<f64>,
    /// Why no order, as a code (None when there is an order).
    pub reason: Option<FitReason>,
    /// Why no fit, when there is none, in words.
    pub note: Option<String>,
}

fn lsq(x: &[f64], y: &[f64]) -> (f64, f64, f64, f64) {
    let n = x.len() as f64;
    let xm = x.iter().sum::<f64>() / n;
    let ym = y.iter().sum::<f64>() / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxx += (a - xm) * (a - xm);
        sxy += (a - xm) * (b - ym);
        syy += (b - ym) * (b - ym);
    }
    let slope = sxy / sxx;
    let icpt = ym - slope * xm;
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        1.0
    };
    let maxres = x
        .iter()
        .zip(y)
        .map(|(a, b)| (b - (icpt + slope * a)).abs())
        .fold(0.0, f64::max);
    (slope, icpt, r2, maxres)
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|s| format!("{s:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The fit before any window is chosen: no order, nothing counted.
fn empty_fit() -> OrderFit {
    OrderFit {
        observed_order: None,
        r_squared: None,
        max_residual_decades: None,
        dt_range: None,
        points_used: 0,
        excluded_unstable: 0,
        excluded_floor: 0,
        excluded_saturated: 0,
        excluded_preasymptotic: 0,
        local_slopes: Vec::new(),
        reason: None,
        note: None,
    }
}

/// The (dt, error) points usable for a fit, ascending in dt; the unstable, floored and
/// saturated ones counted in `f`.
fn usable_points(
    points: &[(f64, f64, bool, f64)],
    saturation: f64,
    f: &mut OrderFit,
) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for &(dt, e, ok, floor) in points {
        if !ok {
            f.excluded_unstable += 1;
        } else if e.is_nan() || e <= floor {
            f.excluded_floor += 1;
        } else if e > saturation {
            f.excluded_saturated += 1;
        } else {
            pts.push((dt, e));
        }
    }
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts
}

/// Why the finest three of the usable points (`finest` their smallest dt; `x`, `y` their
/// log10 dt and error, `slopes` the local slopes) are not an asymptotic start, if they are not.
fn small_end_problem(
    f: &OrderFit,
    finest: f64,
    x: &[f64],
    y: &[f64],
    slopes: &[f64],
) -> Option<(FitReason, String)> {
    if !(y[1] > y[0] && y[2] > y[1]) {
        let note = format!(
            "asymptotic range not reached: the error does not fall at every refinement of the finest three steps (local slopes {}; finest step {} s)",
            list(&slopes[..2]),
            significant(finest, 4)
        );
        return Some((FitReason::NotMonotone, note));
    }
    if (slopes[1] - slopes[0]).abs() > SLOPE_TOL {
        let note = format!(
            "asymptotic range not reached: local slopes {} (finest first) still change by more than {SLOPE_TOL} at the finest step {} s",
            list(&f.local_slopes),
            significant(finest, 4)
        );
        return Some((FitReason::SlopesNotSteady, note));
    }
    let (s3, _, r3, _) = lsq(&x[..3], &y[..3]);
    if r3 < MIN_R2 || s3 < MIN_ORDER {
        let note = format!(
            "no convergence at the small-step end: the finest three steps fit slope {s3:.2} with R² {r3:.3} (need slope ≥ {MIN_ORDER} and R² ≥ {MIN_R2}); finest step {} s",
            significant(finest, 4)
        );
        return Some((FitReason::NoConvergence, note));
    }
    None
}

/// Fits the order from (dt, error, stable, floor) points: `floor` is that point's measurement
/// floor and `saturation` the error above which a point is not asymptotic (both in m);
/// `expected` is the method's theoretical order, if it has one.
pub fn fit_order(
    points: &[(f64, f64, bool, f64)],
    saturation: f64,
    expected: Option<f64>,
) -> OrderFit {
    let mut f = empty_fit();
    let pts = usable_points(points, saturation, &mut f);
    f.excluded_preasymptotic = pts.len();
    let x: Vec<f64> = pts.iter().map(|p| p.0.log10()).collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1.log10()).collect();
    let slopes: Vec<f64> = (1..pts.len())
        .map(|k| (y[k] - y[k - 1]) / (x[k] - x[k - 1]))
        .collect();
    f.local_slopes = slopes.iter().take(5).copied().collect();
    let fail = |f: &mut OrderFit, r: FitReason, note: String| {
        f.reason = Some(r);
        f.note = Some(note);
    };
    if pts.len() < 3 {
        let note = format!(
            "fewer than 3 usable points ({} unstable, {} at the error floor, {} saturated)",
            f.excluded_unstable, f.excluded_floor, f.excluded_saturated
        );
        fail(&mut f, FitReason::TooFewPoints, note);
        return f;
    }
    let finest = pts[0].0;
    if let Some((r, note)) = small_end_problem(&f, finest, &x, &y, &slopes) {
        fail(&mut f, r, note);
        return f;
    }
    let mut len = 3;
    while len < pts.len()
        && y[len] > y[len - 1]
        && (slopes[len - 1] - slopes[0]).abs() <= SLOPE_TOL
        && lsq(&x[..=len], &y[..=len]).2 >= MIN_R2
    {
        len += 1;
    }
    let (slope, _, r2, res) = lsq(&x[..len], &y[..len]);
    if let Some(p) = expected {
        if (slope - p).abs() > ORDER_TOL {
            let note = format!(
                "asymptotic range not confirmed: local slopes {} (finest first) are steady at {slope:.2} down to {} s but the method's order is {p}",
                list(&f.local_slopes),
                significant(finest, 4)
            );
            fail(&mut f, FitReason::OrderMismatch, note);
            return f;
        }
    }
    f.observed_order = Some(slope);
    f.r_squared = Some(r2);
    f.max_residual_decades = Some(res);
    f.dt_range = Some([pts[0].0, pts[len - 1].0]);
    f.points_used = len;
    f.excluded_preasymptotic = pts.len() - len;
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_power_law_and_skips_floor_saturation_and_unstable() {
        // Oracle: e = 3 dt² exactly on the asymptotic range.
        let mut pts: Vec<(f64, f64, bool, f64)> = (0..8)
            .map(|i| {
                let dt = 1e-3 * 2f64.powi(i);
                (dt, 3.0 * dt * dt, true, 1e-14)
            })
            .collect();
        pts.push((1e-5, 1e-16, true, 1e-14)); // round-off floor
        pts.push((1.0, 5.0, true, 1e-14)); // saturated
        pts.push((2.0, 1.0, false, 1e-14)); // unstable
        let f = fit_order(&pts, 0.1, Some(2.0));
        assert!((f.observed_order.unwrap() - 2.0).abs() < 1e-9);
        assert_eq!(f.points_used, 8);
        assert_eq!(
            (f.excluded_floor, f.excluded_saturated, f.excluded_unstable),
            (1, 1, 1)
        );
        assert!(f.reason.is_none() && f.note.is_none());
    }

    #[test]
    fn the_window_stops_where_the_large_steps_bend() {
        // e = 8h² for small h, bending to 8h²(1 + 100 h²) past h ≈ 0.05: the window starts at
        // the smallest step and stops before the bend.
        let pts: Vec<(f64, f64, bool, f64)> = (0..9)
            .map(|i| {
                let h = 1e-3 * 2f64.powi(i);
                (h, 8.0 * h * h * (1.0 + 100.0 * h * h), true, 0.0)
            })
            .collect();
        let f = fit_order(&pts, 10.0, Some(2.0));
        let q = f.observed_order.unwrap();
        assert!((q - 2.0).abs() < 0.02, "{f:?}");
        assert_eq!(f.dt_range.unwrap()[0], 1e-3);
        assert!(f.points_used < 9 && f.excluded_preasymptotic > 0, "{f:?}");
    }

    #[test]
    fn a_curve_still_bending_at_the_small_end_gives_no_order() {
        // Pre-asymptotic at the small end: below h = 0.1 the local slope climbs 0.53, 0.71,
        // 0.85 as h shrinks (not yet steady), while the large-step end is a clean power law of
        // slope 3 (e = h³ for h ≥ 0.1) over six points. The old longest-window rule printed
        // the large-step slope; the small-end rule must give null, naming the slopes.
        let mut pts: Vec<(f64, f64, bool, f64)> = Vec::new();
        for i in 0..6 {
            let h = 0.1 * 2f64.powi(i);
            pts.push((h, h * h * h, true, 0.0));
        }
        // Below 0.1: slopes 0.85, 0.71, 0.53 going down (still rising toward the small end).
        let mut e = 1e-3;
        let mut h = 0.1;
        for s in [0.53, 0.71, 0.85] {
            h /= 2.0;
            e /= 2f64.powf(s);
            pts.push((h, e, true, 0.0));
        }
        let f = fit_order(&pts, 1e3, None);
        assert!(f.observed_order.is_none(), "{f:?}");
        assert_eq!(f.reason, Some(FitReason::SlopesNotSteady));
        assert!(f.note.as_deref().unwrap().contains("0.85, 0.71"), "{f:?}");
    }

    #[test]
    fn a_window_must_fall_monotonically() {
        // Errors 8h², with the finest point dipping below its neighbour's trend: the error
        // rises as dt shrinks, so the small end is not asymptotic and no order is printed.
        let hs = [1e-3, 2e-3, 4e-3, 8e-3, 1.6e-2];
        let mut pts: Vec<(f64, f64, bool, f64)> =
            hs.iter().map(|&h| (h, 8.0 * h * h, true, 0.0)).collect();
        pts[0].1 = 1.1 * pts[1].1;
        let f = fit_order(&pts, 1.0, None);
        assert_eq!(f.reason, Some(FitReason::NotMonotone), "{f:?}");
        assert!(f.observed_order.is_none());
    }

    #[test]
    fn a_steady_slope_far_from_theory_is_not_printed() {
        // A clean slope-1.4 power law given as a first-order method: steady but not the order.
        let pts: Vec<(f64, f64, bool, f64)> = (0..5)
            .map(|i| {
                let h = 1e-3 * 2f64.powi(i);
                (h, h.powf(1.4), true, 0.0)
            })
            .collect();
        let f = fit_order(&pts, 1.0, Some(1.0));
        assert_eq!(f.reason, Some(FitReason::OrderMismatch), "{f:?}");
        let g = fit_order(&pts, 1.0, None);
        assert!((g.observed_order.unwrap() - 1.4).abs() < 1e-9);
    }

    #[test]
    fn an_error_that_barely_falls_is_no_order() {
        // Errors creeping up by 0.1 % per doubling: monotone and steady, but slope ≈ 0.001.
        let pts: Vec<(f64, f64, bool, f64)> = (0..5)
            .map(|i| (1e-3 * 2f64.powi(i), 0.05 * 1.001f64.powi(i), true, 0.0))
            .collect();
        let f = fit_order(&pts, 1.0, None);
        assert_eq!(f.reason, Some(FitReason::NoConvergence), "{f:?}");
    }

    #[test]
    fn no_fit_from_two_points() {
        let f = fit_order(&[(0.1, 0.01, true, 0.0), (0.2, 0.04, true, 0.0)], 1.0, None);
        assert!(f.observed_order.is_none() && f.note.is_some());
        assert_eq!(f.reason, Some(FitReason::TooFewPoints));
    }
}
