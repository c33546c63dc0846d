//! The guards that keep a command within its budget: the reference's projection is a floor of
//! the work its solve does, a solve held to a limit stops with an error naming `--budget`, and
//! an empirical stability search stops before a trial its allowance cannot pay for.

use springlab::measure::grid::run_grid;
use springlab::measure::reference::cost::project;
use springlab::measure::reference::Reference;
use springlab::measure::stability::work::SearchWork;
use springlab::measure::stability::{empirical_limit_within, EmpiricalCriterion, Verdict};
use springlab::method::{MethodOptions, Registry};
use springlab::scenario::{Scenario, Timing};

/// The projected steps and the reference of shipped scene `name` (its duration replaced by
/// `duration` when given: a horizon no other test solves, so no kept solve is shared).
fn reference_of(
    name: &str,
    duration: Option<&str>,
    limit: Option<f64>,
) -> (f64, springlab::Result<Reference>) {
    let path = format!("scenarios/{name}.toml");
    let mut text = std::fs::read_to_string(&path).unwrap();
    if let Some(d) = duration {
        text = text.replace("duration = 5.0", &format!("duration = {d}"));
    }
    let scene = Scenario::from_toml_str(&text, &path).unwrap();
    let (sys, s0) = (scene.build(), scene.initial_state());
    let t = Timing::resolve(&scene, None, None).unwrap();
    let grid = run_grid(t.dt, t.steps, sys.len());
    let horizon = grid.time(t.steps);
    let p = project(&sys, &s0, &[grid], horizon);
    (
        p.steps,
        Reference::compute_within(&sys, &s0, &[grid], horizon, limit),
    )
}

// Oracle: the solvers' own step counts. The projection counts at least a step per radian of the
// fastest motion (or the contact solve's least steps), which the adaptive solver at 1e-12 never
// takes fewer of; the fine-step reference runs its first level, its perturbed run and its
// second level (four first levels' worth of RK4 steps, four evaluations each) at least.
#[test]
fn the_reference_projection_is_a_floor_of_its_solve() {
    for name in [
        "two_body",
        "pendulum_rod",
        "hanging_chain",
        "bounce",
        "chain_on_box",
    ] {
        let (steps, r) = reference_of(name, None, None);
        let info = r.unwrap().info;
        let taken = (info.solver_steps + info.solver_rejected) as f64;
        assert!(steps >= 1.0 && steps <= taken, "{name}: {steps} > {taken}");
    }
    let (steps, r) = reference_of("cloth_on_sphere", None, None);
    let evals = r.unwrap().info.solver_evals as f64;
    assert!(steps <= evals / 4.0, "{steps} > {evals} / 4");
}

// A limit below what the solve needs stops it with an error naming --budget; the twin with a
// limit that covers its work solves.
#[test]
fn a_reference_held_to_a_limit_stops_naming_the_budget() {
    let d = Some("3.7");
    let (_, r) = reference_of("two_body", d, Some(1e-6));
    let err = r.expect_err("stopped").to_string();
    assert!(
        err.starts_with("--budget: the reference (DOP853) stopped"),
        "{err}"
    );
    let (_, held) = reference_of("two_body", d, Some(100.0));
    assert!(held.unwrap().info.solver_steps > 0);
}

// Oracle: the allowance rule by hand. With an allowance below the cost of any trial, the first
// trial runs (nothing prices it yet) and the second is refused: one run, and the reason names
// --budget. The twin without an allowance runs its search to the end.
#[test]
fn a_stability_search_stops_before_a_trial_it_cannot_pay_for() {
    let scene = Scenario::from_file("scenarios/anchored_spring.toml").unwrap();
    let (sys, s0) = (scene.build(), scene.initial_state());
    let registry = Registry::builtin();
    let method = registry.get("symplectic_euler").unwrap();
    let opts = MethodOptions::default();
    let crit = EmpiricalCriterion {
        horizon: 100.0,
        blowup_factor: springlab::run::DEFAULT_BLOWUP_FACTOR,
        dt_min: 1e-4,
        dt_max: 50.0,
    };
    let bar = indicatif::ProgressBar::hidden();
    let mut work = SearchWork::new(&bar, 0.0, Some(1e-12));
    let held =
        empirical_limit_within(&sys, &s0, method, &opts, 0.01, &crit, Some(&mut work)).unwrap();
    assert_eq!(held.runs, 1);
    let why = held.stopped.expect("stopped");
    assert!(why.contains("`--budget`"), "{why}");
    // The first trial at 0.01 s (hω = 0.02) is stable: that much is known.
    assert_eq!(
        (held.verdict, held.max_stable_dt),
        (Verdict::StableBelow, Some(0.01))
    );
    let free = empirical_limit_within(&sys, &s0, method, &opts, 0.01, &crit, None).unwrap();
    assert!(free.stopped.is_none() && free.runs > 1);
    assert_eq!(free.verdict, Verdict::StableBelow);
}
