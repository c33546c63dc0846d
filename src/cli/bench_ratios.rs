//! `springlab bench-ratios`: the cost ratios that have targets, measured in one run
//! with the contenders interleaved (see [`springlab::perf::ratios`]), as `ratios.csv` and
//! `implicit.csv` (written atomically) and a table on stdout.

use anyhow::{bail, Result};
use springlab::integrate::{ImplicitSettings, LinearSolver};
use springlab::method::options::{OptionValue, LINEAR_SOLVER, MAX_NEWTON};
use springlab::output::write_atomic;
use springlab::perf::ratios::{
    best_loop, fresh_stepper, hand_loop, implicit_cost, interleaved_stats, on_threads, stepping,
    Contender, ImplicitCost, RoundTimes,
};
use springlab::perf::{bench_dt, cloth};
use std::path::PathBuf;
use std::time::Instant;

/// The implicit steps that have a cost target, as (method, cloth side, target in symplectic
/// steps of the same cloth): implicit Euler on the 100×100 cloth within 60.
const IMPLICIT_TARGETS: [(&str, usize, &str); 1] = [("implicit_euler", 100, "<= 60")];

/// Flags of `springlab bench-ratios`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Interleaved rounds per ratio (the minimum and the median per contender are kept).
    #[arg(long, default_value_t = 11, allow_negative_numbers = true)]
    pub rounds: usize,
    /// Cloth size n for the hand-loop and Rapier ratios.
    #[arg(long, default_value_t = 100, allow_negative_numbers = true)]
    pub size: usize,
    /// Cloth size n for the 1→2 thread speedup.
    #[arg(long, default_value_t = 316, allow_negative_numbers = true)]
    pub thread_size: usize,
    /// Cloth sizes for the implicit methods at dt = 1/60, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "32,100,316",
        allow_negative_numbers = true
    )]
    pub implicit_sizes: Vec<usize>,
    /// Implicit methods timed at each size, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "implicit_euler,implicit_midpoint,bdf2,linear_implicit_euler"
    )]
    pub implicit_methods: Vec<String>,
    /// Linear solver of the implicit methods: block_jacobi_cg (the default), block_ic0_cg, or
    /// cholesky_pcg (a build with `--features direct-solver` only).
    #[arg(long, default_value = "block_jacobi_cg")]
    pub implicit_solver: String,
    /// Steps per implicit method and size, from rest (180 = 3 s at 1/60: the 316×316
    /// cloth's run, which `implicit_euler` and `bdf2` complete; see docs/performance.md).
    #[arg(long, default_value_t = 10, allow_negative_numbers = true)]
    pub implicit_steps: usize,
    /// Newton iterations each solve of a step may take (`ImplicitSettings::max_newton`;
    /// default: the implicit methods' own, 50).
    #[arg(long, allow_negative_numbers = true)]
    pub implicit_max_newton: Option<usize>,
    /// Leave out the Rapier ratio.
    #[arg(long)]
    pub no_rapier: bool,
    /// Output directory.
    #[arg(long, default_value = "out/bench-ratios")]
    pub out: PathBuf,
}

/// One measured ratio: both sides' minimum and median time per step over the rounds.
struct Row {
    measure: &'static str,
    n: usize,
    num: String,
    num_s: RoundTimes,
    den: String,
    den_s: RoundTimes,
    target: &'static str,
}

impl Row {
    /// The ratio of the minima (the target is judged on it).
    fn ratio(&self) -> f64 {
        self.num_s.min / self.den_s.min
    }
    /// The ratio of the medians.
    fn ratio_median(&self) -> f64 {
        self.num_s.median / self.den_s.median
    }
    fn met(&self) -> bool {
        let r = self.ratio();
        match self.target.split_once(' ') {
            Some(("<=", v)) => v.parse().is_ok_and(|v: f64| r <= v),
            Some((">=", v)) => v.parse().is_ok_and(|v: f64| r >= v),
            _ => true,
        }
    }
}

/// Runs the command: the step and thread ratios, then the implicit table, each measured in
/// one interleaved run; both tables written atomically.
pub fn run(a: Args) -> Result<()> {
    super::common::check_out(&a.out)?;
    let solver = checked(&a)?;
    let _lock = springlab::output::lock_dir(&a.out)?;
    let t_all = Instant::now();
    let mut rows = step_rows(&a)?;
    rows.extend(best_loop_rows(&a)?);
    rows.extend(thread_rows(&a)?);
    print_rows(&rows);
    let implicit = implicit_table(&a, solver)?;
    let (p1, p2) = (a.out.join("ratios.csv"), a.out.join("implicit.csv"));
    write_atomic(&p1, &ratios_csv(&rows)?)?;
    write_atomic(&p2, &implicit)?;
    println!(
        "wrote {} and {} in {:.1} s ({} rayon threads available)",
        p1.display(),
        p2.display(),
        t_all.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    Ok(())
}

/// The validated flags: cloth sizes, counts, the implicit solver and methods.
fn checked(a: &Args) -> Result<LinearSolver> {
    let ok = |n: usize| (2..=1000).contains(&n);
    if !ok(a.size) || !ok(a.thread_size) || a.implicit_sizes.iter().any(|&n| !ok(n)) {
        bail!(
            "--size, --thread-size, --implicit-sizes: each cloth size must be between 2 and 1000"
        );
    }
    if a.rounds == 0 || a.implicit_steps == 0 || a.implicit_max_newton == Some(0) {
        bail!("--rounds, --implicit-steps and --implicit-max-newton must be at least 1");
    }
    let Some(solver) = LinearSolver::from_name(&a.implicit_solver) else {
        bail!(
            "--implicit-solver: unknown solver {:?} (one of: {}; cholesky_pcg needs a build with `--features direct-solver`)",
            a.implicit_solver,
            LinearSolver::ALL
                .iter()
                .map(|s| s.name())
                .collect::<Vec<_>>()
                .join(", ")
        );
    };
    for m in &a.implicit_methods {
        let implicit = springlab::method::Registry::builtin()
            .info(m)
            .is_ok_and(|i| i.implicit);
        if !implicit {
            bail!("--implicit-methods: {m:?} is not an implicit method with a Newton solver");
        }
    }
    Ok(solver)
}

/// The symplectic step against the hand-written loop (same cloth, same dt), and one
/// rapier_impulse frame against one symplectic step at 1/60 s (a short batch from rest, so
/// the explicit step stays finite while it is timed).
fn step_rows(a: &Args) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    let scene = cloth(a.size);
    let (sys, s0) = (scene.build(), scene.initial_state());
    let h = bench_dt("symplectic_euler");
    let batch = (2_000_000 / sys.springs.len().max(1)).clamp(5, 200);
    let mut c: Vec<Contender> = vec![
        stepping(&sys, &s0, fresh_stepper("symplectic_euler")?, h, batch),
        hand_loop(&sys, &s0, h, batch),
    ];
    let t = interleaved_stats(a.rounds, &mut c)?;
    rows.push(Row {
        measure: "step_vs_hand_loop",
        n: a.size,
        num: "symplectic_euler".into(),
        num_s: t[0],
        den: "hand_loop".into(),
        den_s: t[1],
        target: "<= 1.2",
    });
    if !a.no_rapier {
        let frame = 1.0 / 60.0;
        let mut c: Vec<Contender> = vec![
            stepping(&sys, &s0, fresh_stepper("rapier_impulse")?, frame, 1),
            stepping(&sys, &s0, fresh_stepper("symplectic_euler")?, frame, 5),
        ];
        let t = interleaved_stats(a.rounds.min(5), &mut c)?;
        rows.push(Row {
            measure: "rapier_frame_vs_step",
            n: a.size,
            num: "rapier_impulse (4 substeps)".into(),
            num_s: t[0],
            den: "symplectic_euler".into(),
            den_s: t[1],
            target: ">= 100",
        });
    }
    Ok(rows)
}

/// The symplectic step against the best exact loop ([`springlab::perf::stencil`]) on the
/// small and the large cloth, both on one thread.
fn best_loop_rows(a: &Args) -> Result<Vec<Row>> {
    let h = bench_dt("symplectic_euler");
    let mut rows = Vec::new();
    for n in [a.size, a.thread_size] {
        let scene = cloth(n);
        let (sys, s0) = (scene.build(), scene.initial_state());
        let batch = (2_000_000 / sys.springs.len().max(1)).clamp(3, 200);
        let Some(best) = best_loop(&sys, &s0, n, h, batch) else {
            bail!("the {n}×{n} benchmark cloth has no stencil form");
        };
        let mut c: Vec<Contender> = vec![
            on_threads(
                1,
                stepping(&sys, &s0, fresh_stepper("symplectic_euler")?, h, batch),
            )?,
            on_threads(1, best)?,
        ];
        let t = interleaved_stats(a.rounds, &mut c)?;
        rows.push(Row {
            measure: "step_vs_best_loop",
            n,
            num: "symplectic_euler, 1 thread".into(),
            num_s: t[0],
            den: "stencil loop, 1 thread".into(),
            den_s: t[1],
            target: "<= 1.5",
        });
    }
    Ok(rows)
}

/// 1 → 2 threads on the large cloth: one force evaluation and one symplectic step.
fn thread_rows(a: &Args) -> Result<Vec<Row>> {
    let h = bench_dt("symplectic_euler");
    let big = cloth(a.thread_size);
    let (bsys, bs0) = (big.build(), big.initial_state());
    let bbatch = (4_000_000 / bsys.springs.len().max(1)).clamp(3, 200);
    let forces = |threads| -> Result<Contender> {
        let mut acc = vec![springlab::model::Vec3::zeros(); bsys.len()];
        let (sys, s0) = (&bsys, &bs0);
        Ok(on_threads(
            threads,
            Box::new(move || {
                let t0 = Instant::now();
                for _ in 0..bbatch {
                    std::hint::black_box(sys.accelerations(&s0.x, &s0.v, &mut acc));
                }
                Ok(t0.elapsed().as_secs_f64() / bbatch as f64)
            }),
        )?)
    };
    let steps = |threads| -> Result<Contender> {
        Ok(on_threads(
            threads,
            stepping(&bsys, &bs0, fresh_stepper("symplectic_euler")?, h, bbatch),
        )?)
    };
    let mut c: Vec<Contender> = vec![forces(1)?, forces(2)?, steps(1)?, steps(2)?];
    let t = interleaved_stats(a.rounds, &mut c)?;
    Ok([
        ("thread_speedup_forces", t[0], t[1]),
        ("thread_speedup_step", t[2], t[3]),
    ]
    .into_iter()
    .map(|(measure, one, two)| Row {
        measure,
        n: a.thread_size,
        num: "1 thread".into(),
        num_s: one,
        den: "2 threads".into(),
        den_s: two,
        target: ">= 1.7",
    })
    .collect())
}

/// The ratio table on stdout.
fn print_rows(rows: &[Row]) {
    println!(
        "{:<24} {:>5} {:>28} {:>12} {:>26} {:>12} {:>9} {:>9} {:>8}",
        "measure",
        "n",
        "numerator",
        "min s/step",
        "denominator",
        "min s/step",
        "ratio",
        "median",
        "target"
    );
    for r in rows {
        println!(
            "{:<24} {:>5} {:>28} {:>12.4e} {:>26} {:>12.4e} {:>9.3} {:>9.3} {:>8} {}",
            r.measure,
            r.n,
            r.num,
            r.num_s.min,
            r.den,
            r.den_s.min,
            r.ratio(),
            r.ratio_median(),
            r.target,
            if r.met() { "met" } else { "NOT MET" }
        );
    }
}

/// `ratios.csv`.
fn ratios_csv(rows: &[Row]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "measure",
        "n",
        "numerator",
        "numerator_seconds_per_step",
        "denominator",
        "denominator_seconds_per_step",
        "ratio",
        "numerator_median_seconds_per_step",
        "denominator_median_seconds_per_step",
        "ratio_median",
        "target",
        "met",
    ])?;
    for r in rows {
        w.write_record([
            r.measure.to_string(),
            r.n.to_string(),
            r.num.clone(),
            r.num_s.min.to_string(),
            r.den.clone(),
            r.den_s.min.to_string(),
            r.ratio().to_string(),
            r.num_s.median.to_string(),
            r.den_s.median.to_string(),
            r.ratio_median().to_string(),
            r.target.to_string(),
            r.met().to_string(),
        ])?;
    }
    Ok(w.into_inner()?)
}

/// `implicit.csv`'s header.
const IMPLICIT_HEADER: [&str; 23] = [
    "method",
    "solver",
    "n",
    "particles",
    "springs",
    "steps",
    "seconds_per_step",
    "ns_per_spring",
    "newton_per_step",
    "linear_per_step",
    "linear_per_newton",
    "newton_max",
    "shifted_per_step",
    "patch_per_step",
    "factorizations_per_step",
    "force_evals_per_step",
    "symplectic_seconds_per_step",
    "ratio_to_symplectic_step",
    "median_seconds_per_step",
    "symplectic_median_seconds_per_step",
    "ratio_median",
    "target",
    "status",
];

/// Every implicit method at one frame on each cloth size: solver work and cost relative to a
/// symplectic step of the same cloth, the two timed in one interleaved run (minimum and
/// median over the rounds); printed, and `implicit.csv`.
fn implicit_table(a: &Args, solver: LinearSolver) -> Result<Vec<u8>> {
    let mut imp = csv::Writer::from_writer(Vec::new());
    imp.write_record(IMPLICIT_HEADER)?;
    println!(
        "\nimplicit methods at dt = 1/60 ({} solver, inexact Newton), {} steps from rest:",
        solver.name(),
        a.implicit_steps
    );
    println!(
        "{:<22} {:>9} {:>11} {:>10} {:>8} {:>11} {:>11} {:>9} {:>9} {:>9} {:>10} {:>9} {:>9}  status",
        "method",
        "n",
        "ms/step",
        "Newton/st",
        "Nwt max",
        "linear/st",
        "linear/Nwt",
        "shifted/st",
        "patch/st",
        "factor/st",
        "×sympl.",
        "median",
        "target"
    );
    let mut set = ImplicitSettings {
        solver,
        ..ImplicitSettings::default()
    };
    if let Some(m) = a.implicit_max_newton {
        set.max_newton = m;
    }
    // The methods read the solver and the cap as their options.
    let opts = springlab::method::MethodOptions::default()
        .with(
            &LINEAR_SOLVER,
            OptionValue::Choice(set.solver.name().into()),
        )
        .with(&MAX_NEWTON, OptionValue::Count(set.max_newton));
    for &n in &a.implicit_sizes {
        let scene = cloth(n);
        let (sys, s0) = (scene.build(), scene.initial_state());
        let h = bench_dt("symplectic_euler");
        for method in &a.implicit_methods {
            // The implicit method's runs from rest and the symplectic step, interleaved; the
            // counts (the same in every run) are kept from the last one.
            let (failed, last) = (std::sync::Mutex::new(None), std::sync::Mutex::new(None));
            let implicit: Contender = Box::new(|| {
                match implicit_cost(&scene, method, &opts, 1.0 / 60.0, a.implicit_steps) {
                    Ok(ic) => {
                        let s = ic.seconds_per_step;
                        *last.lock().expect("not poisoned") = Some(ic);
                        Ok(s)
                    }
                    Err(why) => {
                        *failed.lock().expect("not poisoned") = Some(why.clone());
                        Err(springlab::Error::Step(why))
                    }
                }
            });
            let mut c: Vec<Contender> = vec![
                stepping(&sys, &s0, fresh_stepper("symplectic_euler")?, h, 5),
                implicit,
            ];
            let times = interleaved_stats(a.rounds.min(7), &mut c);
            drop(c);
            let measured = match (times, last.into_inner().expect("not poisoned")) {
                (Ok(t), Some(ic)) => Ok((ic, t[0], t[1])),
                (Err(e), _) => Err(failed
                    .into_inner()
                    .expect("not poisoned")
                    .unwrap_or_else(|| e.to_string())),
                (Ok(_), None) => Err("no implicit run was timed".into()),
            };
            imp.write_record(implicit_row(a, (n, &scene), method, set, measured)?)?;
        }
    }
    Ok(imp.into_inner()?)
}

/// One implicit method on one cloth: its line on stdout and its `implicit.csv` record, a
/// failed run keeping its row with the reason. `measured`: the implicit run's counts, and the
/// symplectic step's and the implicit method's times per step over their interleaved rounds;
/// or why a run failed.
fn implicit_row(
    a: &Args,
    (n, scene): (usize, &springlab::scenario::Scenario),
    method: &str,
    set: ImplicitSettings,
    measured: std::result::Result<(ImplicitCost, RoundTimes, RoundTimes), String>,
) -> Result<Vec<String>> {
    let springs = scene.build().springs.len();
    let target = IMPLICIT_TARGETS
        .iter()
        .find(|t| t.0 == method && t.1 == n)
        .map_or("", |t| t.2);
    let size = format!("{n}×{n}");
    let mut rec = vec![
        method.to_string(),
        set.solver.name().to_string(),
        n.to_string(),
        (n * n).to_string(),
        springs.to_string(),
    ];
    match measured {
        Ok((ic, se, it)) => {
            let (ratio, ratio_median) = (it.min / se.min, it.median / se.median);
            let met = match target.split_once(' ') {
                Some((_, v)) => {
                    if ic.status.is_ok() && v.parse().is_ok_and(|v: f64| ratio <= v) {
                        "met"
                    } else {
                        "NOT MET"
                    }
                }
                None => "",
            };
            let per_newton = ic.linear_per_step / ic.newton_per_step.max(f64::MIN_POSITIVE);
            println!(
                "{method:<22} {size:>9} {:>11.3} {:>10.2} {:>8} {:>11.1} {:>11.1} {:>9.2} {:>9.2} {:>9.2} {:>10.1} {:>9.1} {:>9}  {} {met}",
                it.min * 1e3,
                ic.newton_per_step,
                ic.newton_max,
                ic.linear_per_step,
                per_newton,
                ic.shifted_per_step,
                ic.patch_per_step,
                ic.factorizations_per_step,
                ratio,
                ratio_median,
                target,
                ic.status,
            );
            rec.extend([
                ic.steps.to_string(),
                it.min.to_string(),
                (it.min * 1e9 / springs as f64).to_string(),
                ic.newton_per_step.to_string(),
                ic.linear_per_step.to_string(),
                per_newton.to_string(),
                ic.newton_max.to_string(),
                ic.shifted_per_step.to_string(),
                ic.patch_per_step.to_string(),
                ic.factorizations_per_step.to_string(),
                ic.force_evals_per_step.to_string(),
                se.min.to_string(),
                ratio.to_string(),
                it.median.to_string(),
                se.median.to_string(),
                ratio_median.to_string(),
                target.to_string(),
                ic.status.to_string(),
            ]);
        }
        Err(why) => {
            println!("{method:<22} {size:>9}  failed: {why}");
            rec.push(a.implicit_steps.to_string());
            rec.extend(std::iter::repeat_n(String::new(), 15));
            rec.push(target.to_string());
            rec.push(format!("failed: {why}"));
        }
    }
    Ok(rec)
}
