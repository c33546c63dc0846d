//! `--xpbd-substeps` and `--xpbd-iterations`: xpbd's own splitting of a step, separate from
//! `--substeps` (Rapier's) so that the two never change each other's meaning.

use anyhow::{bail, Result};

/// xpbd's substeps and iterations.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct XpbdArgs {
    /// Substeps per step for xpbd (one step of h is n XPBD substeps of h/n).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub xpbd_substeps: usize,
    /// Constraint sweeps per substep for xpbd.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub xpbd_iterations: usize,
}

impl XpbdArgs {
    /// The validated (substeps, iterations).
    pub fn values(&self) -> Result<(usize, usize)> {
        if self.xpbd_substeps == 0 {
            bail!("--xpbd-substeps: must be at least 1");
        }
        if self.xpbd_iterations == 0 {
            bail!("--xpbd-iterations: must be at least 1");
        }
        Ok((self.xpbd_substeps, self.xpbd_iterations))
    }
}
