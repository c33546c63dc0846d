//! Observed order of convergence: the least-squares slope of log(error) against log(dt) over
//! the asymptotic range only.
//!
//! Points are excluded when the run was unstable, when the error is at the measurement floor
//! (below 10× the reference's accuracy, or below 1e-13 of the length scale: round-off), or
//! when it is saturated (above 10 % of the length scale: not small enough to be asymptotic).
//! Among the remaining points, sorted by dt, the fit uses the longest run of consecutive
//! points (at least 3) whose error falls strictly as dt shrinks and whose fit has R² ≥ 0.99,
//! preferring the smallest steps on ties. (R² alone accepts a window that is still bending or
//! has a dip, e.g. a cloth whose error crosses zero in one component; a convergent method's
//! error must fall at every refinement of the asymptotic range.)

use serde::{Deserialize, Serialize};

/// Minimum R² for a window to count as asymptotic.
pub const MIN_R2: f64 = 0.99;

/// The result of an order fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrderFit {
    /// The slope d log(error) / d log(dt), if a fit was possible.
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
    /// Why no fit, when there is none.
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

/// Fits the order from (dt, error, stable, floor) points: `floor` is that point's measurement
/// floor and `saturation` the error above which a point is not asymptotic (both in m).
pub fn fit_order(points: &[(f64, f64, bool, f64)], saturation: f64) -> OrderFit {
    let mut f = OrderFit {
        observed_order: None,
        r_squared: None,
        max_residual_decades: None,
        dt_range: None,
        points_used: 0,
        excluded_unstable: 0,
        excluded_floor: 0,
        excluded_saturated: 0,
        excluded_preasymptotic: 0,
        note: None,
    };
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
    let x: Vec<f64> = pts.iter().map(|p| p.0.log10()).collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1.log10()).collect();
    let mut best: Option<(usize, usize, f64, f64)> = None;
    for len in (3..=pts.len()).rev() {
        for start in 0..=pts.len() - len {
            let (s, _, r2, res) = lsq(&x[start..start + len], &y[start..start + len]);
            let monotone = y[start..start + len].windows(2).all(|w| w[1] > w[0]);
            if monotone && r2 >= MIN_R2 && s.is_finite() {
                best = Some((start, len, s, res));
                break;
            }
        }
        if best.is_some() {
            break;
        }
    }
    match best {
        Some((start, len, slope, res)) => {
            let (_, _, r2, _) = lsq(&x[start..start + len], &y[start..start + len]);
            f.observed_order = Some(slope);
            f.r_squared = Some(r2);
            f.max_residual_decades = Some(res);
            f.dt_range = Some([pts[start].0, pts[start + len - 1].0]);
            f.points_used = len;
            f.excluded_preasymptotic = pts.len() - len;
        }
        None => {
            f.excluded_preasymptotic = pts.len();
            f.note = Some(if pts.len() < 3 {
                format!(
                    "fewer than 3 usable points ({} unstable, {} at the error floor, {} saturated)",
                    f.excluded_unstable, f.excluded_floor, f.excluded_saturated
                )
            } else {
                format!("no 3 consecutive points fall monotonically and fit a power law with R² ≥ {MIN_R2}")
            });
        }
    }
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
        let f = fit_order(&pts, 0.1);
        assert!((f.observed_order.unwrap() - 2.0).abs() < 1e-9);
        assert_eq!(f.points_used, 8);
        assert_eq!(
            (f.excluded_floor, f.excluded_saturated, f.excluded_unstable),
            (1, 1, 1)
        );
    }

    #[test]
    fn a_window_must_fall_monotonically() {
        // Errors 8h², plus a point at h = 9e-3 that dips 2 % below the error at 8e-3: the
        // 6-point window across it has R² > 0.99 but is not asymptotic; the fit must avoid it.
        let hs = [1e-3, 2e-3, 4e-3, 8e-3, 9e-3, 1.6e-2];
        let mut pts: Vec<(f64, f64, bool, f64)> =
            hs.iter().map(|&h| (h, 8.0 * h * h, true, 0.0)).collect();
        pts[4].1 = 0.98 * pts[3].1;
        let all: Vec<f64> = pts.iter().map(|p| p.1.log10()).collect();
        let xs: Vec<f64> = pts.iter().map(|p| p.0.log10()).collect();
        let (_, _, r2, _) = lsq(&xs, &all);
        assert!(r2 >= MIN_R2, "the dip must fool R² alone (R² = {r2})");
        let f = fit_order(&pts, 1.0);
        assert_eq!(f.points_used, 4, "{f:?}");
        assert!((f.observed_order.unwrap() - 2.0).abs() < 1e-9);
        assert_eq!(f.dt_range, Some([1e-3, 8e-3]));
    }

    #[test]
    fn no_fit_from_two_points() {
        let f = fit_order(&[(0.1, 0.01, true, 0.0), (0.2, 0.04, true, 0.0)], 1.0);
        assert!(f.observed_order.is_none() && f.note.is_some());
    }
}
