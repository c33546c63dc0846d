//! The Levenberg–Marquardt shift of the Newton matrix (Nocedal & Wright, Numerical
//! Optimization, 2nd ed., §3.4 "Newton's method with Hessian modification" and §10.3): the
//! stage solves ((1 + μ) M − h ∂f/∂v − h² ∂f/∂x) Δv = −G, a matrix positive definite once μ
//! exceeds the most negative mass-relative curvature of the exact one. Where the exact matrix
//! is positive definite (near a minimum of the incremental potential) μ falls to 0 and the
//! steps are Newton's own; where compressed springs make it indefinite, μ adds the mass term's
//! curvature evenly to every direction, rather than dropping the compressed springs' stiffness
//! (which over-stiffens every folding direction and left the iteration crawling at a tenth of
//! the residual per step).

/// The smallest shift tried when one is needed.
pub(super) const MIN_SHIFT: f64 = 1e-3;

/// The least shift after a line search cut the step below half: the quadratic model
/// overshot, so the next step is shortened in the soft directions only (the stiff ones, where
/// h²k ≫ m, hardly feel a shift of order one).
pub(super) const CUT_SHIFT: f64 = 0.1;

/// Shifts tried in one linear solve before it gives up (each at least doubles the last).
pub(super) const MAX_SHIFTS: usize = 40;

/// The shift to retry with after CG met the mass-relative curvature `curvature` = pᵀAp/pᵀMp
/// ≤ 0 on the matrix shifted by `shift`: twice past it, at least double, at least
/// [`MIN_SHIFT`]. The curvature is a Rayleigh quotient, so the exact matrix's lowest
/// mass-relative eigenvalue is at most it, and the retry may meet another direction.
pub(super) fn raised(shift: f64, curvature: f64) -> f64 {
    (2.0 * shift).max(shift - 2.0 * curvature).max(MIN_SHIFT)
}

/// The shift for the next iteration after a step of length `alpha` (1: the full step).
/// After a cut below half, the shift that would have made the full step about as short in
/// the soft directions, (1 + μ)/α − 1 (at least [`CUT_SHIFT`]): a stiff valley that curves
/// (a spinning stiff body) needs the damping on the next steps too. After a full step a
/// third of it (0 below [`MIN_SHIFT`]), so that it fades over a few good steps rather than
/// vanishing after one (the decrease of Nielsen's rule for Levenberg–Marquardt, 1999). Else
/// unchanged.
pub(super) fn after_step(shift: f64, alpha: f64) -> f64 {
    if alpha >= 1.0 {
        if shift < MIN_SHIFT {
            0.0
        } else {
            shift / 3.0
        }
    } else if alpha < 0.5 {
        ((1.0 + shift) / alpha - 1.0).max(CUT_SHIFT)
    } else {
        shift
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the rules as stated on [`raised`] and [`after_step`].
    #[test]
    fn shift_rises_past_the_curvature_and_falls_after_full_steps() {
        assert_eq!(raised(0.0, -0.3), 0.6);
        assert_eq!(raised(0.0, 0.0), MIN_SHIFT);
        assert_eq!(raised(1.0, -0.1), 2.0);
        assert_eq!(raised(1.0, -2.0), 5.0);
        assert_eq!(after_step(3.0, 1.0), 1.0);
        assert_eq!(after_step(MIN_SHIFT * 0.5, 1.0), 0.0);
        assert_eq!(after_step(0.0, 0.45), 1.0 / 0.45 - 1.0);
        assert_eq!(after_step(0.0, 0.1), 9.0);
        assert_eq!(after_step(1.0, 0.25), 7.0);
        assert_eq!(after_step(1.0, 0.6), 1.0);
    }
}
