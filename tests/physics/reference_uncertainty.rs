//! The reference measures its own error: uncertainty and predictability horizon.
//!
//! Oracles: (1) a chaotic double spring pendulum: the divergence of two references whose
//! gravity differs by a relative 1e-12 (a protocol independent of the
//! reference's own perturbation of positions) — the reported uncertainty must be of its
//! order and the horizon inside the run; (2) a linear damped spring, which cannot amplify
//! round-off (its flow is a contraction): no horizon, uncertainty at the tolerance level;
//! (3) the thread count cannot change a number.

use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::{Reference, ReferenceSolver};
use springlab::scenario::Scenario;

/// A double pendulum of two 1 kg beads on springs, released from a horizontal line: chaotic.
fn double_spring_pendulum(g: f64) -> Scenario {
    Scenario::from_toml_str(
        &format!(
            r#"
            [world]
            gravity = [0.0, {g:e}, 0.0]
            [[particle]]
            position = [0.0, 0.0, 0.0]
            mass = 1.0
            fixed = true
            [[particle]]
            position = [1.0, 0.0, 0.0]
            mass = 1.0
            [[particle]]
            position = [2.0, 0.0, 0.0]
            mass = 1.0
            [[spring]]
            between = [0, 1]
            stiffness = 50.0
            rest_length = 1.0
            [[spring]]
            between = [1, 2]
            stiffness = 50.0
            rest_length = 1.0
            "#
        ),
        "double_spring_pendulum.toml",
    )
    .unwrap()
}

fn reference(scene: &Scenario, grid: TimeGrid) -> Reference {
    let sys = scene.build();
    Reference::compute(&sys, &scene.initial_state(), &[grid], grid.time(grid.steps)).unwrap()
}

#[test]
fn chaotic_pendulum_reports_a_horizon_and_its_divergence() {
    let grid = TimeGrid::new(0.01, 6000, 6000);
    let duration = grid.time(grid.steps);
    let a = reference(&double_spring_pendulum(-9.81), grid);
    let b = reference(&double_spring_pendulum(-9.81 * (1.0 + 1e-12)), grid);
    let mut divergence: f64 = 0.0;
    for n in grid.sample_steps() {
        let (x, y) = (a.positions(0, n).unwrap(), b.positions(0, n).unwrap());
        for (p, q) in x.iter().zip(y) {
            divergence = divergence.max((p - q).norm());
        }
    }
    let info = &a.info;
    eprintln!(
        "double spring pendulum: divergence {divergence:e} m, uncertainty {:e} m, horizon {:?} s",
        info.uncertainty, info.predictability_horizon
    );
    let h = info
        .predictability_horizon
        .expect("a chaotic scene has a horizon");
    assert!(h > 0.0 && h < duration, "{h}");
    assert!(
        divergence > 1e-3,
        "the oracle scene is not chaotic: {divergence:e}"
    );
    let ratio = info.uncertainty / divergence;
    assert!(
        (0.1..10.0).contains(&ratio),
        "uncertainty / divergence = {ratio}"
    );
    // Per-sample uncertainty grows: small at the start, the maximum later.
    assert!(a.uncertainty_at(0, 10) < 1e-6 * info.uncertainty);
    assert!(!a.predictable_at(duration));
    assert!(a.predictable_at(0.0));
}

#[test]
fn linear_damped_spring_is_predictable_with_tiny_uncertainty() {
    let scene = Scenario::from_file("scenarios/damped_spring.toml").unwrap();
    let sys = scene.build();
    let s0 = scene.initial_state();
    let grid = TimeGrid::new(0.01, 500, 500);
    let r = Reference::compute_with(&sys, &s0, &[grid], 5.0, ReferenceSolver::Adaptive).unwrap();
    assert_eq!(r.info.kind.name(), "dop853");
    assert_eq!(r.info.predictability_horizon, None);
    // Tiny: the companions' distances (~1e-10 m) plus the dense output's own error estimate,
    // which is one order lower in the step than the interpolant's error and so overstates it.
    assert!(r.info.uncertainty < 1e-8, "{:e}", r.info.uncertainty);
    assert!(r.info.uncertainty > 0.0);
    // The closed form: round-off, no horizon.
    let exact = Reference::compute(&sys, &s0, &[grid], 5.0).unwrap();
    assert_eq!(exact.info.kind.name(), "analytic");
    assert_eq!(exact.info.predictability_horizon, None);
    assert!(
        exact.info.uncertainty <= 1e-13,
        "{:e}",
        exact.info.uncertainty
    );
    // The adaptive reference's distance to the closed form is within its uncertainty.
    for n in grid.sample_steps() {
        let d = (r.positions(0, n).unwrap()[1] - exact.positions(0, n).unwrap()[1]).norm();
        assert!(
            d <= r.floor_at(0, n),
            "step {n}: {d:e} > {:e}",
            r.floor_at(0, n)
        );
    }
}

#[test]
fn uncertainty_is_the_same_whatever_the_thread_count() {
    let grid = TimeGrid::new(0.01, 300, 300);
    let scene = double_spring_pendulum(-9.81);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| reference(&scene, grid))
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.info, b.info);
    for n in grid.sample_steps() {
        assert_eq!(a.positions(0, n), b.positions(0, n));
        assert_eq!(
            a.uncertainty_at(0, n).to_bits(),
            b.uncertainty_at(0, n).to_bits()
        );
    }
}
