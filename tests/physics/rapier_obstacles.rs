//! Obstacles as fixed Rapier colliders: Rapier's bounce against Newton's restitution law.
//!
//! Oracle: a ball leaving a plane with normal speed e·v rises to (e v)²/(2g), so successive
//! apex heights have ratio e² (Newton's law of impact). Rapier applies restitution at the
//! velocity level with the obstacle's coefficient (combine rule Max against the particle's 0),
//! so at a small step its first apex ratios must be e² = 0.25 within 2 %. A fast particle shot
//! at a thin wall must not pass it (Rapier sweeps fixed colliders for fast bodies).

use springlab::measure::contacts::ContactMetrics;
use springlab::run::{run, RunPlan};
use springlab::scenario::Scenario;

fn scene(file: &str) -> Scenario {
    Scenario::from_file(format!("{}/scenarios/{file}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

#[test]
fn rapier_bounce_apex_ratios_match_e_squared() {
    let s = scene("bounce.toml");
    let sys = s.build();
    for name in ["rapier_impulse", "rapier_multibody"] {
        let dt = 1e-3;
        let mut stepper = springlab::method::create(name, &Default::default()).unwrap();
        assert!(stepper.info.contacts);
        let mut m = ContactMetrics::new(&sys, dt).expect("scene has obstacles");
        let out = run(
            &sys,
            &mut stepper,
            s.initial_state(),
            &RunPlan::for_duration(dt, 1.3),
            &mut m,
        )
        .unwrap();
        assert!(out.status.is_ok(), "{name}: {:?}", out.status);
        let rep = m.report();
        let ratios: Vec<f64> = rep.bounces[0]
            .apexes
            .iter()
            .filter_map(|a| a.ratio)
            .collect();
        assert!(ratios.len() >= 2, "{name}: only {} bounces", ratios.len());
        for (n, r) in ratios.iter().take(2).enumerate() {
            assert!(
                (r / 0.25 - 1.0).abs() < 0.02,
                "{name}: apex ratio {} = {r}",
                n + 1
            );
        }
    }
}

#[test]
fn rapier_fast_particle_does_not_pass_the_wall() {
    let s = scene("fast_particle_wall.toml");
    let sys = s.build();
    let mut stepper = springlab::method::create("rapier_impulse", &Default::default()).unwrap();
    let dt = s.run.dt.unwrap();
    let mut m = ContactMetrics::new(&sys, dt).expect("scene has obstacles");
    let out = run(
        &sys,
        &mut stepper,
        s.initial_state(),
        &RunPlan::new(dt, 50),
        &mut m,
    )
    .unwrap();
    assert!(out.status.is_ok());
    assert!(
        m.report().tunnelling.is_empty(),
        "Rapier let the particle through the wall"
    );
}
