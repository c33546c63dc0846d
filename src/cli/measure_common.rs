//! Flags shared by the measuring subcommands (sweep, stability, advise, compare).

use anyhow::Result;
use std::path::{Path, PathBuf};

/// Method selection and options.
#[derive(Debug, Clone, clap::Args)]
pub struct MeasureArgs {
    #[command(flatten)]
    pub common: super::common::CommonArgs,
    /// Substeps per step. Rapier methods take this many solver substeps (default 4). In
    /// `compare` the step is a frame and every native method also splits it into this many
    /// equal steps (default 1; bit-identical to dt/N, every N-th state measured); `sweep`,
    /// `stability` and `advise` vary the step itself, so there it sets Rapier's only.
    #[arg(long, allow_negative_numbers = true, value_parser = super::method_args::substeps)]
    pub substeps: Option<usize>,
    #[command(flatten)]
    pub out: super::common::OutArg,
}

impl MeasureArgs {
    /// The shared settings; `--substeps` is also an engine's solver substeps.
    pub fn common(&self) -> Result<springlab::measure::Common> {
        self.common.common(self.substeps)
    }
    /// Substeps per frame for every method, when `--substeps` was given (`compare`).
    pub fn frame_substeps(&self) -> Option<u64> {
        self.substeps.map(|n| n as u64)
    }
    /// Refuses `--out` when it is a file (before any work).
    pub fn check_out(&self) -> Result<()> {
        self.out.check()
    }
    /// The output directory for `command` on `scenario`.
    pub fn out_dir(&self, scenario: &str, command: &str) -> PathBuf {
        self.out
            .or(|| Path::new("out").join(scenario).join(command))
    }
}

/// Formats an optional number for tables.
pub fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.3e}"))
}
