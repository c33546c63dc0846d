//! Turns one scene's [`SceneStudy`] into the plain chart data of [`super::data`]: every point
//! is a number of a document (compare's series and traces, the sweep's rows and fits, the
//! contact metrics); nothing is measured here.

use super::data::*;
use crate::measure::case::CaseResult;
use crate::measure::study::SceneStudy;

const AXES: [&str; 3] = ["x", "y", "z"];

/// The compared runs that ran (skipped ones have nothing to draw).
fn runs(s: &SceneStudy) -> impl Iterator<Item = &CaseResult> {
    s.compare.entries.iter().filter_map(|e| e.result.as_ref())
}

fn blowup_at(run: &CaseResult, last: Option<[f64; 2]>) -> Option<BlowUp> {
    match (run.unstable_time, last) {
        (Some(t), Some(p)) => Some(BlowUp { x: t, y: p[1] }),
        _ => None,
    }
}

/// One series of a run's compare series: `f(k)` at every recorded time.
fn time_series(
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

/// Energy over time: totals per method, and (when `terms`) the terms of the first method.
pub fn energy(s: &SceneStudy, terms: bool) -> EnergyData {
    let totals = runs(s)
        .map(|run| time_series(run, |se, k| se.energy[k].total))
        .collect();
    let mut term_series = Vec::new();
    if let Some(run) = runs(s).next().filter(|_| terms) {
        type Term = fn(&crate::run::EnergyRecord) -> f64;
        let all: [(&str, Term); 5] = [
            ("kinetic", |e| e.kinetic),
            ("gravity", |e| e.gravity),
            ("elastic", |e| e.elastic),
            ("dissipated", |e| e.dissipated),
            ("injected", |e| e.injected),
        ];
        for (name, f) in all {
            if run
                .series
                .as_ref()
                .is_some_and(|se| se.energy.iter().any(|e| f(e) != 0.0))
            {
                let mut t = time_series(run, |se, k| f(&se.energy[k]));
                t.label = format!("{name} ({})", run.method);
                term_series.push(t);
            }
        }
    }
    EnergyData {
        totals,
        terms: term_series,
    }
}

/// Relative energy error per method, as compare's metrics define it.
pub fn energy_error(s: &SceneStudy) -> EnergyErrorData {
    EnergyErrorData {
        series: runs(s)
            .map(|run| time_series(run, |se, k| se.energy_error[k].abs()))
            .collect(),
        scale_note: "the scene's energy scale (compare's definition)".into(),
    }
}

/// Position error per method, leaving out the run of the method that is the reference itself
/// (the closed form's own run: zero error, nothing to plot).
pub fn position_error(s: &SceneStudy) -> PositionErrorData {
    let registry = crate::method::Registry::builtin();
    let closed_form =
        s.compare.reference.kind == crate::measure::reference::ReferenceKind::Analytic;
    PositionErrorData {
        series: runs(s)
            .filter(|run| {
                !(closed_form
                    && registry
                        .info(&run.method)
                        .is_ok_and(|m| m.order == crate::method::Order::Exact))
            })
            .map(|run| time_series(run, |se, k| se.position_error[k]))
            .collect(),
        reference: super::summary::reference_words(s),
    }
}

/// Convergence lines from the sweep's rows with the sweep's fitted orders and the theoretical
/// orders its plan recorded, and reference slopes dt^p for the orders present.
pub fn convergence(s: &SceneStudy) -> Option<ConvergenceData> {
    let sweep = s.sweep.as_ref()?;
    let summary = sweep.summary.as_ref()?;
    let mut lines = Vec::new();
    for (name, order) in sweep.plan.methods.iter().zip(&sweep.plan.orders) {
        let rows = sweep.rows.iter().filter(|r| &r.method == name);
        let points: Vec<[f64; 2]> = rows
            .clone()
            .filter_map(|r| {
                r.error_max
                    .filter(|e| e.is_finite() && *e > 0.0)
                    .map(|e| [r.dt, e])
            })
            .collect();
        let unstable = rows
            .filter(|r| !r.status.is_ok())
            .map(|r| r.dt)
            .reduce(f64::max);
        let top = points.iter().map(|p| p[1]).reduce(f64::max).unwrap_or(1.0);
        let mut series = Series::new(name.clone(), points);
        series.blowup = unstable.map(|dt| BlowUp { x: dt, y: top });
        let fit = summary.methods.iter().find(|i| &i.method == name);
        let Some(order) = *order else {
            continue;
        };
        lines.push(ConvergenceLine {
            series,
            fitted_slope: fit.and_then(|f| f.observed_order),
            order,
            note: fit.and_then(|f| f.fit.note.clone()),
        });
    }
    let mut orders: Vec<u32> = lines.iter().map(|l| l.order).collect();
    orders.sort();
    orders.dedup();
    let (dt0, dt1) = sweep
        .plan
        .dts
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &d| (a.min(d), b.max(d)));
    let guides = orders
        .iter()
        .filter_map(|&p| {
            let anchor = lines
                .iter()
                .filter(|l| l.order == p)
                .flat_map(|l| l.series.points.iter())
                .min_by(|a, b| a[0].total_cmp(&b[0]))?;
            let c = anchor[1] * 0.5 / anchor[0].powi(p as i32);
            Some(Guide {
                label: format!("reference slope {p} (∝ dt^{p})"),
                points: vec![[dt0, c * dt0.powi(p as i32)], [dt1, c * dt1.powi(p as i32)]],
            })
        })
        .collect();
    Some(ConvergenceData {
        lines,
        guides,
        reference: format!("{} ({})", sweep.reference.kind, sweep.reference.description),
    })
}

/// Work-precision lines from the sweep's stable rows, and each engine's compare run at the
/// scene's step as one point beside them (same duration, same error measure; an engine is
/// not swept); `None` when no sweep run was stable.
pub fn work_precision(s: &SceneStudy) -> Option<WorkPrecisionData> {
    let sweep = s.sweep.as_ref()?;
    let registry = crate::method::Registry::builtin();
    let engines = runs(s)
        .filter(|r| registry.info(&r.method).is_ok_and(|m| m.engine))
        .map(|r| WorkLine {
            label: r.method.clone(),
            points: r
                .metrics
                .as_ref()
                .map(|m| m.error_max)
                .filter(|e| e.is_finite() && *e > 0.0 && r.status.is_ok())
                .map(|e| WorkPoint {
                    dt: r.dt,
                    error: e,
                    modelled_seconds: r.modelled_seconds,
                    force_evals: r.force_evals,
                })
                .into_iter()
                .collect(),
        });
    let lines: Vec<WorkLine> = sweep
        .plan
        .methods
        .iter()
        .map(|name| WorkLine {
            label: name.clone(),
            points: sweep
                .rows
                .iter()
                .filter(|r| &r.method == name)
                .filter_map(|r| {
                    r.error_max
                        .filter(|e| e.is_finite() && *e > 0.0)
                        .map(|e| WorkPoint {
                            dt: r.dt,
                            error: e,
                            modelled_seconds: r.modelled_seconds,
                            force_evals: r.force_evals,
                        })
                })
                .collect(),
        })
        .chain(engines)
        .collect();
    lines
        .iter()
        .any(|l| !l.points.is_empty())
        .then_some(WorkPrecisionData { lines })
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

/// Paths of the tracked particles in the main plane.
pub fn paths(s: &SceneStudy, plane: [usize; 2]) -> PathData {
    let [a, b] = plane;
    let mut series = Vec::new();
    for run in runs(s) {
        let Some(tr) = &run.trace else { continue };
        for (k, path) in tr.paths.iter().enumerate() {
            let points: Vec<[f64; 2]> = path
                .iter()
                .filter(|p| p[a].is_finite() && p[b].is_finite())
                .map(|p| [p[a], p[b]])
                .collect();
            let label = if tr.tracked.len() > 1 {
                format!("{} particle {}", run.method, tr.tracked[k])
            } else {
                run.method.clone()
            };
            let mut line = Series::new(label, points);
            line.blowup = match (run.unstable_time, line.points.last()) {
                (Some(_), Some(p)) => Some(BlowUp { x: p[0], y: p[1] }),
                _ => None,
            };
            series.push(line);
        }
    }
    PathData {
        axes: [AXES[a].into(), AXES[b].into()],
        series,
    }
}

/// Polylines of a chain or cloth block (cloth rows and columns, at most 9 of each).
fn block_lines(
    block: &crate::scenario::Block,
    x: &[[f64; 3]],
    plane: [usize; 2],
) -> Vec<Vec<[f64; 2]>> {
    let [nx, ny] = block.shape;
    let at = |ix: usize, iy: usize| {
        let p = x[block.first + iy * nx + ix];
        [p[plane[0]], p[plane[1]]]
    };
    let pick = |n: usize| -> Vec<usize> {
        let step = n.div_ceil(8).max(1);
        let mut v: Vec<usize> = (0..n).step_by(step).collect();
        if v.last() != Some(&(n - 1)) {
            v.push(n - 1);
        }
        v
    };
    let mut lines = Vec::new();
    for iy in pick(ny) {
        lines.push((0..nx).map(|ix| at(ix, iy)).collect());
    }
    if ny > 1 {
        for ix in pick(nx) {
            lines.push((0..ny).map(|iy| at(ix, iy)).collect());
        }
    }
    lines
}

/// Snapshots of the scene's chains and cloths per method, if it has any.
pub fn snapshots(
    s: &SceneStudy,
    blocks: &[crate::scenario::Block],
    plane: [usize; 2],
) -> Option<SnapshotData> {
    if blocks.is_empty() {
        return None;
    }
    let panels = runs(s)
        .map(|run| SnapshotPanel {
            label: run.method.clone(),
            snapshots: run
                .trace
                .iter()
                .flat_map(|tr| tr.snapshots.iter())
                .map(|(t, x)| Snapshot {
                    t: *t,
                    lines: blocks
                        .iter()
                        .flat_map(|b| block_lines(b, x, plane))
                        .collect(),
                })
                .collect(),
            blowup_time: run.unstable_time,
        })
        .collect();
    Some(SnapshotData {
        axes: [AXES[plane[0]].into(), AXES[plane[1]].into()],
        panels,
    })
}

/// Height over time, the h₀·e^(2n) envelope and per-bounce restitution and penetration, for
/// scenes with obstacles (the first tracked particle of each method's contact metrics).
pub fn collision(s: &SceneStudy) -> Option<CollisionData> {
    let mut heights = Vec::new();
    let mut bounces = Vec::new();
    let mut envelope = None;
    for run in runs(s) {
        let Some(c) = &run.contacts else { continue };
        let Some(pb) = c.bounces.first() else {
            continue;
        };
        let mut h = Series::new(run.method.clone(), pb.heights.clone());
        h.blowup = blowup_at(run, h.points.last().copied());
        heights.push(h);
        if envelope.is_none() && pb.apexes.len() > 1 {
            envelope = Some(Series::new(
                format!("particle {}", pb.particle),
                pb.apexes.iter().map(|a| [a.t, a.predicted]).collect(),
            ));
        }
        let list: Vec<Bounce> = c
            .events
            .iter()
            .filter(|e| e.particle == pb.particle)
            .enumerate()
            .filter_map(|(k, e)| {
                e.restitution.map(|m| Bounce {
                    n: k as u32 + 1,
                    measured: m,
                    specified: e.expected_restitution,
                    penetration: e.max_penetration,
                })
            })
            .collect();
        bounces.push((run.method.clone(), list));
    }
    if heights.is_empty() {
        return None;
    }
    Some(CollisionData {
        heights,
        envelope: envelope.unwrap_or_else(|| Series::new("no apex", Vec::new())),
        bounces,
    })
}

/// Most impacts drawn per method (evenly strided in time order beyond that).
pub const MAX_IMPACT_POINTS: usize = 300;

/// Measured against expected restitution per impact (the impacts each run's contact summary
/// covers: approaching faster than its floor), for scenes with obstacles and impacts.
pub fn impacts(s: &SceneStudy) -> Option<ImpactData> {
    let mut measured = Vec::new();
    let mut deviation = Vec::new();
    // (obstacle, speed, expected) of every impact drawn, for the expected lines.
    let mut expected: Vec<(usize, f64, f64)> = Vec::new();
    for run in runs(s) {
        let Some(c) = &run.contacts else { continue };
        let list: Vec<_> = c
            .summary_impacts()
            .filter(|(e, m)| m.is_finite() && e.expected_restitution.is_finite())
            .collect();
        if list.is_empty() {
            continue;
        }
        let stride = list.len().div_ceil(MAX_IMPACT_POINTS).max(1);
        let drawn: Vec<_> = list.into_iter().step_by(stride).collect();
        let mut by_speed: Vec<[f64; 2]> = drawn.iter().map(|(e, m)| [e.v_in.abs(), *m]).collect();
        by_speed.sort_by(|a, b| a[0].total_cmp(&b[0]));
        measured.push(Series::new(run.method.clone(), by_speed));
        deviation.push(Series::new(
            run.method.clone(),
            drawn
                .iter()
                .map(|(e, m)| [e.t_in, m - e.expected_restitution])
                .collect(),
        ));
        expected.extend(
            drawn
                .iter()
                .map(|(e, _)| (e.obstacle, e.v_in.abs(), e.expected_restitution)),
        );
    }
    if measured.is_empty() {
        return None;
    }
    expected.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut lines: Vec<Guide> = Vec::new();
    for (k, v, e) in expected {
        let label = format!("expected e, obstacle {k}");
        match lines.last_mut() {
            Some(g) if g.label == label => g.points.push([v, e]),
            _ => lines.push(Guide {
                label,
                points: vec![[v, e]],
            }),
        }
    }
    for g in &mut lines {
        // A guide needs two points: widen a single impact speed into a short flat line.
        if g.points.len() == 1 {
            let [v, e] = g.points[0];
            g.points = vec![[0.95 * v, e], [1.05 * v, e]];
        }
    }
    Some(ImpactData {
        measured,
        expected: lines,
        deviation,
    })
}
