//! Extreme parameters: every method must either finish with finite results or report an
//! `unstable` status with step and reason; never panic, never NaN in outputs. Each case states
//! what theory predicts and checks it where the prediction is sharp (textbook stability limits
//! of the undamped oscillator: explicit Euler never stable; symplectic Euler and Verlet for
//! hω < 2; RK4 for hω < 2√2; implicit Euler and the exact solution for every h).

use crate::common;

use springlab::model::Vec3;
use springlab::run::{run, NoObserver, RunOutcome, RunPlan, Status};
use springlab::scenario::Scenario;

/// Every built-in method.
fn known_names() -> Vec<&'static str> {
    springlab::method::Registry::builtin().names()
}

/// The built-in methods that are not engines.
fn native_names() -> Vec<&'static str> {
    springlab::method::Registry::builtin().native_names()
}

fn scene(toml: &str) -> Scenario {
    Scenario::from_toml_str(toml, "extreme.toml").expect("valid extreme scene")
}

/// Runs every method that accepts `scene` and checks the no-NaN contract on each outcome.
/// Returns (name, outcome) pairs; `skipped` collects names whose `check` refused the scene.
fn run_all(scene: &Scenario, dt: f64, steps: u64) -> Vec<(&'static str, RunOutcome)> {
    run_names(scene, dt, steps, &known_names())
}

/// [`run_all`] restricted to `names` (for cases too slow for the multibody engine in CI).
fn run_names(
    scene: &Scenario,
    dt: f64,
    steps: u64,
    names: &[&'static str],
) -> Vec<(&'static str, RunOutcome)> {
    let sys = scene.build();
    let mut out = Vec::new();
    for &name in names {
        let mut stepper = common::stepper(name);
        if stepper.check(&sys).is_err() {
            continue;
        }
        let o = run(
            &sys,
            &mut stepper,
            scene.initial_state(),
            &RunPlan::new(dt, steps),
            &mut NoObserver,
        )
        .expect("a blow-up is a status, not an error");
        assert!(
            o.final_state.first_non_finite().is_none(),
            "{name}: non-finite final state"
        );
        assert!(o.final_energy.is_finite(), "{name}: non-finite energy");
        match &o.status {
            Status::Ok => assert_eq!(o.steps_done, steps, "{name}"),
            Status::Unstable { step, time, reason } => {
                assert!(*step >= 1 && *step <= steps, "{name}: step {step}");
                assert!(time.is_finite() && !reason.is_empty(), "{name}");
                assert_eq!(o.steps_done, step - 1, "{name}: last accepted step");
            }
        }
        out.push((name, o));
    }
    assert!(!out.is_empty());
    out
}

fn status<'a>(runs: &'a [(&str, RunOutcome)], name: &str) -> &'a Status {
    &runs
        .iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("{name} did not run"))
        .1
        .status
}

/// Native methods only: the exactness and accuracy oracles below are theirs; external
/// engines (Rapier) are held to the no-NaN contract in [`run_all`] and have their outcome printed.
fn native(runs: &[(&'static str, RunOutcome)]) -> Vec<(&'static str, RunOutcome)> {
    runs.iter()
        .filter(|(n, _)| native_names().contains(n))
        .cloned()
        .collect()
}

fn print(case: &str, runs: &[(&str, RunOutcome)]) {
    for (n, o) in runs {
        match &o.status {
            Status::Ok => eprintln!("{case}: {n}: ok"),
            Status::Unstable { step, reason, .. } => {
                eprintln!("{case}: {n}: unstable at step {step}: {reason}")
            }
        }
    }
}

/// Stable for hω below `limit` (∞: always), never for explicit Euler over enough steps.
fn expect_oscillator_limits(runs: &[(&str, RunOutcome)], hw: f64) {
    for (name, limit) in [
        ("symplectic_euler", 2.0),
        ("velocity_verlet", 2.0),
        ("position_verlet", 2.0),
        ("rk4", 2.0 * 2f64.sqrt()),
        ("implicit_euler", f64::INFINITY),
        ("linear_implicit_euler", f64::INFINITY),
        ("implicit_midpoint", f64::INFINITY),
        ("bdf2", f64::INFINITY),
        ("rattle", 2.0),
        ("analytic", f64::INFINITY),
    ] {
        let st = status(runs, name);
        if hw < 0.9 * limit {
            assert!(
                st.is_ok(),
                "{name} at hω = {hw}: theory says stable, got {st:?}"
            );
        } else if hw > 1.1 * limit {
            assert!(!st.is_ok(), "{name} at hω = {hw}: theory says unstable");
        }
    }
}

/// Anchored oscillator, 1 kg, stiffness `k`, displaced by 0.1 m.
fn oscillator(k: f64) -> Scenario {
    common::oscillator(k, 0.0, 0.1, 0.0)
}

#[test]
fn stiffness_1e_minus_3_everything_stable() {
    // ω = 0.0316 rad/s, h = 0.1 s: hω = 3e-3, far inside every limit; explicit Euler's growth
    // factor (1 + (hω)²)^(n/2) over 1000 steps is 1.005, not a blow-up.
    let runs = run_all(&oscillator(1e-3), 0.1, 1000);
    print("k=1e-3", &runs);
    let runs = native(&runs);
    assert!(runs.iter().all(|(_, o)| o.status.is_ok()));
}

#[test]
fn stiffness_1e9_only_unconditionally_stable_methods_survive() {
    // ω = 31623 rad/s, h = 1e-3 s: hω = 31.6, beyond every explicit limit.
    let runs = run_all(&oscillator(1e9), 1e-3, 200);
    print("k=1e9", &runs);
    expect_oscillator_limits(&runs, 31.6);
    assert!(!status(&runs, "explicit_euler").is_ok());
    assert!(!status(&runs, "rk2").is_ok());
}

#[test]
fn stiffness_1e9_at_dt_1_implicit_euler_converges() {
    // hω = 31623: implicit Euler damps the oscillation by 1/√(1 + (hω)²) per step, so after one
    // step the displacement is ≈ 0.1/31623 m; Newton must converge at this conditioning.
    let runs = run_all(&oscillator(1e9), 1.0, 20);
    print("k=1e9 dt=1", &runs);
    expect_oscillator_limits(&runs, 31623.0);
    let ie = &runs.iter().find(|(n, _)| *n == "implicit_euler").unwrap().1;
    let u = (ie.final_state.x[1].x - 1.0).abs();
    assert!(
        u < 1e-6,
        "implicit Euler should have damped the oscillation, |u| = {u}"
    );
}

#[test]
fn dt_1e_minus_6_everything_stable_and_accurate() {
    // k = 1, hω = 1e-6: every method is stable and within 1e-5 of the exact cos(t).
    let runs = run_all(&oscillator(1.0), 1e-6, 10_000);
    print("dt=1e-6", &runs);
    let runs = native(&runs);
    let t: f64 = 0.01;
    for (name, o) in &runs {
        assert!(o.status.is_ok(), "{name}");
        let exact = 1.0 + 0.1 * t.cos();
        assert!((o.final_state.x[1].x - exact).abs() < 1e-8, "{name}");
    }
}

#[test]
fn dt_1_second_matches_stability_limits() {
    // k = 1, hω = 1: inside the symplectic, Verlet and RK4 limits; explicit Euler grows by
    // √2 per step and RK2 (explicit midpoint) by √1.25, both past the blow-up bound in 200 steps.
    let runs = run_all(&oscillator(1.0), 1.0, 200);
    print("dt=1", &runs);
    expect_oscillator_limits(&runs, 1.0);
    assert!(!status(&runs, "explicit_euler").is_ok());
    assert!(!status(&runs, "rk2").is_ok());
}

#[test]
fn mass_ratio_1e9_between_neighbours() {
    // A 1 ng bead between two 1 kg masses on k = 1 N/m springs: the bead's frequency
    // √(2k/m) = 44721 rad/s makes h = 1e-3 s far beyond explicit limits (hω = 44.7);
    // the heavy masses barely move. Implicit Euler must stay bounded.
    let toml = "\
        [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n\
        [[particle]]\nposition=[1.0,0.0,0.0]\nmass=1e-9\nvelocity=[0.0,1.0,0.0]\n\
        [[particle]]\nposition=[2.0,0.0,0.0]\nmass=1.0\n\
        [[spring]]\nbetween=[0,1]\nstiffness=1.0\nrest_length=0.9\n\
        [[spring]]\nbetween=[1,2]\nstiffness=1.0\nrest_length=0.9\n";
    let runs = run_all(&scene(toml), 1e-3, 500);
    print("mass ratio 1e9", &runs);
    assert!(status(&runs, "implicit_euler").is_ok());
    assert!(!status(&runs, "symplectic_euler").is_ok());
    // And the reverse: a 1e9 kg mass next to a 1 kg one at a step the light one resolves.
    let toml = "\
        [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1e9\n\
        [[particle]]\nposition=[1.0,0.0,0.0]\nmass=1.0\n\
        [[spring]]\nbetween=[0,1]\nstiffness=1.0\nrest_length=0.9\n";
    let runs = run_all(&scene(toml), 1e-2, 1000);
    print("mass ratio 1e9 resolved", &runs);
    for name in [
        "symplectic_euler",
        "velocity_verlet",
        "rk4",
        "implicit_euler",
    ] {
        assert!(status(&runs, name).is_ok(), "{name}");
    }
}

#[test]
fn zero_rest_length_is_an_isotropic_linear_spring() {
    // l0 = 0: f = -k d exactly, an isotropic 3D oscillator; started off-axis with a transverse
    // velocity it traces an ellipse and returns to its start after one period 2π/√k.
    let toml = "\
        [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
        [[particle]]\nposition=[0.3,0.4,0.0]\nvelocity=[0.0,0.0,0.5]\nmass=1.0\n\
        [[spring]]\nbetween=[0,1]\nstiffness=4.0\nrest_length=0.0\n";
    let sc = scene(toml);
    let runs = run_all(&sc, 1e-3, 100);
    print("l0=0", &runs);
    let runs = native(&runs);
    assert!(runs.iter().all(|(_, o)| o.status.is_ok()));
    let period = std::f64::consts::PI; // 2π/√4
    let steps = 10_000u64;
    let o = common::run_steps(&sc, "rk4", period / steps as f64, steps);
    let x = o.final_state.x[1];
    assert!(
        (x - Vec3::new(0.3, 0.4, 0.0)).norm() < 1e-10,
        "rk4 after one period: {x}"
    );
    // Through the origin, where the direction is undefined: still finite.
    let toml = "\
        [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
        [[particle]]\nposition=[0.5,0.0,0.0]\nmass=1.0\n\
        [[spring]]\nbetween=[0,1]\nstiffness=1.0\nrest_length=0.0\n";
    let runs = run_all(&scene(toml), std::f64::consts::FRAC_PI_2 / 100.0, 400);
    print("l0=0 through the anchor", &runs);
    let runs = native(&runs);
    assert!(runs.iter().all(|(_, o)| o.status.is_ok()));
}

#[test]
fn coincident_particles_use_the_documented_fallback() {
    // Two particles at the same point joined by a spring of rest length 1: the direction is
    // undefined. A file that starts them so is refused (naming the spring); a run can still
    // bring them together, where the fallback force k·d is zero. At rest there they stay put
    // (an equilibrium of the fallback); moving apart, the spring pushes them to its rest length.
    let base = "\
        [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n\
        [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nVEL\n\
        [[spring]]\nbetween=[0,1]\nstiffness=10.0\nrest_length=1.0\ndamping=0.5\n";
    let refused = Scenario::from_toml_str(&base.replace("VEL", ""), "extreme.toml").unwrap_err();
    assert!(refused.to_string().contains("spring[0]"), "{refused}");
    // The same pair as a run reaches it: placed apart in the file, then brought together.
    let coincident = |vel: &str| {
        let mut s = scene(
            &base
                .replacen("position=[0.0,0.0,0.0]", "position=[0.0,0.0,1.0]", 1)
                .replace("VEL", vel),
        );
        s.particles[0].position = Vec3::zeros();
        s
    };
    let runs = run_all(&coincident(""), 1e-3, 100);
    print("coincident at rest", &runs);
    let runs = native(&runs);
    for (name, o) in &runs {
        assert!(o.status.is_ok(), "{name}");
        assert_eq!(o.final_state.x[1], Vec3::zeros(), "{name}");
    }
    let runs = run_all(&coincident("velocity=[0.0,1e-3,0.0]"), 1e-3, 3000);
    print("coincident moving", &runs);
    let runs = native(&runs);
    for (name, o) in &runs {
        assert!(o.status.is_ok(), "{name}");
        let sep = (o.final_state.x[1] - o.final_state.x[0]).norm();
        assert!(
            sep > 0.1,
            "{name}: the spring should push them apart, separation {sep}"
        );
    }
}

#[test]
fn single_particle_in_free_fall() {
    // x = x0 + v0 t + ½ g t²: RK4 and velocity Verlet are exact for constant acceleration.
    let toml = "[world]\ngravity=[0.0,-9.81,0.0]\n[[particle]]\nposition=[0.0,10.0,0.0]\nvelocity=[1.0,2.0,0.0]\nmass=2.0\n";
    let runs = run_all(&scene(toml), 0.01, 100);
    print("single particle", &runs);
    let runs = native(&runs);
    let t = 1.0;
    let exact = Vec3::new(t, 10.0 + 2.0 * t - 0.5 * 9.81 * t * t, 0.0);
    for (name, o) in &runs {
        assert!(o.status.is_ok(), "{name}");
        if ["rk4", "velocity_verlet", "rk2"].contains(name) {
            assert!((o.final_state.x[0] - exact).norm() < 1e-11, "{name}");
        }
    }
}

#[test]
fn no_springs_particles_move_in_straight_lines() {
    // No forces at all: x = x0 + v0 t for every method, to rounding.
    let toml = "\
        [[particle]]\nposition=[0.0,0.0,0.0]\nvelocity=[1.0,0.0,0.0]\nmass=1.0\n\
        [[particle]]\nposition=[0.0,1.0,0.0]\nvelocity=[0.0,0.0,-3.0]\nmass=1e-6\n";
    let runs = run_all(&scene(toml), 0.5, 20);
    print("no springs", &runs);
    let runs = native(&runs);
    for (name, o) in &runs {
        assert!(o.status.is_ok(), "{name}");
        assert!(
            (o.final_state.x[0] - Vec3::new(10.0, 0.0, 0.0)).norm() < 1e-12,
            "{name}"
        );
        assert!(
            (o.final_state.x[1] - Vec3::new(0.0, 1.0, -30.0)).norm() < 1e-12,
            "{name}"
        );
    }
}

#[test]
fn hundred_thousand_particles() {
    // A 316×316 cloth (99 856 particles, 397 530 springs) for a few steps at its stable step:
    // every method finishes, and the pinned corners have not moved.
    let sc = springlab::perf::cloth(316);
    assert!(sc.particles.len() >= 99_000);
    // Rapier's multibody method needs minutes for this scene: natives and rapier_impulse only.
    let names: Vec<&'static str> = native_names()
        .into_iter()
        .chain(["rapier_impulse"])
        .collect();
    let runs = run_names(&sc, 1e-3, 3, &names);
    print("1e5 particles", &runs);
    let runs = native(&runs);
    for (name, o) in &runs {
        assert!(o.status.is_ok(), "{name}");
        assert_eq!(o.final_state.x[316 * 315], sc.particles[316 * 315].position);
    }
}

/// `n` steps of the anchored oscillator (k = 1, hω = 0.01) with every method: symplectic
/// methods keep the energy error bounded (O(h) for symplectic Euler, O(h²) for Verlet),
/// implicit Euler loses energy (amplitude factor (1 + (hω)²)^(-n/2)), explicit Euler gains it
/// until it trips the blow-up bound.
fn long_run(n: u64) {
    // Native methods only: the Rapier methods take minutes for 1e6 steps.
    let runs = run_names(&oscillator(1.0), 0.01, n, &native_names());
    print("long run", &runs);
    let e0 = 0.5 * 0.01;
    for (name, tol) in [
        ("symplectic_euler", 0.02),
        ("velocity_verlet", 1e-4),
        ("position_verlet", 1e-4),
        ("analytic", 1e-9),
    ] {
        let o = &runs.iter().find(|(m, _)| *m == name).unwrap().1;
        assert!(o.status.is_ok(), "{name}");
        let drift = (o.final_energy.total - e0).abs() / e0;
        assert!(drift < tol, "{name}: relative energy drift {drift}");
    }
    // Implicit Euler: energy factor 1/(1 + (hω)²) per step, checked where it is above the
    // rounding level (10⁴ steps: e^-1), and never growing over the long run.
    let predicted = (1.0f64 + 1e-4).powf(-10_000.0);
    let o = common::run_steps(&oscillator(1.0), "implicit_euler", 0.01, 10_000);
    let e = o.final_energy.mechanical() / e0;
    assert!(
        (e / predicted - 1.0).abs() < 1e-3,
        "implicit: {e} vs {predicted}"
    );
    let ie = &runs.iter().find(|(m, _)| *m == "implicit_euler").unwrap().1;
    assert!(ie.status.is_ok());
    let e = ie.final_energy.mechanical() / e0;
    assert!(
        e < predicted,
        "implicit Euler after {n} steps: energy ratio {e}"
    );
}

#[test]
fn long_run_1e6_steps() {
    long_run(1_000_000);
}

#[test]
#[ignore = "1e7 steps of every method: about ten times long_run_1e6_steps; run with --ignored"]
fn long_run_1e7_steps() {
    long_run(10_000_000);
}
