//! Flags shared by several subcommands and their validation into library values.

use anyhow::{bail, Result};
use springlab::error::num;
use springlab::method::MethodOptions;
use springlab::run::RunPlan;
use springlab::scenario::{Asked, Scenario, Timing};
use std::path::{Path, PathBuf};

/// A step in seconds as typed: a number (`0.01`, `1e-3`) or a fraction (`1/60`).
pub fn parse_seconds(s: &str) -> std::result::Result<f64, String> {
    let number = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("expected a number of seconds such as 0.01 or 1/60, got '{s}'"))
    };
    match s.split_once('/') {
        Some((a, b)) => {
            let (a, b) = (number(a)?, number(b)?);
            if b == 0.0 {
                return Err(format!("'{s}' divides by zero"));
            }
            Ok(a / b)
        }
        None => number(s),
    }
}

/// `--budget`: one flag, one default and one help text for every command that has a budget.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct BudgetArg {
    /// Time budget in modelled seconds of runs, summed over methods and steps (default 120).
    /// Each method's cost is modelled from its counted work before its runs (an engine's from
    /// the scene), so a re-run decides the same; the costliest runs that would pass the budget
    /// are left out (a sweep first drops their finest steps), named with the figure.
    #[arg(long, allow_negative_numbers = true, default_value_t = springlab::measure::probe::DEFAULT_BUDGET_SECONDS)]
    pub budget: f64,
}

/// `--blowup-factor`: one flag, one default and one help text for every command.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct BlowupArg {
    #[arg(
        long,
        default_value_t = springlab::run::DEFAULT_BLOWUP_FACTOR,
        allow_negative_numbers = true,
        help = springlab::run::verdict::BLOWUP_FACTOR_HELP
    )]
    blowup_factor: f64,
}

impl BlowupArg {
    /// The validated factor.
    pub fn value(&self) -> Result<f64> {
        springlab::run::verdict::check_factor(self.blowup_factor)
            .map_err(|why| anyhow::anyhow!("--blowup-factor: {why}"))
    }
}

/// `--out` of a command that writes one folder per scene (or per run): one flag, one help.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct OutArg {
    /// Output directory (default: out/<scenario>/<command>/; `run`: out/<scenario>/<method>/;
    /// `small-steps`: out/small_steps/).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

impl OutArg {
    /// Refuses `--out` when it cannot be a folder ([`check_out`]), before any work.
    pub fn check(&self) -> Result<()> {
        self.out.as_deref().map_or(Ok(()), check_out)
    }
    /// The folder: `--out`, else `default`.
    pub fn or(&self, default: impl FnOnce() -> PathBuf) -> PathBuf {
        self.out.clone().unwrap_or_else(default)
    }
}

/// `--duration`: simulated time, one flag, one help and one check for every command.
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct DurationArg {
    /// Simulated time in seconds (default: the scene's [run] duration).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
}

impl DurationArg {
    /// The duration asked for, refused unless finite and > 0.
    pub fn value(&self) -> Result<Option<f64>> {
        match self.duration {
            Some(d) if !(d.is_finite() && d > 0.0) => {
                bail!("--duration: must be a finite number > 0, got {}", num(d))
            }
            d => Ok(d),
        }
    }
}

/// `--methods`: which methods a command runs, one flag and one help for every command.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct MethodsArg {
    /// Methods, comma-separated (default: every one that applies to the scene and the
    /// command).
    #[arg(
        long = "methods",
        value_name = "METHODS",
        value_delimiter = ',',
        alias = "integrators"
    )]
    pub list: Vec<String>,
}

/// What every measuring command's flags share: the methods, their options, the blow-up
/// factor and the budget, declared once and flattened into each command.
#[derive(Debug, Clone, clap::Args)]
pub struct CommonArgs {
    #[command(flatten)]
    pub methods: MethodsArg,
    #[command(flatten)]
    pub method_options: super::method_args::MethodArgs,
    #[command(flatten)]
    pub blowup: BlowupArg,
    #[command(flatten)]
    pub budget: BudgetArg,
}

impl CommonArgs {
    /// The library's shared settings from the flags, checked (an option no listed method
    /// reads, a blow-up factor out of range), with progress on; `substeps` is also an
    /// engine's solver substeps.
    pub fn common(&self, substeps: Option<usize>) -> Result<springlab::measure::Common> {
        self.method_options.check_read_by(&self.methods.list)?;
        Ok(springlab::measure::Common {
            methods: self.methods.list.clone(),
            options: self.method_options.options(substeps),
            blowup_factor: self.blowup.value()?,
            progress: true,
            budget_seconds: Some(self.budget.budget),
            ..Default::default()
        })
    }
}

/// `--tolerance` and `--metric`: what a run is judged by, for every command that judges.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct JudgeArgs {
    /// Position tolerance (m; default the scene's [run] tolerance, else 1 % of its motion
    /// scale). Strain and energy are held to it over the motion scale.
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Which error: position (over the predictable range), strain, energy, statistics
    /// (position before the predictability horizon, the reference ensemble past it) or
    /// impacts (apex heights bounce by bounce); default statistics where the scene has a
    /// horizon before its end, impacts on scenes with obstacles and gravity, else position.
    #[arg(long)]
    pub metric: Option<springlab::measure::tolerance::Metric>,
}

/// Step and length flags; each overrides the scenario's `[run]` table.
#[derive(Debug, Clone, clap::Args)]
pub struct StepArgs {
    /// Frame step in seconds, a number or a fraction such as 1/60 (overrides [run].dt).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_seconds, conflicts_with = "hz")]
    pub dt: Option<f64>,
    /// Frame rate in Hz: the frame step is 1/HZ s (instead of --dt).
    #[arg(long, allow_negative_numbers = true)]
    pub hz: Option<f64>,
    /// Number of steps (overrides [run].steps / duration).
    #[arg(long, conflicts_with = "duration", allow_negative_numbers = true)]
    pub steps: Option<u64>,
    #[command(flatten)]
    pub duration: DurationArg,
    #[command(flatten)]
    pub blowup: BlowupArg,
    /// Substeps per frame: native methods take N equal steps of dt/N per frame (bit for bit
    /// the run at dt/N, every N-th state written), Rapier methods N solver substeps.
    /// Default: 1 for native methods, Rapier's own 4 for Rapier methods.
    #[arg(long, allow_negative_numbers = true, value_parser = super::method_args::substeps)]
    pub substeps: Option<usize>,
    #[command(flatten)]
    pub method_options: super::method_args::MethodArgs,
}

impl StepArgs {
    /// The run plan: flags first, then the scene's `[run]` (resolved by the library's one
    /// rule, [`Timing::resolve_asked`]), else an error saying what to add.
    pub fn plan(&self, scene: &Scenario) -> Result<RunPlan> {
        let hz_dt = match self.hz {
            Some(f) if !(f.is_finite() && f > 0.0) => {
                bail!("--hz: must be a finite frame rate > 0, got {}", num(f))
            }
            Some(f) => Some(1.0 / f),
            None => None,
        };
        let blowup_factor = self.blowup.value()?;
        let asked = Asked {
            dt: self.dt.or(hz_dt),
            step_flag: if self.hz.is_some() { "--hz" } else { "--dt" },
            steps: self.steps,
            duration: self.duration.duration,
        };
        let t = Timing::resolve_asked(scene, &asked)?;
        let mut plan = RunPlan::new(t.dt, t.steps);
        plan.blowup_factor = blowup_factor;
        plan.substeps = self.substeps.unwrap_or(1) as u64;
        Timing::substeps_within("--substeps", t.steps, plan.substeps)?;
        Ok(plan)
    }

    /// Method options from the flags; `--substeps` is also an engine's solver substeps.
    pub fn options(&self) -> MethodOptions {
        self.method_options.options(self.substeps)
    }
}

/// Refuses an output folder that cannot be one, before any work: `--out` (or a folder above
/// it) exists and is a file, is a symbolic link to nothing, or is the first existing folder
/// on the path and cannot be written (read-only filesystem, no permission). A folder that
/// does not exist yet is fine (it is created).
pub fn check_out(out: &Path) -> Result<()> {
    let at = |p: &Path| {
        if p == out {
            format!("{}", out.display())
        } else {
            format!("{}: {}", out.display(), p.display())
        }
    };
    for p in out.ancestors().filter(|p| !p.as_os_str().is_empty()) {
        match std::fs::metadata(p) {
            Ok(m) if m.is_dir() => {
                return writable(p)
                    .map_err(|e| anyhow::anyhow!("--out: {}: cannot write there: {e}", at(p)))
            }
            Ok(_) => bail!("--out: {} is a file, not a folder", at(p)),
            Err(_) => {
                if let Ok(target) = std::fs::read_link(p) {
                    bail!(
                        "--out: {} is a symbolic link to {}, which does not exist",
                        at(p),
                        target.display()
                    );
                }
            }
        }
    }
    Ok(())
}

/// Whether this process may create entries in the folder `dir` (the OS's own answer, which
/// also knows a read-only filesystem).
#[cfg(unix)]
fn writable(dir: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes())
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))?;
    // SAFETY: `c` is a valid NUL-terminated path that outlives the call.
    if unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) } == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// Elsewhere the first write says it.
#[cfg(not(unix))]
fn writable(_dir: &Path) -> std::io::Result<()> {
    Ok(())
}

/// Loads a scenario, adding nothing to the library's error (it already names the file).
pub fn load(path: &PathBuf) -> Result<Scenario> {
    Ok(Scenario::from_file(path)?)
}

/// Prints `wrote PATH` once per file written, in the order first written (a folder's
/// `timing.json` is rewritten with each document that has wall times).
pub fn print_written(files: &[PathBuf]) {
    let mut seen: Vec<&PathBuf> = Vec::new();
    for f in files {
        if !seen.contains(&f) {
            println!("wrote {}", f.display());
            seen.push(f);
        }
    }
}
