//! A frame of n substeps is, for every native method, bit for bit the run at
//! dt/n with every n-th state kept. Oracle: the runner itself at the fine step (the
//! definition of substepping), compared with `==` on every coordinate of every frame.

use springlab::method::MethodOptions;
use springlab::method::Registry;
use springlab::model::State;
use springlab::run::{run, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

#[derive(Default)]
struct Keep(Vec<(u64, State)>);
impl Observer for Keep {
    fn observe(&mut self, step: u64, s: &State, _: &EnergyRecord) -> springlab::Result<()> {
        self.0.push((step, s.clone()));
        Ok(())
    }
}

/// A damped chain under gravity and drag, kicked inside a substep (exact events split it).
const CHAIN: &str = r#"
[world]
gravity = [0.0, -9.81, 0.0]
drag = 0.01
[[chain]]
start = [0.0, 0.0, 0.0]
end = [0.6, 0.0, 0.0]
count = 6
mass = 0.05
stiffness = 300.0
damping = 0.02
fix = ["first"]
[[impulse]]
time = 0.0371
particle = 5
delta_v = [0.0, 1.0, 0.5]
[run]
dt = 0.01
duration = 0.2
"#;

fn same(name: &str, scene: &Scenario, n: u64) {
    let sys = scene.build();
    let registry = Registry::builtin();
    let opts = MethodOptions::default();
    let frame = 1.0 / 60.0;
    let frames = 12;
    let mut coarse = Keep::default();
    let mut stepper = registry.create(name, &opts).unwrap();
    let plan = RunPlan::new(frame, frames).with_substeps(n);
    let a = run(
        &sys,
        &mut stepper,
        scene.initial_state(),
        &plan,
        &mut coarse,
    )
    .unwrap();
    let mut fine = Keep::default();
    let mut stepper = registry.create(name, &opts).unwrap();
    let plan = RunPlan::new(frame / n as f64, frames * n);
    let b = run(&sys, &mut stepper, scene.initial_state(), &plan, &mut fine).unwrap();
    // A blow-up (explicit Euler) trips at the same substep: same time, same reason.
    let at = |s: &springlab::run::Status| match s {
        springlab::run::Status::Ok => None,
        springlab::run::Status::Unstable { time, reason, .. } => Some((*time, reason.clone())),
    };
    assert_eq!(at(&a.status), at(&b.status), "{name}");
    if a.status.is_ok() {
        assert_eq!(a.steps_done, frames, "{name}: outputs are per frame");
        assert_eq!(a.force_evals, b.force_evals, "{name}: the same work");
    }
    assert_eq!(coarse.0.len() as u64, a.steps_done + 1);
    for (k, s) in &coarse.0 {
        let (j, f) = &fine.0[(*k * n) as usize];
        assert_eq!(*j, k * n);
        assert_eq!(s.x, f.x, "{name}: positions at frame {k}");
        assert_eq!(s.v, f.v, "{name}: velocities at frame {k}");
    }
}

#[test]
fn substeps_are_bit_identical_to_the_fine_step_for_every_native_method() {
    let chain = Scenario::from_toml_str(CHAIN, "chain.toml").unwrap();
    let rod = Scenario::from_file("scenarios/pendulum_rod.toml").unwrap();
    let registry = Registry::builtin();
    let mut covered = Vec::new();
    for name in registry.names() {
        let info = registry.info(name).unwrap();
        if info.engine {
            continue;
        }
        let stepper = registry.create(name, &MethodOptions::default()).unwrap();
        let mut ran = false;
        for scene in [&chain, &rod] {
            if stepper.check(&scene.build()).is_ok() {
                for n in [2, 3, 4] {
                    same(name, scene, n);
                }
                ran = true;
            }
        }
        if ran {
            covered.push(name);
        }
    }
    // analytic needs independent anchored springs; every other native method runs one scene.
    let natives: Vec<&str> = registry
        .names()
        .into_iter()
        .filter(|n| !registry.info(n).unwrap().engine && *n != "analytic")
        .collect();
    for n in natives {
        assert!(covered.contains(&n), "{n} was not checked");
    }
}

/// The closed form checks too, on its own kind of scene (a kicked anchored spring).
#[test]
fn substeps_are_bit_identical_for_the_closed_form() {
    let scene = Scenario::from_file("scenarios/recoil_spring.toml").unwrap();
    for n in [2, 5] {
        same("analytic", &scene, n);
    }
}

/// Rapier splits frames itself: the runner hands it whole frames, and its solver substeps
/// come from the options (the same `--substeps`).
#[test]
fn rapier_gets_whole_frames() {
    let scene = Scenario::from_toml_str(CHAIN, "chain.toml").unwrap();
    let sys = scene.build();
    let registry = Registry::builtin();
    let opts = MethodOptions::default().with_substeps(3);
    let mut a = registry.create("rapier_impulse", &opts).unwrap();
    assert!(a.info.splits_frames);
    let plan = RunPlan::new(1.0 / 60.0, 6).with_substeps(3);
    let x = run(
        &sys,
        &mut a,
        scene.initial_state(),
        &plan,
        &mut Keep::default(),
    )
    .unwrap();
    let mut b = registry.create("rapier_impulse", &opts).unwrap();
    let plan = RunPlan::new(1.0 / 60.0, 6);
    let y = run(
        &sys,
        &mut b,
        scene.initial_state(),
        &plan,
        &mut Keep::default(),
    )
    .unwrap();
    assert_eq!(x.final_state.x, y.final_state.x);
}

/// `compare --substeps n` measures every native method per frame of n substeps: its final
/// state, hence its final error, is bit for bit the run at dt/n (same definition as above),
/// its work the same force evaluations, its step count the frames; Rapier gets n solver
/// substeps; and the command it prints says `--substeps n`.
#[test]
fn compare_splits_frames_for_every_native_method() {
    use springlab::measure::compare::{compare, CompareConfig};
    let scene = Scenario::from_toml_str(CHAIN, "chain.toml").unwrap();
    let names: Vec<String> = [
        "symplectic_euler",
        "rk4",
        "implicit_euler",
        "rapier_impulse",
    ]
    .map(String::from)
    .to_vec();
    let at = |dt: f64, frame_substeps: Option<u64>| {
        compare(
            &scene,
            &CompareConfig {
                dt: Some(dt),
                duration: Some(0.2),
                frame_substeps,
                series_points: 0,
                common: springlab::measure::Common {
                    methods: names.clone(),
                    ..Default::default()
                },
                ..Default::default()
            },
        )
        .unwrap()
    };
    let split = at(1.0 / 60.0, Some(4));
    let fine = at(1.0 / 240.0, None);
    assert!(split.command.contains("--substeps 4"), "{}", split.command);
    assert_eq!(split.substeps, 4);
    for (a, b) in split.entries.iter().zip(&fine.entries) {
        let (a, b) = (a.result.as_ref().unwrap(), b.result.as_ref().unwrap());
        if a.method == "rapier_impulse" {
            continue;
        }
        assert_eq!(a.steps_done * 4, b.steps_done, "{}", a.method);
        assert_eq!(a.force_evals, b.force_evals, "{}", a.method);
        assert_eq!(
            a.metric(|m| m.error_final).map(f64::to_bits),
            b.metric(|m| m.error_final).map(f64::to_bits),
            "{}",
            a.method
        );
    }
}
