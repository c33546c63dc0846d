//! The modelled cost: counted work, priced per item, so every decision on cost is the same on
//! every re-run. Oracles: the counts each method's algorithm makes by construction (one force
//! evaluation per symplectic Euler step, substeps × sweeps × links link updates per XPBD
//! step, the implicit core's own iteration counters), and the engine's price from the scene
//! alone.

use springlab::measure::probe::seconds_per_step;
use springlab::method::options::{OptionValue, XPBD_ITERATIONS, XPBD_SUBSTEPS};
use springlab::method::{MethodOptions, Registry};
use springlab::rapier::{EngineShape, Mode};
use springlab::run::{run, CostModel, NoObserver, RunPlan};
use springlab::scenario::Scenario;

fn chain() -> Scenario {
    Scenario::from_file("scenarios/hanging_chain.toml").unwrap()
}

fn outcome(name: &str, opts: &MethodOptions, steps: u64) -> springlab::run::RunOutcome {
    let scene = chain();
    let sys = scene.build();
    let mut stepper = Registry::builtin().create(name, opts).unwrap();
    run(
        &sys,
        &mut stepper,
        scene.initial_state(),
        &RunPlan::new(1e-3, steps),
        &mut NoObserver,
    )
    .unwrap()
}

#[test]
fn work_is_what_each_algorithm_does_by_construction() {
    let o = outcome("symplectic_euler", &MethodOptions::default(), 50);
    assert_eq!((o.work.steps, o.work.force_evals), (50, 50));
    assert_eq!(o.work.link_updates + o.work.linear_iterations, 0);
    // XPBD: every substep sweeps every link `iterations` times (19 springs, no rods).
    let opts = MethodOptions::default()
        .with(&XPBD_SUBSTEPS, OptionValue::Count(2))
        .with(&XPBD_ITERATIONS, OptionValue::Count(3));
    let o = outcome("xpbd", &opts, 50);
    assert_eq!(o.work.link_updates, 50 * 2 * 3 * 19);
    assert_eq!(o.work.force_evals, 0);
    // Implicit Euler: at least one Newton iteration and one linear iteration per step.
    let o = outcome("implicit_euler", &MethodOptions::default(), 50);
    assert!(o.work.newton_iterations >= 50 && o.work.linear_iterations >= o.work.newton_iterations);
    // The price is the scene's model applied to the counts, bit for bit on a re-run.
    let sys = chain().build();
    assert_eq!(o.modelled_seconds, CostModel::of(&sys).seconds(&o.work));
    let again = outcome("implicit_euler", &MethodOptions::default(), 50);
    assert_eq!(again.work, o.work);
    assert_eq!(
        again.modelled_seconds.to_bits(),
        o.modelled_seconds.to_bits()
    );
}

#[test]
fn more_work_costs_more_and_a_native_step_costs_less_than_an_engine_frame() {
    let sym = outcome("symplectic_euler", &MethodOptions::default(), 50);
    let imp = outcome("implicit_euler", &MethodOptions::default(), 50);
    assert!(imp.modelled_seconds > 5.0 * sym.modelled_seconds);
    // The engine is priced from the scene without running: the probe returns its frame and
    // the runner's step on it, what a run books per frame.
    let scene = chain();
    let (sys, s0) = (scene.build(), scene.initial_state());
    let reg = Registry::builtin();
    let opts = MethodOptions::default();
    let frame = seconds_per_step(&sys, &s0, &reg, &opts, "rapier_impulse", 1e-3, 40).unwrap();
    let shape = EngineShape::of(&sys, Mode::Impulse);
    let step = springlab::run::cost::Work {
        steps: 1,
        ..Default::default()
    };
    let runner = springlab::run::cost::CostModel::of(&sys).seconds(&step);
    assert_eq!(frame, shape.frame_seconds(opts.substeps) + runner);
    assert_eq!(shape.impulse_joints, sys.springs.len());
    // The chain as one multibody tree (a cubic dense solve) is dearer than impulse joints.
    let multi = seconds_per_step(&sys, &s0, &reg, &opts, "rapier_multibody", 1e-3, 40).unwrap();
    assert!(multi > frame);
    let native = seconds_per_step(&sys, &s0, &reg, &opts, "symplectic_euler", 1e-3, 40).unwrap();
    assert!(native > 0.0 && native < frame);
}
