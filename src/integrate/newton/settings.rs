//! The implicit core's settings: Newton's stops and limits, and which linear solver each
//! Newton iteration uses.

/// Settings of the implicit solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplicitSettings {
    /// Iterations of each solve of a stage: its direct Newton iteration, each patch
    /// elimination (trust-region iterations, `patch.rs`) and each root-path piece.
    pub max_newton: usize,
    /// The root tolerance every accepted stage meets, whichever stop ends it: the mass-weighted
    /// RMS of M⁻¹G ≤ `root_tol` × the stage's velocity scale (the largest |v̂|, |v'|, β|f_p|/m_p
    /// or β|g| component).
    /// The cheap stops (a small update, the error estimate) are taken only there; a stage that
    /// runs out of iterations above it fails.
    pub root_tol: f64,
    /// Newton stops when max |M⁻¹ G| ≤ `newton_tol` × the velocity scale, or when an update
    /// is below `newton_tol` × |v| plus the round-off floor 16ε·max|x|/h.
    pub newton_tol: f64,
    /// Newton also stops, once at [`ImplicitSettings::root_tol`], when |M⁻¹ G| ≤ `kappa` × the
    /// step's truncation-error estimate
    /// ½ |v' − v_pred| (v_pred: the first-order explicit predictor), both in the mass-weighted
    /// RMS norm √(Σ m |·|² / Σ m), so the solver error stays `kappa` times below the method's
    /// own error (Hairer & Wanner, Solving ODEs II, §IV.8, stop Newton at κ ∈ [0.01, 0.1] of
    /// the error tolerance, in an RMS norm; we take 1 % of the error itself). The estimate is
    /// first order; a second-order method's error is smaller by about hω, so second-order
    /// methods stop at `kappa²` × the estimate (see `Stop::SecondOrder`).
    pub kappa: f64,
    /// CG stops at this relative residual (preconditioned norm).
    pub cg_tol: f64,
    /// CG iterations before giving up on one linear solve.
    pub max_cg: usize,
    /// Halvings of a Newton update the line search (on the residual merit or, by Armijo's
    /// rule, the incremental potential) tries after the full step; the last trial is taken
    /// if none passes.
    pub max_halvings: usize,
    /// Largest inexact-Newton forcing η: each linear solve stops once its residual is below
    /// η |G| (Eisenstat–Walker; smaller η as Newton converges) or half the error-based stop.
    pub forcing: f64,
    /// The linear solver of each Newton iteration.
    pub solver: LinearSolver,
    /// `LinearSolver::Cholesky` (the `direct-solver` feature): CG iterations a reused (stale)
    /// factor may take before it is refactored at the current iterate.
    pub refactor_after: usize,
}

impl Default for ImplicitSettings {
    fn default() -> Self {
        ImplicitSettings {
            max_newton: 50,
            root_tol: 1e-6,
            newton_tol: 1e-10,
            kappa: 1e-2,
            cg_tol: 1e-8,
            max_cg: 2000,
            max_halvings: 4,
            forcing: 0.1,
            solver: LinearSolver::default(),
            refactor_after: 10,
        }
    }
}

/// Which linear solver the implicit core uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolver {
    /// Matrix-free CG preconditioned by the inverse 3×3 diagonal blocks, clamping compressed
    /// springs in steps on non-positive curvature: as fast as IC(0) on the large cloths, with
    /// no factor to build (module docs of `linsolve.rs` give the measured choice).
    #[default]
    BlockJacobiCg,
    /// CG preconditioned by a block incomplete Cholesky factor IC(0) of the clamped Newton
    /// matrix, refactored at every Newton iteration, clamping as
    /// [`LinearSolver::BlockJacobiCg`] does: a quarter of the iterations, a factor each
    /// Newton iteration (module docs).
    BlockIc0Cg,
    /// CG preconditioned by a reused sparse Cholesky factor of the clamped Newton matrix;
    /// projected Newton (the clamped system, solved directly) where the exact matrix is
    /// indefinite. Built with the `direct-solver` feature only.
    #[cfg(feature = "direct-solver")]
    Cholesky,
}

impl LinearSolver {
    /// Every solver compiled in, the default first.
    pub const ALL: &'static [LinearSolver] = &[
        LinearSolver::BlockJacobiCg,
        LinearSolver::BlockIc0Cg,
        #[cfg(feature = "direct-solver")]
        LinearSolver::Cholesky,
    ];

    /// The names of [`LinearSolver::ALL`], in its order: what `--linear-solver` takes.
    pub const NAMES: &'static [&'static str] = &[
        "block_jacobi_cg",
        "block_ic0_cg",
        #[cfg(feature = "direct-solver")]
        "cholesky_pcg",
    ];

    /// The name bench reports print and `--linear-solver` takes.
    pub fn name(self) -> &'static str {
        match self {
            LinearSolver::BlockJacobiCg => "block_jacobi_cg",
            LinearSolver::BlockIc0Cg => "block_ic0_cg",
            #[cfg(feature = "direct-solver")]
            LinearSolver::Cholesky => "cholesky_pcg",
        }
    }

    /// The solver called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|s| s.name() == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the definition of `NAMES`: every solver's own name, in `ALL`'s order, the
    /// default first (a choice option's first name is its default).
    #[test]
    fn names_are_the_solvers_own_in_order() {
        let names: Vec<&str> = LinearSolver::ALL.iter().map(|s| s.name()).collect();
        assert_eq!(names, LinearSolver::NAMES);
        assert_eq!(LinearSolver::NAMES[0], LinearSolver::default().name());
    }
}
