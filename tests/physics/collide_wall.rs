//! Tunnelling through a thin wall.
//!
//! Oracle: geometry. The shipped particle moves 10 cm per step at a 2 cm wall, so a
//! position-only test misses it; it must never end up beyond the wall (x > 1.01 m) and the
//! metrics must count no tunnelling. A penalty contact (no swept response) must be caught by
//! the same detector, which shows the count can fail.

use springlab::measure::contacts::ContactMetrics;
use springlab::method::create as by_name;
use springlab::method::MethodOptions;
use springlab::run::{run, RunPlan};
use springlab::scenario::Scenario;

fn path() -> String {
    format!(
        "{}/scenarios/fast_particle_wall.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn tunnels(scene: &Scenario, method: &str) -> (u64, f64) {
    let sys = scene.build();
    let dt = scene.run.dt.unwrap();
    let mut stepper = by_name(method, &MethodOptions::default()).unwrap();
    let mut m = ContactMetrics::new(&sys, dt).unwrap();
    let plan = RunPlan::for_duration(dt, scene.run.duration.unwrap());
    let out = run(&sys, &mut stepper, scene.initial_state(), &plan, &mut m).unwrap();
    (m.report().tunnelling_count, out.final_state.x[0].x)
}

#[test]
fn shipped_fast_particle_does_not_tunnel() {
    let s = Scenario::from_file(path()).unwrap();
    for name in [
        "symplectic_euler",
        "velocity_verlet",
        "rk4",
        "implicit_euler",
        "explicit_euler",
    ] {
        let (count, x) = tunnels(&s, name);
        assert_eq!(count, 0, "{name}: tunnelled");
        assert!(
            x < 0.99,
            "{name}: ended at x = {x}, beyond the wall's front face"
        );
    }
}

#[test]
fn detector_counts_a_penalty_pass_through() {
    let text = std::fs::read_to_string(path()).unwrap().replace(
        "response = \"impulse\"",
        "response = \"penalty\"\nstiffness = 1e3",
    );
    let s = Scenario::from_toml_str(&text, "wall_penalty.toml").unwrap();
    let (count, x) = tunnels(&s, "symplectic_euler");
    assert!(
        x > 1.01,
        "the soft penalty wall should let it through, x = {x}"
    );
    assert_eq!(count, 1);
}
