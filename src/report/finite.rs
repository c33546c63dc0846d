//! The one gate every number passes before it reaches a plot or a table: non-finite values
//! (and non-positive ones on log axes) are dropped, and what comes out is asserted finite.

/// Keeps the points a chart can draw: both coordinates finite, and positive on log axes.
/// Every chart calls this (through `plots::common`), so no NaN or infinity is ever drawn.
pub fn plottable(points: &[[f64; 2]], x_log: bool, y_log: bool) -> Vec<(f64, f64)> {
    let ok = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let out: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| ok(p[0], x_log) && ok(p[1], y_log))
        .map(|p| (p[0], p[1]))
        .collect();
    assert!(
        out.iter().all(|(x, y)| x.is_finite() && y.is_finite()),
        "non-finite value reached a chart"
    );
    out
}

/// True when a single value can be drawn on an axis (finite, and positive on a log axis).
pub fn drawable(v: f64, log: bool) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

/// A table cell for a number with `sig` significant digits; `—` for a missing or non-finite
/// value, so no NaN or `inf` is ever printed.
pub fn cell(v: Option<f64>, sig: usize) -> String {
    match v {
        Some(v) if v.is_finite() => crate::error::significant(v, sig),
        _ => "—".into(),
    }
}

/// A table cell for a relative number in percent with `sig` significant digits (`2.6%`); `—`
/// for a missing or non-finite value.
pub fn percent(v: Option<f64>, sig: usize) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{}%", cell(Some(100.0 * v), sig)),
        _ => "—".into(),
    }
}

/// `Some(v)` when `v` is finite.
pub fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drops_non_finite_and_non_positive_on_log_axes() {
        let pts = [
            [0.0, 1.0],
            [1.0, f64::NAN],
            [f64::INFINITY, 2.0],
            [2.0, 0.0],
            [3.0, 4.0],
        ];
        assert_eq!(
            plottable(&pts, false, false),
            vec![(0.0, 1.0), (2.0, 0.0), (3.0, 4.0)]
        );
        assert_eq!(plottable(&pts, false, true), vec![(0.0, 1.0), (3.0, 4.0)]);
        assert_eq!(plottable(&pts, true, true), vec![(3.0, 4.0)]);
    }

    #[test]
    fn cells_never_print_nan() {
        assert_eq!(cell(Some(f64::NAN), 3), "—");
        assert_eq!(cell(Some(f64::INFINITY), 3), "—");
        assert_eq!(cell(None, 3), "—");
        assert_eq!(cell(Some(0.012345), 3), "0.0123");
        assert_eq!(cell(Some(123.456), 3), "123");
        assert_eq!(cell(Some(1.5e-7), 2), "1.5e-7");
    }
}
