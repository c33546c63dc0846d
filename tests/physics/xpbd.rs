//! xpbd against oracles nobody tuned: the damped oscillator's closed form (first-order
//! convergence in the substep), the equivalence of a spring and a compliant rod (the paper's
//! α = 1/k), a rigid rod kept to rounding, and Gauss–Seidel convergence on a rod chain.

use crate::common;
use springlab::integrate::{Stepper, Xpbd};
use springlab::method::{MethodOptions, Registry};
use springlab::run::{run_with, NoObserver, RunPlan};
use springlab::scenario::Scenario;

/// Textbook closed form of m ü + c u̇ + k u = 0 (m = 1, underdamped) from u(0) = u0, u̇(0) = 0.
fn closed_form(k: f64, c: f64, u0: f64, t: f64) -> f64 {
    let w0 = k.sqrt();
    let zeta = c / (2.0 * w0);
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    (-zeta * w0 * t).exp() * (u0 * (wd * t).cos() + zeta * w0 * u0 / wd * (wd * t).sin())
}

/// Largest |u − closed form| over 2 s of frames of 0.1 s, with `n` substeps per frame.
fn oscillator_error(scene: &Scenario, rest: f64, n: usize) -> f64 {
    let sys = scene.build();
    let mut s = scene.initial_state();
    let mut m = Xpbd::new(n, 1);
    let mut err: f64 = 0.0;
    for f in 1..=20 {
        m.step(&sys, &mut s, 0.1).unwrap();
        let u = s.x[1].x - rest;
        err = err.max((u - closed_form(4.0, 0.3, 0.1, f as f64 * 0.1)).abs());
    }
    err
}

#[test]
fn converges_to_the_damped_springs_closed_form_at_first_order() {
    // k = 4, c = 0.3, 1 kg: one iteration per substep is backward Euler on the spring and the
    // damper, so the error halves with each doubling of the substeps.
    let hooke = common::oscillator(4.0, 0.3, 0.1, 0.0);
    // The strain law with L = 2 and k = 8 N is k_eff = 4 N/m: the same oscillator.
    let strain = Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[2.1,0.0,0.0]\nmass=1.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness=8.0\nrest_length=2.0\ndamping=0.3\nlaw=\"strain\"\n",
        "strain.toml",
    )
    .unwrap();
    let ns = [8, 16, 32, 64, 128];
    for (scene, rest) in [(&hooke, 1.0), (&strain, 2.0)] {
        let errs: Vec<f64> = ns
            .iter()
            .map(|&n| oscillator_error(scene, rest, n))
            .collect();
        let h: Vec<f64> = ns.iter().map(|&n| 0.1 / n as f64).collect();
        let p = common::loglog_slope(&h, &errs);
        eprintln!("{}: errors {errs:?}, order {p:.3}", scene.name);
        assert!((p - 1.0).abs() < 0.1, "order {p}, errors {errs:?}");
        assert!(errs[4] < errs[0] / 10.0);
    }
}

#[test]
fn a_spring_and_a_rod_of_compliance_one_over_k_are_the_same_constraint() {
    // Oracle: XPBD's definition (Macklin et al. 2016, α = 1/k).
    let spring = common::oscillator(4.0, 0.0, 0.1, 0.0);
    let rod = Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.1,0.0,0.0]\nmass=1.0\n\
         [[constraint]]\nbetween=[0,1]\nlength=1.0\ncompliance=0.25\n",
        "rod.toml",
    )
    .unwrap();
    let end = |scene: &Scenario| {
        let sys = scene.build();
        let mut s = scene.initial_state();
        let mut m = Xpbd::new(3, 2);
        for _ in 0..50 {
            m.step(&sys, &mut s, 0.05).unwrap();
        }
        s
    };
    let (a, b) = (end(&spring), end(&rod));
    assert_eq!(a.x[1].x.to_bits(), b.x[1].x.to_bits());
    assert_eq!(a.v[1].x.to_bits(), b.v[1].x.to_bits());
}

#[test]
fn keeps_a_rigid_rod_pendulum_to_rounding() {
    // One rigid rod with a fixed end is projected exactly onto its length by one update, so
    // the violation is rounding: ≤ 1e-12 m on a 1 m rod over 5000 steps.
    let scene = Scenario::from_file("scenarios/pendulum_rod.toml").unwrap();
    let sys = scene.build();
    let mut m = springlab::method::create("xpbd", &MethodOptions::default()).unwrap();
    let mut s = scene.initial_state();
    let mut worst: f64 = 0.0;
    for _ in 0..5000 {
        m.step(&sys, &mut s, 1e-3).unwrap();
        worst = worst.max(sys.constraint_violation(&s.x));
    }
    eprintln!("pendulum_rod: largest violation {worst:e} m");
    assert!(worst <= 1e-12, "{worst:e}");
    // At a frame of 1/60 s with substeps the same holds.
    let mut m = Xpbd::new(20, 1);
    let mut s = scene.initial_state();
    for _ in 0..300 {
        m.step(&sys, &mut s, 1.0 / 60.0).unwrap();
        worst = worst.max(sys.constraint_violation(&s.x));
    }
    assert!(worst <= 1e-12, "{worst:e}");
}

#[test]
fn gauss_seidel_iterations_converge_a_rigid_rod_chain() {
    // Five rigid rods hanging from a pin, released horizontally: with k iterations per
    // substep the violation left after the solve falls as k grows: Gauss–Seidel on the
    // constraint system converges (geometrically, slowly on a chain), so each 4× more
    // iterations must at least halve it.
    let mut toml = String::from("[world]\ngravity=[0.0,-9.81,0.0]\n");
    for p in 0..6 {
        toml += &format!(
            "[[particle]]\nposition=[{},0.0,0.0]\nmass=0.1\nfixed={}\n",
            0.2 * p as f64,
            p == 0
        );
    }
    for p in 0..5 {
        toml += &format!("[[constraint]]\nbetween=[{p},{}]\nlength=0.2\n", p + 1);
    }
    let scene = Scenario::from_toml_str(&toml, "rod_chain.toml").unwrap();
    let sys = scene.build();
    let violation = |k: usize| {
        let mut m = Xpbd::new(10, k);
        let mut s = scene.initial_state();
        let mut worst: f64 = 0.0;
        for _ in 0..60 {
            m.step(&sys, &mut s, 1.0 / 60.0).unwrap();
            worst = worst.max(sys.constraint_violation(&s.x));
        }
        worst
    };
    let v: Vec<f64> = [1, 4, 16, 64].iter().map(|&k| violation(k)).collect();
    eprintln!("rod chain: violation by iterations 1, 4, 16, 64: {v:?}");
    assert!(v.windows(2).all(|w| w[1] < 0.5 * w[0]), "{v:?}");
}

#[test]
fn books_damper_work_and_leaves_numerical_dissipation_to_the_balance() {
    // With substeps the booked damper work approaches the exact flow's, and the balance
    // error (the position solve's numerical dissipation) shrinks at first order.
    let scene = Scenario::from_file("scenarios/damped_spring.toml").unwrap();
    let sys = scene.build();
    let balance = |n: usize| {
        let mut m = Xpbd::new(n, 1);
        let out = run_with(
            &sys,
            &mut m,
            Registry::builtin().info("xpbd").unwrap(),
            scene.initial_state(),
            &RunPlan::new(0.01, 100),
            &mut NoObserver,
        )
        .unwrap();
        assert!(out.final_energy.dissipated > 0.0);
        (out.final_energy.total - out.initial_energy.total).abs()
    };
    let (b1, b2) = (balance(4), balance(8));
    eprintln!("damped_spring balance errors {b1:e} {b2:e}");
    assert!(b1 / b2 > 1.6 && b1 / b2 < 2.5, "{b1:e} {b2:e}");
}
