//! The lowest eigenvalue of the mass-scaled Newton matrix M^(-1/2) A M^(-1/2) at an iterate,
//! bounded from above by Lanczos' lowest Ritz value (Golub & Van Loan, Matrix Computations,
//! 4th ed., §10.1; a Ritz value lies inside the spectrum): what a stage that ran
//! out of iterations reports, so that a reader can tell a root the solver missed (a positive
//! curvature of order one) from a stage whose matrix is nearly singular or indefinite there
//! (near 0 or below: no regular root nearby, or one at a saddle of the potential). The mass
//! term alone gives 1 in every direction.

use crate::model::parallel::dot;
use crate::model::{Jacobian, System, Vec3};
use nalgebra::{DMatrix, SymmetricEigen};

/// Lanczos steps. The lowest Ritz value bounds the lowest eigenvalue from above and falls
/// toward it as steps are added; on the 316×316 cloth, whose spectrum spans about 1 to 900,
/// 60 steps read 0.27 where 200 read 0.0013 at the same root, so a few hundred are taken
/// (each one matrix product; the estimate is made only for a stage that failed).
pub(super) const LANCZOS_STEPS: usize = 300;

/// The lowest eigenvalue of M^(-1/2) A M^(-1/2) over the free particles, A the Newton matrix
/// prepared in `jac`, from `LANCZOS_STEPS` Lanczos steps started at `start` (mass-scaled
/// inside; the residual is a good start: it leans on the directions the stage could not
/// settle). Allocates: it runs only to explain a failed stage. `None` where the start is zero.
pub(super) fn lowest_curvature(jac: &Jacobian, sys: &System, start: &[Vec3]) -> Option<f64> {
    let n = sys.len();
    let free = &sys.free;
    let scale: Vec<f64> = sys.mass.iter().map(|m| 1.0 / m.sqrt()).collect();
    let mut parts = Vec::new();
    let norm = |v: &[Vec3], parts: &mut Vec<f64>| dot(v, v, parts).sqrt();
    let mut q: Vec<Vec3> = (0..n)
        .map(|p| {
            if free[p] {
                start[p] * scale[p]
            } else {
                Vec3::zeros()
            }
        })
        .collect();
    let q_norm = norm(&q, &mut parts);
    if q_norm.is_nan() || q_norm <= 0.0 {
        return None;
    }
    q.iter_mut().for_each(|c| *c /= q_norm);
    let (mut prev, mut w, mut scaled) = (
        vec![Vec3::zeros(); n],
        vec![Vec3::zeros(); n],
        vec![Vec3::zeros(); n],
    );
    let (mut alphas, mut betas) = (Vec::new(), Vec::new());
    let mut beta = 0.0;
    let dofs = 3 * free.iter().filter(|&&f| f).count();
    for _ in 0..LANCZOS_STEPS.min(dofs) {
        for p in 0..n {
            scaled[p] = q[p] * scale[p];
        }
        jac.newton_matvec(free, &scaled, &mut w);
        for p in 0..n {
            w[p] = if free[p] {
                w[p] * scale[p] - prev[p] * beta
            } else {
                Vec3::zeros()
            };
        }
        let alpha = dot(&q, &w, &mut parts);
        for p in 0..n {
            w[p] -= q[p] * alpha;
        }
        alphas.push(alpha);
        beta = norm(&w, &mut parts);
        if beta.is_nan() || beta <= 1e-12 * alpha.abs().max(1.0) {
            break;
        }
        betas.push(beta);
        std::mem::swap(&mut prev, &mut q);
        for p in 0..n {
            q[p] = w[p] / beta;
        }
    }
    let k = alphas.len();
    let t = DMatrix::from_fn(k, k, |i, j| {
        if i == j {
            alphas[i]
        } else if i + 1 == j || j + 1 == i {
            betas[i.min(j)]
        } else {
            0.0
        }
    });
    Some(SymmetricEigen::new(t).eigenvalues.min())
}

#[cfg(test)]
mod tests {
    //! Oracle: the eigenvalues of the Newton matrix assembled densely from the matrix-free
    //! product, scaled by M^(-1/2) on both sides, by nalgebra's symmetric eigensolver.
    use super::*;
    use crate::integrate::newton::cg::tests::crumpled;

    /// Lanczos' lowest eigenvalue and the dense one, for the crumpled 5×5 cloth at `h` with
    /// `clamp`.
    fn both(h: f64, clamp: f64) -> (f64, f64) {
        let (sys, jac, dense, dofs) = crumpled(h, clamp);
        let w: Vec<f64> = dofs.iter().map(|&d| 1.0 / sys.mass[d / 3].sqrt()).collect();
        let scaled = DMatrix::from_fn(dofs.len(), dofs.len(), |i, j| dense[(i, j)] * w[i] * w[j]);
        let want = scaled.symmetric_eigen().eigenvalues.min();
        let start: Vec<Vec3> = (0..sys.len())
            .map(|p| Vec3::new((p as f64).sin(), (p as f64 * 0.3).cos(), 1.0))
            .collect();
        (lowest_curvature(&jac, &sys, &start).unwrap(), want)
    }

    /// The crumpled cloth's exact matrix at h = 0.2 s is indefinite: its lowest
    /// mass-relative eigenvalue is negative, and Lanczos finds it.
    #[test]
    fn lanczos_finds_the_negative_curvature_of_an_indefinite_matrix() {
        let (got, want) = both(0.2, 0.0);
        assert!(want < 0.0, "the test needs an indefinite matrix: {want}");
        assert!(
            (got - want).abs() <= 1e-6 * want.abs().max(1.0),
            "{got} vs {want}"
        );
    }

    /// Twin: the clamped matrix is positive definite, its lowest eigenvalue at least the mass
    /// term's 1, and Lanczos finds that too.
    #[test]
    fn lanczos_finds_the_lowest_curvature_of_a_positive_definite_matrix() {
        let (got, want) = both(0.2, 1.0);
        assert!(want >= 1.0 - 1e-9, "{want}");
        assert!(
            (got - want).abs() <= 1e-6 * want.abs().max(1.0),
            "{got} vs {want}"
        );
    }
}
