//! Rapier's pendulum on a rigid rod against the large-amplitude period.
//! Oracle: T = 4·√(L/g)·K(sin(θ0/2)) (exact period of the ideal pendulum; K by the AGM).
use crate::rapier_support;
use rapier_support::*;
use springlab::scenario::Scenario;

#[test]
fn pendulum_rod_period_matches_elliptic_formula() {
    let scene = Scenario::from_file("scenarios/pendulum_rod.toml").unwrap();
    let sys = scene.build();
    let s0 = scene.initial_state();
    let d = s0.x[1] - s0.x[0];
    let l = d.norm();
    let g = sys.gravity.unwrap().norm();
    let theta0 = (d.x / l).asin();
    let period = 4.0 * (l / g).sqrt() * elliptic_k((theta0 / 2.0).sin());
    let h = 1e-3;
    let steps = (2.6 * period / h) as u64;
    for name in METHODS {
        let (rec, out) = record(&scene, name, h, 4, steps);
        assert!(out.status.is_ok(), "{name}: {:?}", out.status);
        let t: Vec<f64> = rec.energy.iter().map(|e| e.0).collect();
        let x: Vec<f64> = rec.x.iter().map(|x| x[1].x).collect();
        let c = upward_crossings(&t, &x);
        assert!(c.len() >= 2, "{name}: {} crossings", c.len());
        let measured = c[c.len() - 1] - c[c.len() - 2];
        let rel = (measured - period).abs() / period;
        eprintln!("{name}: T = {measured:.6} s vs {period:.6} s (rel {rel:.2e})");
        // h = 1 ms resolves T to ~1e-4 by interpolation; a first-order scheme's phase error is
        // O(h) ~ 1e-3 relative at most here.
        assert!(
            rel < 2e-3,
            "{name}: period {measured} vs {period}, rel {rel}"
        );
    }
}
