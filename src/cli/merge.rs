//! `springlab merge`: joins the shard directories of one sweep.

use anyhow::Result;
use springlab::measure::sweep::{merge, write_sweep};
use std::path::PathBuf;

/// Flags of `springlab merge`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Shard output directories (each with sweep.csv and shard.json).
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Output directory for the merged sweep.csv and summary.json.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    super::common::check_out(&a.out)?;
    let _lock = springlab::output::lock_dir(&a.out)?;
    let res = merge(&a.dirs)?;
    let files = write_sweep(&a.out, &res)?;
    println!(
        "merged {} shards: {} cases of {}",
        a.dirs.len(),
        res.rows.len(),
        res.plan.scenario
    );
    super::common::print_written(&files);
    Ok(())
}
