//! Trust-region bookkeeping of the Newton stage (Nocedal & Wright, Numerical Optimization,
//! 2nd ed., Alg. 4.1 and 7.2): the Steihaug–Toint CG inside [`super::cg`] follows negative
//! curvature of the Newton matrix to the region's boundary instead of clamping it, and the
//! Newton loop accepts or rejects the step on the ratio of the incremental potential's actual
//! to predicted decrease. The region is measured in the preconditioner's norm
//! ‖s‖_P = √(sᵀPs), in which the CG iterates' norms grow monotonically (Steihaug 1983).

/// Accept a step whose actual/predicted decrease ratio reaches this (N&W Alg. 4.1's η).
pub(super) const ETA: f64 = 0.1;

/// A strategy has stalled when the residual merit GᵀM⁻¹G has not fallen below
/// [`STALL_FACTOR`] × its best value within this many Newton iterations.
pub(super) const STALL_ITERATIONS: usize = 6;

/// The merit fraction a strategy must reach within [`STALL_ITERATIONS`]: ½, i.e. the residual
/// norm falling by √2 (a linear rate better than 0.94 per iteration).
pub(super) const STALL_FACTOR: f64 = 0.5;

/// Watches the residual merit for a stalled strategy. Measured on the 316² cloth at 1/60 s
/// (`springlab bench-ratios --implicit-sizes 316 --implicit-steps 180`): clamped Newton
/// circles a saddle of the incremental potential on some stages (step 21: 114 iterations
/// alone, 24 once the trust region takes over), while on others the trust region crawls with
/// radii of a few percent of a step where clamped Newton converges (steps 70 and 179: 169 and
/// 298 trust-region iterations against 21 and 17 clamped ones). Neither strategy is the
/// better one throughout, so a stage switches to the other each time the one it runs stalls.
#[derive(Debug, Clone, Copy)]
pub(super) struct Stall {
    best: f64,
    since: usize,
}

impl Stall {
    /// A watcher with no merit seen yet.
    pub(super) fn new() -> Self {
        Stall {
            best: f64::INFINITY,
            since: 0,
        }
    }

    /// Records the merit at the current iterate; true when the running strategy has stalled
    /// (the watcher then restarts from this merit, for the strategy switched to).
    pub(super) fn stalled(&mut self, merit: f64) -> bool {
        if merit < STALL_FACTOR * self.best {
            self.best = merit;
            self.since = 0;
            return false;
        }
        self.since += 1;
        if self.since >= STALL_ITERATIONS {
            self.best = merit;
            self.since = 0;
            return true;
        }
        false
    }
}

/// The positive root τ of ‖x + τp‖² = Δ², from ‖x‖², xᵀp, pᵀp in any inner product (here
/// the P one): the step from an interior iterate x along p to the boundary (N&W Alg. 7.2).
/// Returns 0 when x already lies on or outside the boundary.
pub(super) fn to_boundary(xx: f64, xp: f64, pp: f64, radius: f64) -> f64 {
    let c = xx - radius * radius;
    if c >= 0.0 || pp <= 0.0 {
        return 0.0;
    }
    // Roots of pp τ² + 2 xp τ + c = 0 with c < 0: one positive, one negative. The form
    // −c / (xp + √·) avoids cancellation when xp > 0.
    let disc = (xp * xp - pp * c).sqrt();
    if xp > 0.0 {
        -c / (xp + disc)
    } else {
        (disc - xp) / pp
    }
}

/// The radius after a step of P-norm `step` with ratio `rho` that ended on the boundary or not
/// (N&W Alg. 4.1): a quarter of the step after a poor ratio, doubled after a very good
/// boundary step, else unchanged.
pub(super) fn update_radius(radius: f64, step: f64, rho: f64, on_boundary: bool) -> f64 {
    if rho < 0.25 {
        0.25 * step
    } else if rho > 0.75 && on_boundary {
        2.0 * radius
    } else {
        radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the definition of the boundary, |x + τp| = Δ in the Euclidean product, checked
    /// by recomputing the norm from the vectors (not from the inputs the root used).
    #[test]
    fn boundary_root_lands_on_the_sphere() {
        let cases = [
            ([0.3, -0.2, 0.1], [1.0, 2.0, -0.5], 1.5),
            ([0.0, 0.0, 0.0], [0.0, 3.0, 4.0], 2.0),
            ([0.5, 0.5, 0.0], [-1.0, -1.0, 0.0], 1.0), // p points back through the origin
        ];
        for (x, p, r) in cases {
            let d = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>();
            let tau = to_boundary(d(x, x), d(x, p), d(p, p), r);
            assert!(tau > 0.0);
            let y: Vec<f64> = (0..3).map(|i| x[i] + tau * p[i]).collect();
            let norm = y.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!((norm - r).abs() <= 1e-14 * r, "|x + τp| = {norm}, Δ = {r}");
        }
        // Outside already: no step.
        assert_eq!(to_boundary(4.0, 1.0, 1.0, 1.0), 0.0);
    }

    /// Oracle: the stall rule as stated on [`Stall`]: a merit that halves resets the count; six
    /// iterations without halving are a stall, after which the count restarts from there.
    #[test]
    fn stall_is_six_iterations_without_halving() {
        let mut s = Stall::new();
        assert!(!s.stalled(1.0)); // first merit: the best so far
        assert!(!s.stalled(0.4)); // halved: reset
        for _ in 0..5 {
            assert!(!s.stalled(0.3)); // 0.3 > 0.5 × 0.4: no progress counted
        }
        assert!(s.stalled(0.3)); // the sixth: stalled
        assert!(!s.stalled(0.14)); // below 0.5 × 0.3, the restarted best
        let mut slow = Stall::new();
        // At 0.95 per iteration six iterations give 0.735, not ½: a stall at the 6th, and the
        // next 5 (to k = 11) do not reach ½ of the restarted best either.
        let stalls: Vec<i32> = (0..12).filter(|&k| slow.stalled(0.95f64.powi(k))).collect();
        assert_eq!(stalls, vec![6]);
    }

    /// Oracle: N&W Alg. 4.1's radius rules, stated there.
    #[test]
    fn radius_follows_algorithm_4_1() {
        assert_eq!(update_radius(1.0, 0.8, 0.1, false), 0.2);
        assert_eq!(update_radius(1.0, 1.0, 0.9, true), 2.0);
        assert_eq!(update_radius(1.0, 0.5, 0.9, false), 1.0);
        assert_eq!(update_radius(1.0, 1.0, 0.5, true), 1.0);
    }
}
