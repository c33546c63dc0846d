//! Penalty (spring-dashpot) contact against its closed form.
//!
//! Oracle: a mass m hitting a wall through a linear spring k and dashpot c (no other force)
//! follows a damped half oscillation; it leaves when the penetration returns to zero with
//! restitution e = exp(−ζπ/√(1−ζ²)), ζ = c/(2√(km)), after π/ω_d, ω_d = √(k/m)·√(1−ζ²)
//! (e.g. Schwager & Pöschel, "Coefficient of restitution and linear-dashpot model revisited",
//! Granular Matter 9 (2007), eq. 5).

use springlab::collide::{damping_ratio_for_restitution, restitution_for_damping_ratio};
use springlab::measure::contacts::ContactMetrics;
use springlab::method::create as by_name;
use springlab::method::MethodOptions;
use springlab::run::{run, RunPlan};
use springlab::scenario::Scenario;

/// A particle of mass 1 kg flying at 2 m/s into the plane y = 0, no gravity.
fn wall(collision: &str, restitution: f64) -> Scenario {
    Scenario::from_toml_str(
        &format!(
            r#"
            [[particle]]
            position = [0.0, 0.05, 0.0]
            velocity = [0.0, -2.0, 0.0]
            mass = 1.0
            [[obstacle]]
            shape = "plane"
            point = [0.0, 0.0, 0.0]
            normal = [0.0, 1.0, 0.0]
            restitution = {restitution}
            [collision]
            {collision}
            "#
        ),
        "penalty_wall.toml",
    )
    .unwrap()
}

fn measure(scene: &Scenario, method: &str, dt: f64) -> springlab::measure::contacts::ContactEvent {
    let sys = scene.build();
    assert!(sys.active_terms().contains(&"penalty_contacts"));
    let mut stepper = by_name(method, &MethodOptions::default()).unwrap();
    let mut m = ContactMetrics::new(&sys, dt).unwrap();
    let plan = RunPlan::for_duration(dt, 0.1);
    let out = run(&sys, &mut stepper, scene.initial_state(), &plan, &mut m).unwrap();
    assert!(out.status.is_ok());
    let rep = m.report();
    assert_eq!(rep.events_total, 1, "{method}: one contact");
    rep.events[0].clone()
}

#[test]
fn formulas_are_inverse() {
    for e in [0.05, 0.3, 0.5, 0.9, 0.99] {
        let z = damping_ratio_for_restitution(e);
        assert!((restitution_for_damping_ratio(z) - e).abs() < 1e-12);
    }
    assert_eq!(damping_ratio_for_restitution(0.0), 1.0);
    assert_eq!(restitution_for_damping_ratio(1.0), 0.0);
}

#[test]
fn restitution_derived_from_obstacle_matches_formula() {
    // k = 1e4 N/m, m = 1 kg: ω = 100 rad/s, contact ≈ 31 ms; dt = 1e-5 s.
    let s = wall("response = \"penalty\"\nstiffness = 1e4", 0.5);
    for name in [
        "rk4",
        "velocity_verlet",
        "symplectic_euler",
        "implicit_euler",
    ] {
        let ev = measure(&s, name, 1e-5);
        let e = ev.restitution.unwrap();
        assert!((ev.expected_restitution - 0.5).abs() < 1e-12);
        assert!(
            (e / 0.5 - 1.0).abs() < 0.02,
            "{name}: measured e = {e}, formula 0.5"
        );
        let d = ev.expected_duration.unwrap();
        assert!(
            (ev.duration / d - 1.0).abs() < 0.02,
            "{name}: duration {} vs π/ω_d = {d}",
            ev.duration
        );
        assert!(
            (ev.v_in + 2.0).abs() < 1e-9,
            "v_in carried to the surface: {}",
            ev.v_in
        );
    }
}

#[test]
fn restitution_from_given_damping_matches_formula() {
    // c = 20 N·s/m: ζ = 20 / (2·√(1e4·1)) = 0.1, e = exp(−0.1π/√0.99) ≈ 0.7292.
    let s = wall(
        "response = \"penalty\"\nstiffness = 1e4\ndamping = 20.0",
        0.0,
    );
    let expected = (-0.1 * std::f64::consts::PI / (1.0f64 - 0.01).sqrt()).exp();
    let ev = measure(&s, "rk4", 1e-5);
    assert!((ev.expected_restitution - expected).abs() < 1e-12);
    let e = ev.restitution.unwrap();
    assert!(
        (e / expected - 1.0).abs() < 0.02,
        "measured e = {e}, formula {expected}"
    );
    // Largest penetration of the damped oscillator: below the undamped v/ω = 0.02 m.
    assert!(ev.max_penetration > 0.015 && ev.max_penetration < 0.02);
}
