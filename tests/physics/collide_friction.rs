//! Coulomb friction of every response against the sliding-block closed form.
//!
//! Oracle: a particle sliding on a horizontal plane with Coulomb friction μ decelerates at μg
//! and stops after v0² / (2μg) (any mechanics text); every response must reproduce it.

use springlab::method::create as by_name;
use springlab::method::MethodOptions;
use springlab::run::{run, NoObserver, RunPlan};
use springlab::scenario::Scenario;

fn slide(collision: &str, method: &str, dt: f64) -> f64 {
    let s = Scenario::from_toml_str(
        &format!(
            r#"
            [world]
            gravity = [0.0, -9.81, 0.0]
            [[particle]]
            position = [0.0, 0.0, 0.0]
            velocity = [2.0, 0.0, 0.0]
            mass = 1.0
            [[obstacle]]
            shape = "plane"
            point = [0.0, 0.0, 0.0]
            normal = [0.0, 1.0, 0.0]
            friction = 0.5
            [collision]
            {collision}
            "#
        ),
        "slide.toml",
    )
    .unwrap();
    let sys = s.build();
    let mut stepper = by_name(method, &MethodOptions::default()).unwrap();
    let out = run(
        &sys,
        &mut stepper,
        s.initial_state(),
        &RunPlan::for_duration(dt, 0.8),
        &mut NoObserver,
    )
    .unwrap();
    assert!(out.status.is_ok());
    out.final_state.x[0].x
}

#[test]
fn every_response_stops_a_slide_at_v0_squared_over_two_mu_g() {
    let expected = 2.0f64.powi(2) / (2.0 * 0.5 * 9.81);
    let cases = [
        ("response = \"impulse\"", "symplectic_euler"),
        ("response = \"impulse\"", "velocity_verlet"),
        ("response = \"projection\"", "verlet_constraints"),
        (
            "response = \"penalty\"\nstiffness = 1e5\nrestitution = 0.0",
            "rk4",
        ),
    ];
    for (collision, name) in cases {
        let d = slide(collision, name, 1e-4);
        assert!(
            (d / expected - 1.0).abs() < 0.02,
            "{collision} / {name}: stopped at {d}, expected {expected}"
        );
    }
}
