//! `springlab run`: one scenario, one method, full outputs.

use super::common::{load, StepArgs};
use super::measure_common::fmt_opt;
use anyhow::{bail, Result};
use springlab::output::{write_run, RunFiles, RunSummary};
use std::path::PathBuf;

/// Flags of `springlab run`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Method name (see `springlab list`).
    #[arg(long, short, alias = "integrator", short_alias = 'i')]
    pub method: String,
    #[command(flatten)]
    pub step: StepArgs,
    /// Write every k-th step to trajectory.csv and energy.csv (the last step always); default
    /// 1. Outputs projected above 100 MB need it written out (or --force).
    #[arg(long, allow_negative_numbers = true)]
    pub every: Option<u64>,
    /// Write the outputs even when they are projected past the free space, the process's
    /// file-size limit or 100 MB.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub out: super::common::OutArg,
    /// Stop at the first unstable verdict instead of computing on until the state diverges or
    /// passes the --blowup-factor cap (the measuring commands always stop there).
    #[arg(long)]
    pub stop_at_verdict: bool,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    a.out.check()?;
    a.step
        .method_options
        .check_read_by(std::slice::from_ref(&a.method))?;
    let scene = load(&a.scenario)?;
    let mut plan = a.step.plan(&scene)?;
    plan.stop_at_verdict = a.stop_at_verdict;
    let every = a.every.unwrap_or(1);
    if every == 0 {
        bail!("--every: must be at least 1");
    }
    let mut stepper = springlab::method::create(&a.method, &a.step.options())?;
    let sys = scene.build();
    if let Err(reason) = stepper.check(&sys) {
        return Err(springlab::Error::Unsupported {
            method: stepper.name().into(),
            scenario: scene.name.clone(),
            reason,
        }
        .into());
    }
    let name = stepper.name().to_string();
    let dir = a
        .out
        .or(|| PathBuf::from("out").join(&scene.name).join(&name));
    let _lock = springlab::output::lock_dir(&dir)?;
    let ask = springlab::output::SizeAsk {
        every_given: a.every.is_some(),
        force: a.force,
    };
    let (size, warning) = springlab::output::size_guard(&dir, sys.len(), plan.steps, every, ask)?;
    if let Some(w) = warning {
        eprintln!("warning: {w}");
    }
    println!("{size}");
    let mut files = RunFiles::create(&dir, every, plan.dt)?;
    // Collision metrics only when the scene has obstacles (contacts.json).
    let mut metrics = springlab::measure::contacts::ContactMetrics::new(&sys, plan.dt);
    let s0 = scene.initial_state();
    let mut quality = springlab::measure::QualityObserver::new(&sys, &s0, plan.dt, plan.duration());
    let mut bar = springlab::run::ProgressObserver::new(
        plan.steps,
        &format!("{} with {name}", scene.name),
        true,
    );
    let out = springlab::run::run(
        &sys,
        &mut stepper,
        s0,
        &plan,
        &mut (&mut files, (metrics.as_mut(), (&mut quality, &mut bar))),
    )?;
    files.commit()?;
    let contacts = metrics.as_ref().map(|m| m.report());
    if let Some(r) = &contacts {
        springlab::measure::contacts::write_report(&dir, r)?;
        print_contacts(r);
    }
    // Quality observables as compare reports them: none for a run that is not ok.
    let finished = out.status.is_ok() && out.steps_done == plan.steps;
    let q = finished.then(|| quality.quality());
    // Rapier splits frames itself with its solver substeps (the options'); native methods
    // with the plan's.
    let substeps = if stepper.info.splits_frames {
        a.step.options().substeps as u64
    } else {
        plan.substeps
    };
    let summary = RunSummary {
        substeps,
        events: sys.events.label(),
        strain_max: q.map(|q| q.strain_max),
        penetration_max: contacts
            .as_ref()
            .filter(|_| finished)
            .map(|c| c.penetration_max()),
        energy_drift_rate: q.map(|q| q.energy_drift_rate),
        rest_jitter: q.map(|q| q.rest_jitter),
        ..RunSummary::new(&scene.name, &name, plan.dt, plan.steps, &out)
    };
    write_run(&dir, &summary)?;
    print_run(&summary, &out);
    println!("wrote {}", dir.display());
    Ok(())
}

/// Prints the collision metrics of a scene with obstacles.
fn print_contacts(r: &springlab::measure::contacts::ContactReport) {
    println!(
        "contacts ({}): {} events ({} open), restitution {:.4} measured vs {:.4} expected (mean of {} impacts), max penetration {:.3e} m, {} tunnelling",
        r.response, r.events_total, r.open_contacts, r.restitution.mean, r.expected_restitution.mean,
        r.restitution.count, r.penetration_max(), r.tunnelling_count
    );
}

/// Prints the run's summary lines: steps and cost, status, energy account and quality.
fn print_run(summary: &RunSummary, out: &springlab::run::RunOutcome) {
    println!(
        "{} with {}: dt = {} s per frame, {} substep(s) per frame, {} frames, {} force evaluations, {:.3} ms modelled, {:.3} ms stepping ({:.3e} s per frame)",
        summary.scenario,
        summary.method,
        summary.dt,
        summary.substeps,
        out.steps_done,
        out.force_evals,
        out.modelled_seconds * 1e3,
        out.wall_seconds * 1e3,
        summary.wall_seconds_per_frame
    );
    println!("status: {}", out.status);
    let (e0, e1) = (out.initial_energy, out.final_energy);
    let change = match summary.energy_change {
        Some(d) => format!(
            "change {d:.3e} J{}",
            summary
                .energy_error
                .map_or(String::new(), |r| format!(", relative {r:.3e}"))
        ),
        None => format!(
            "change — (stopped after {} of {} frames)",
            out.steps_done, summary.steps
        ),
    };
    println!(
        "energy: total {:.6e} J -> {:.6e} J ({change}); kinetic {:.4e}, gravity {:.4e}, elastic {:.4e}, dissipated {:.4e}, injected {:.4e}",
        e0.total, e1.total, e1.kinetic, e1.gravity, e1.elastic, e1.dissipated, e1.injected
    );
    println!(
        "quality: strain max {}, penetration max {} m, energy drift rate {} J/s, rest jitter {}",
        fmt_opt(summary.strain_max),
        fmt_opt(summary.penetration_max),
        fmt_opt(summary.energy_drift_rate),
        fmt_opt(summary.rest_jitter)
    );
}
