//! Impulse and projection bounces against Newton's restitution law.
//!
//! Oracle: a ball leaving a plane with normal speed e·v rises to (e v)²/(2g), so successive
//! apex heights have ratio e² and each bounce removes the fraction 1 − e² of the mechanical
//! energy (Newton's experimental law of impact; any mechanics text). Also the energy account
//! K + G + E + dissipated must stay constant (a conservation law): rk4 is exact in free fall,
//! so any drift would be energy the contact stage failed to book.

use springlab::measure::contacts::ContactMetrics;
use springlab::method::create as by_name;
use springlab::method::MethodOptions;
use springlab::run::{run, RunPlan};
use springlab::scenario::Scenario;

fn scene(file: &str) -> Scenario {
    Scenario::from_file(format!("{}/scenarios/{file}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn apex_ratios(scene: &Scenario, method: &str, dt: f64) -> (Vec<f64>, f64) {
    let sys = scene.build();
    let mut stepper = by_name(method, &MethodOptions::default()).unwrap();
    let mut m = ContactMetrics::new(&sys, dt).expect("scene has obstacles");
    let plan = RunPlan::for_duration(dt, 1.3);
    let out = run(&sys, &mut stepper, scene.initial_state(), &plan, &mut m).unwrap();
    assert!(out.status.is_ok());
    let rep = m.report();
    let apexes = &rep.bounces[0].apexes;
    assert!((apexes[0].height - 1.0).abs() < 1e-12, "release height 1 m");
    let ratios: Vec<f64> = apexes.iter().filter_map(|a| a.ratio).collect();
    let drift =
        (out.final_energy.total - out.initial_energy.total).abs() / out.initial_energy.total.abs();
    (ratios, drift)
}

#[test]
fn impulse_apex_ratios_match_e_squared() {
    let s = scene("bounce.toml");
    let e: f64 = 0.5;
    for name in [
        "symplectic_euler",
        "velocity_verlet",
        "rk4",
        "implicit_euler",
    ] {
        let (ratios, _) = apex_ratios(&s, name, 1e-4);
        assert!(ratios.len() >= 3, "{name}: only {} bounces", ratios.len());
        for (n, r) in ratios.iter().take(3).enumerate() {
            let rel = (r / (e * e) - 1.0).abs();
            assert!(
                rel < 0.02,
                "{name}: apex ratio {} = {r}, e² = {}, off by {rel:.3}",
                n + 1,
                e * e
            );
        }
    }
}

#[test]
fn impulse_energy_account_balances() {
    // rk4 integrates free fall exactly; the contact stage books what it removes.
    let s = scene("bounce.toml");
    let (_, drift) = apex_ratios(&s, "rk4", 1e-3);
    assert!(drift < 1e-9, "energy account drifted by {drift:e}");
}

#[test]
fn projection_with_verlet_constraints_matches_e_squared() {
    let text = std::fs::read_to_string(format!(
        "{}/scenarios/bounce.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace("response = \"impulse\"", "response = \"projection\"");
    let s = Scenario::from_toml_str(&text, "bounce_projection.toml").unwrap();
    let (ratios, _) = apex_ratios(&s, "verlet_constraints", 1e-4);
    assert!(ratios.len() >= 3);
    for r in ratios.iter().take(3) {
        assert!((r / 0.25 - 1.0).abs() < 0.02, "apex ratio {r} vs e² = 0.25");
    }
}
