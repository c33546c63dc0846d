//! Options that some methods read when they are constructed.

/// Options that some integrators read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegratorOptions {
    /// Constraint projection sweeps per step (`verlet_constraints`).
    pub constraint_iterations: usize,
    /// Solver substeps per frame for physics-engine backends (Rapier's `num_solver_iterations`;
    /// 4 is Rapier's own default). Native methods are split by the runner instead
    /// (`RunPlan::substeps`); the command line sets both from one `--substeps`.
    pub substeps: usize,
    /// Substeps per step for `xpbd` (its own: one `xpbd` step of h is this many XPBD
    /// substeps of h / n, whatever the runner does with the frame).
    pub xpbd_substeps: usize,
    /// Constraint sweeps per substep for `xpbd`.
    pub xpbd_iterations: usize,
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            constraint_iterations: 20,
            substeps: 4,
            xpbd_substeps: 1,
            xpbd_iterations: 1,
        }
    }
}
