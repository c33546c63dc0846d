//! Turns one scene's [`SceneResults`] into the plain chart data of [`super::data`].

use super::data::*;
use super::results::{RunRecord, SceneResults};
use super::summary::sweep_slope;
use crate::run::Status;

const AXES: [&str; 3] = ["x", "y", "z"];

fn blowup_at(run: &RunRecord, last: Option<[f64; 2]>) -> Option<BlowUp> {
    match (&run.status, last) {
        (Status::Unstable { time, .. }, Some(p)) => Some(BlowUp { x: *time, y: p[1] }),
        _ => None,
    }
}

fn time_series(run: &RunRecord, f: impl Fn(&super::results::Sample) -> Option<f64>) -> Series {
    let points: Vec<[f64; 2]> = run
        .samples
        .iter()
        .filter_map(|s| f(s).filter(|v| v.is_finite()).map(|v| [s.t, v]))
        .collect();
    let mut s = Series::new(run.backend.clone(), points);
    s.blowup = blowup_at(run, s.points.last().copied());
    s
}

/// Energy over time: totals per backend, and (when `terms`) the terms of the first backend.
pub fn energy(r: &SceneResults, terms: bool) -> EnergyData {
    let totals = r
        .runs
        .iter()
        .map(|run| time_series(run, |s| Some(s.energy.total)))
        .collect();
    let mut term_series = Vec::new();
    if terms {
        let pick = ["analytic", "rk4", "velocity_verlet", "verlet_constraints"]
            .iter()
            .find_map(|n| r.runs.iter().find(|run| run.backend == *n))
            .or(r.runs.first());
        if let Some(run) = pick {
            type Term = fn(&crate::run::EnergyRecord) -> f64;
            let all: [(&str, Term); 5] = [
                ("kinetic", |e| e.kinetic),
                ("gravity", |e| e.gravity),
                ("elastic", |e| e.elastic),
                ("dissipated", |e| e.dissipated),
                ("injected", |e| e.injected),
            ];
            for (name, f) in all {
                if run.samples.iter().any(|s| f(&s.energy) != 0.0) {
                    let mut s = time_series(run, |s| Some(f(&s.energy)));
                    s.label = format!("{name} ({})", run.backend);
                    term_series.push(s);
                }
            }
        }
    }
    EnergyData {
        totals,
        terms: term_series,
    }
}

/// Relative energy error |E(t) − E(0)| / E_scale per backend.
pub fn energy_error(r: &SceneResults) -> EnergyErrorData {
    let scale = r.energy_scale;
    let series = r
        .runs
        .iter()
        .map(|run| {
            let e0 = run.samples.first().map_or(0.0, |s| s.energy.total);
            time_series(run, |s| Some((s.energy.total - e0).abs() / scale))
        })
        .collect();
    EnergyErrorData {
        series,
        scale_note: format!("E_scale = {} J", super::finite::cell(Some(scale), 3)),
    }
}

/// RMS position error per backend (the exact reference itself left out).
pub fn position_error(r: &SceneResults) -> PositionErrorData {
    let series = r
        .runs
        .iter()
        .filter(|run| !(run.backend == "analytic" && r.reference.starts_with("analytic")))
        .map(|run| time_series(run, |s| s.pos_error))
        .collect();
    PositionErrorData {
        series,
        reference: r.reference.clone(),
    }
}

/// Convergence lines with fitted slopes and reference slopes dt^p for the orders present.
pub fn convergence(r: &SceneResults) -> Option<ConvergenceData> {
    let sweep = r.sweep.as_ref()?;
    let mut lines = Vec::new();
    for l in &sweep.lines {
        let points: Vec<[f64; 2]> = l
            .points
            .iter()
            .filter_map(|p| {
                p.error
                    .filter(|e| e.is_finite() && *e > 0.0)
                    .map(|e| [p.dt, e])
            })
            .collect();
        // Coarsest unstable step, marked at the top of the line.
        let unstable = l
            .points
            .iter()
            .filter(|p| p.blowup_time.is_some())
            .map(|p| p.dt)
            .reduce(f64::max);
        let top = points.iter().map(|p| p[1]).reduce(f64::max).unwrap_or(1.0);
        let mut series = Series::new(l.integrator.clone(), points);
        series.blowup = unstable.map(|dt| BlowUp { x: dt, y: top });
        lines.push(ConvergenceLine {
            series,
            fitted_slope: sweep_slope(sweep, &l.integrator),
            order: l.order,
        });
    }
    let mut orders: Vec<u32> = lines.iter().map(|l| l.order).collect();
    orders.sort();
    orders.dedup();
    let guides = orders
        .iter()
        .filter_map(|&p| {
            let anchor = lines
                .iter()
                .filter(|l| l.order == p)
                .flat_map(|l| l.series.points.iter())
                .filter(|q| q[1] > super::summary::ROUNDOFF_FLOOR)
                .min_by(|a, b| a[0].total_cmp(&b[0]))?;
            let (dt0, dt1) = (
                sweep
                    .lines
                    .iter()
                    .flat_map(|l| l.points.iter().map(|p| p.dt))
                    .fold(f64::INFINITY, f64::min),
                sweep
                    .lines
                    .iter()
                    .flat_map(|l| l.points.iter().map(|p| p.dt))
                    .fold(0.0, f64::max),
            );
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
        reference: sweep.reference.clone(),
    })
}

/// Work-precision lines from the sweep's stable points; `None` when no sweep run was stable.
pub fn work_precision(r: &SceneResults) -> Option<WorkPrecisionData> {
    let sweep = r.sweep.as_ref()?;
    if !sweep.lines.iter().any(|l| {
        l.points
            .iter()
            .any(|p| p.error.is_some_and(|e| e.is_finite() && e > 0.0))
    }) {
        return None;
    }
    Some(WorkPrecisionData {
        lines: sweep
            .lines
            .iter()
            .map(|l| WorkLine {
                label: l.integrator.clone(),
                points: l
                    .points
                    .iter()
                    .filter_map(|p| {
                        p.error
                            .filter(|e| e.is_finite() && *e > 0.0)
                            .map(|e| WorkPoint {
                                dt: p.dt,
                                error: e,
                                wall_seconds: p.wall_seconds,
                                force_evals: p.force_evals,
                            })
                    })
                    .collect(),
            })
            .collect(),
    })
}

/// Stability map from the scan.
pub fn stability(r: &SceneResults) -> Option<StabilityData> {
    let scan = r.scan.as_ref()?;
    Some(StabilityData {
        omega: scan.omega,
        omega_note: scan.omega_note.clone(),
        rows: scan
            .rows
            .iter()
            .map(|row| StabilityRow {
                integrator: row.integrator.clone(),
                cells: row
                    .cells
                    .iter()
                    .map(|&(h_omega, dt, stable)| StabilityCell {
                        h_omega,
                        dt,
                        stable,
                    })
                    .collect(),
                theory: row.theory,
            })
            .collect(),
    })
}

/// Paths of the tracked particles in the main plane.
pub fn paths(r: &SceneResults) -> PathData {
    let [a, b] = r.plane;
    let mut series = Vec::new();
    for run in &r.runs {
        for (k, path) in run.paths.iter().enumerate() {
            let points: Vec<[f64; 2]> = path
                .iter()
                .filter(|p| p[a].is_finite() && p[b].is_finite())
                .map(|p| [p[a], p[b]])
                .collect();
            let label = if r.tracked.len() > 1 {
                format!("{} particle {}", run.backend, r.tracked[k])
            } else {
                run.backend.clone()
            };
            let mut s = Series::new(label, points);
            s.blowup = match (&run.status, s.points.last()) {
                (Status::Unstable { .. }, Some(p)) => Some(BlowUp { x: p[0], y: p[1] }),
                _ => None,
            };
            series.push(s);
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

/// Snapshots of the scene's chains and cloths per backend, if it has any.
pub fn snapshots(r: &SceneResults) -> Option<SnapshotData> {
    if r.blocks.is_empty() {
        return None;
    }
    let panels = r
        .runs
        .iter()
        .map(|run| SnapshotPanel {
            label: run.backend.clone(),
            snapshots: run
                .snapshots
                .iter()
                .map(|(t, x)| Snapshot {
                    t: *t,
                    lines: r
                        .blocks
                        .iter()
                        .flat_map(|b| block_lines(b, x, r.plane))
                        .collect(),
                })
                .collect(),
            blowup_time: match &run.status {
                Status::Unstable { time, .. } => Some(*time),
                Status::Ok => None,
            },
        })
        .collect();
    Some(SnapshotData {
        axes: [AXES[r.plane[0]].into(), AXES[r.plane[1]].into()],
        panels,
    })
}

/// Height over time, the h₀·e^(2n) envelope and per-bounce restitution and penetration, for
/// scenes with obstacles (the first tracked particle of each backend's contact metrics).
pub fn collision(r: &SceneResults) -> Option<CollisionData> {
    let with: Vec<(&RunRecord, &crate::measure::contacts::ContactReport)> = r
        .runs
        .iter()
        .filter_map(|run| run.contacts.as_ref().map(|c| (run, c)))
        .collect();
    if with.is_empty() {
        return None;
    }
    let mut heights = Vec::new();
    let mut bounces = Vec::new();
    let mut envelope = None;
    for (run, c) in &with {
        let Some(pb) = c.bounces.first() else {
            continue;
        };
        let mut s = Series::new(run.backend.clone(), pb.heights.clone());
        s.blowup = blowup_at(run, s.points.last().copied());
        heights.push(s);
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
        bounces.push((run.backend.clone(), list));
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
