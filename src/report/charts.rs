//! What every chart's `from_study` reads a scene's [`SceneStudy`] with: its runs, their time
//! series and blow-up points, and the plane the motion lies in. Every point is a number of a
//! document (compare's series and traces, the sweep's rows and fits, the contact metrics);
//! nothing is measured here.

use super::data::*;
use crate::measure::case::CaseResult;
use crate::measure::study::SceneStudy;

pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

/// The compared runs that ran (skipped ones have nothing to draw).
pub(crate) fn runs(s: &SceneStudy) -> impl Iterator<Item = &CaseResult> {
    s.compare.entries.iter().filter_map(|e| e.result.as_ref())
}

pub(crate) fn blowup_at(run: &CaseResult, last: Option<[f64; 2]>) -> Option<BlowUp> {
    match (run.unstable_time, last) {
        (Some(t), Some(p)) => Some(BlowUp { x: t, y: p[1] }),
        _ => None,
    }
}

/// One series of a run's compare series: `f(k)` at every recorded time.
pub(crate) fn time_series(
    run: &CaseResult,
    f: impl Fn(&crate::measure::metrics::Series, usize) -> f64,
) -> Series {
    let points: Vec<[f64; 2]> = match &run.series {
        Some(se) => (0..se.t.len())
            .map(|k| [se.t[k], f(se, k)])
            .filter(|p| p[1].is_finite())
            .collect(),
        None => Vec::new(),
    };
    let mut s = Series::new(run.method.clone(), points);
    s.blowup = blowup_at(run, s.points.last().copied());
    s
}

/// The plane trajectories are drawn in, as [horizontal, vertical] axis indices: with gravity,
/// the vertical is the axis gravity points along and the horizontal the other axis the first
/// run's trace spreads over most; without, the two axes of largest spread in x, y, z order.
pub fn main_plane(s: &SceneStudy, gravity: Option<[f64; 3]>) -> [usize; 2] {
    let mut var = [0.0f64; 3];
    if let Some(tr) = runs(s).find_map(|r| r.trace.as_ref()) {
        for (a, v) in var.iter_mut().enumerate() {
            let vals = tr
                .paths
                .iter()
                .flatten()
                .chain(tr.snapshots.iter().flat_map(|(_, x)| x.iter()))
                .map(|x| x[a]);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for x in vals.filter(|x| x.is_finite()) {
                lo = lo.min(x);
                hi = hi.max(x);
            }
            *v = if hi >= lo { hi - lo } else { 0.0 };
        }
    }
    if let Some(g) = gravity.filter(|g| g.iter().any(|c| *c != 0.0)) {
        let v = (0..3)
            .max_by(|&a, &b| g[a].abs().total_cmp(&g[b].abs()).then(b.cmp(&a)))
            .unwrap_or(1);
        let h = (0..3)
            .filter(|&a| a != v)
            .max_by(|&a, &b| var[a].total_cmp(&var[b]).then(b.cmp(&a)))
            .unwrap_or(0);
        return [h, v];
    }
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| var[b].total_cmp(&var[a]).then(a.cmp(&b)));
    let mut p = [idx[0], idx[1]];
    p.sort();
    p
}
