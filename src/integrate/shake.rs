//! The two constraint solves of RATTLE for rigid distance constraints |x_j − x_i| = L:
//! SHAKE's position stage (Ryckaert, Ciccotti & Berendsen 1977) and RATTLE's velocity stage
//! (Andersen 1983), each by Gauss–Seidel sweeps of exact one-constraint Newton updates, run
//! until every constraint holds to a relative tolerance.

use super::RattleSettings;
use crate::model::{DistanceConstraint, Vec3};

/// The constraint iteration did not converge in the allowed sweeps.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NotConverged;

/// Position stage: moves `x` (and `v` by the same displacement / h) along the constraint
/// directions `dir` of the start of the step, x_i += w_i δ n, x_j −= w_j δ n, until every
/// ||x_j − x_i| − L| ≤ `set.tol` · L, in at most `set.max_sweeps` sweeps. Each update is
/// Newton's on σ = (|d|² − L²)/2 along n. Returns the sweeps made.
pub(crate) fn positions(
    cons: &[DistanceConstraint],
    dir: &[Vec3],
    inv_mass: &[f64],
    x: &mut [Vec3],
    v: &mut [Vec3],
    h: f64,
    set: &RattleSettings,
) -> Result<u64, NotConverged> {
    let RattleSettings { tol, max_sweeps } = *set;
    for sweep in 0..max_sweeps {
        let mut converged = true;
        for (c, n) in cons.iter().zip(dir) {
            let (wi, wj) = (inv_mass[c.i], inv_mass[c.j]);
            if wi + wj == 0.0 {
                continue; // between fixed particles: nothing can move
            }
            let d = x[c.j] - x[c.i];
            if (d.norm() - c.length).abs() <= tol * c.length {
                continue;
            }
            converged = false;
            let slope = (wi + wj) * d.dot(n);
            if !(slope.abs() > 0.0 && slope.is_finite()) {
                return Err(NotConverged); // the rod turned by 90° within one step
            }
            let delta = 0.5 * (d.norm_squared() - c.length * c.length) / slope;
            let (di, dj) = (n * (wi * delta), n * (wj * delta));
            x[c.i] += di;
            x[c.j] -= dj;
            v[c.i] += di / h;
            v[c.j] -= dj / h;
        }
        if converged {
            return Ok(sweep as u64);
        }
    }
    Err(NotConverged)
}

/// Velocity stage: removes from `v` the relative velocity along each constraint at the new
/// positions `x` (v_i += w_i μ d, v_j −= w_j μ d), until every |d̂·(v_j − v_i)| ≤ `set.tol` ·
/// `scale`, in at most `set.max_sweeps` sweeps. Returns the sweeps made.
pub(crate) fn velocities(
    cons: &[DistanceConstraint],
    inv_mass: &[f64],
    x: &[Vec3],
    v: &mut [Vec3],
    scale: f64,
    set: &RattleSettings,
) -> Result<u64, NotConverged> {
    let RattleSettings { tol, max_sweeps } = *set;
    for sweep in 0..max_sweeps {
        let mut converged = true;
        for c in cons {
            let (wi, wj) = (inv_mass[c.i], inv_mass[c.j]);
            let d = x[c.j] - x[c.i];
            let len2 = d.norm_squared();
            if wi + wj == 0.0 || len2 == 0.0 {
                continue;
            }
            let rate = d.dot(&(v[c.j] - v[c.i]));
            if rate.abs() <= tol * scale * len2.sqrt() {
                continue;
            }
            converged = false;
            let mu = rate / ((wi + wj) * len2);
            v[c.i] += d * (wi * mu);
            v[c.j] -= d * (wj * mu);
        }
        if converged {
            return Ok(sweep as u64);
        }
    }
    Err(NotConverged)
}
