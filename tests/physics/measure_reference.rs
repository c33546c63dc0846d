//! The adaptive reference (DOP853 at 1e-12) against the closed form.
//! Oracle: the closed-form damped/undamped oscillator (the `analytic` method's formula,
//! itself checked against textbook solutions in the core tests).

use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::{Reference, ReferenceSolver};
use springlab::scenario::Scenario;

fn max_gap(path: &str) -> (f64, f64, f64) {
    let scene = Scenario::from_file(path).unwrap();
    let sys = scene.build();
    let s0 = scene.initial_state();
    let grids = [
        TimeGrid::new(0.01, 500, 1000),
        TimeGrid::new(0.0123, 300, 100),
    ];
    let exact = Reference::compute(&sys, &s0, &grids, 5.0).unwrap();
    assert_eq!(exact.info.kind.name(), "analytic");
    let dop = Reference::compute_with(&sys, &s0, &grids, 5.0, ReferenceSolver::Adaptive).unwrap();
    assert_eq!(dop.info.kind.name(), "dop853");
    let mut worst: f64 = 0.0;
    for (g, grid) in grids.iter().enumerate() {
        for n in grid.sample_steps() {
            let a = exact.positions(g, n).unwrap();
            let b = dop.positions(g, n).unwrap();
            for (p, q) in a.iter().zip(b) {
                worst = worst.max((p - q).norm());
            }
        }
    }
    (worst, exact.period().unwrap(), dop.period().unwrap())
}

#[test]
fn dop853_matches_the_closed_form_on_the_anchored_spring() {
    let (gap, pe, pd) = max_gap("scenarios/anchored_spring.toml");
    assert!(gap < 1e-10, "max position gap {gap:e}");
    // ω = 2 rad/s: T = π.
    assert!((pe - std::f64::consts::PI).abs() < 1e-9, "{pe}");
    assert!((pd - pe).abs() < 1e-9);
}

#[test]
fn dop853_matches_the_closed_form_on_the_damped_spring() {
    let (gap, pe, pd) = max_gap("scenarios/damped_spring.toml");
    assert!(gap < 1e-10, "max position gap {gap:e}");
    // ω₀ = 10, ζ = 0.1: damped period 2π/(10·√(1 − 0.01)).
    let t = 2.0 * std::f64::consts::PI / (10.0 * (1.0f64 - 0.01).sqrt());
    assert!((pe - t).abs() < 1e-9, "{pe} vs {t}");
    assert!((pd - pe).abs() < 1e-9);
}

#[test]
fn constrained_reference_keeps_the_pendulum_period() {
    // Oracle: T = 4 √(L/g) K(sin(θ₀/2)) for θ₀ = 60°, L = 1, g = 9.81 (complete elliptic
    // integral K(k) = π/2 / AGM(1, √(1 − k²))).
    let scene = Scenario::from_file("scenarios/pendulum_rod.toml").unwrap();
    let sys = scene.build();
    let s0 = scene.initial_state();
    let grids = [TimeGrid::new(0.01, 500, 1000)];
    let r = Reference::compute(&sys, &s0, &grids, 5.0).unwrap();
    assert_eq!(r.info.kind.name(), "dop853_constrained");
    let k = (30f64.to_radians()).sin();
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        a = an;
        b = bn;
    }
    let t = 4.0 * (1.0f64 / 9.81).sqrt() * std::f64::consts::FRAC_PI_2 / a;
    let p = r.period().unwrap();
    assert!((p - t).abs() < 1e-8, "{p} vs {t}");
    let mut worst: f64 = 0.0;
    for n in grids[0].sample_steps() {
        let x = r.positions(0, n).unwrap();
        worst = worst.max(((x[1] - x[0]).norm() - 1.0).abs());
    }
    // Dense output between projected steps: violation at the solver tolerance.
    assert!(worst < 1e-10, "constraint violation {worst:e}");
}
