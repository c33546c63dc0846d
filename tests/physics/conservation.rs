//! Conservation laws: two free masses on a spring feel only equal and opposite forces, so
//! total momentum is conserved exactly by every method that applies force pairs symmetrically
//! (to round-off); the energy account balances for dissipative scenes.

use crate::common;
use common::*;
use springlab::scenario::Scenario;

#[test]
fn momentum_is_conserved_on_two_free_masses() {
    let scene = Scenario::from_file("scenarios/two_body.toml").unwrap();
    let sys = scene.build();
    let p0 = sys.momentum(&scene.initial_state().v);
    for &name in springlab::method::Registry::builtin()
        .native_names()
        .iter()
        .filter(|n| **n != "analytic")
    {
        let out = run_steps(&scene, name, 0.01, 500);
        // Explicit Euler grows an undamped oscillator's energy at every step (|1 + ihω|² =
        // 1 + h²ω², ω² = 40 /s²): over 500 steps of 0.01 s by e^(500·0.004) ≈ 7.4, growth the
        // verdict cannot yet tell from a bounded swing, far below its cap. Every run finishes;
        // momentum is conserved over all of them.
        assert_eq!(out.steps_done, 500, "{name}: {:?}", out.status);
        let p = sys.momentum(&out.final_state.v);
        // Implicit Euler's Newton solve is symmetric too, but its CG stops at a tolerance.
        let tol = if name == "implicit_euler" {
            1e-9
        } else {
            1e-12
        }; // round-off over 500 steps of |p| ~ 1
        assert!(
            (p - p0).norm() < tol,
            "{name}: momentum drift {:e}",
            (p - p0).norm()
        );
    }
}

#[test]
fn damped_energy_account_balances_to_the_methods_order() {
    // damped_spring: gravity + damper. total = K + U + dissipated is constant for the exact
    // flow; rk4 integrates the dissipated power with its own weights, so the balance error
    // falls as h⁴ (ratio 16 per halving, allow 12–20).
    let scene = Scenario::from_file("scenarios/damped_spring.toml").unwrap();
    let err = |h: f64| {
        let out = run_steps(&scene, "rk4", h, (1.0 / h).round() as u64);
        (out.final_energy.total - out.initial_energy.total).abs()
    };
    let (e1, e2) = (err(0.01), err(0.005));
    assert!(
        e1 / e2 > 12.0 && e1 / e2 < 20.0,
        "balance errors {e1:e} {e2:e}"
    );
}

#[test]
fn implicit_methods_book_dissipation_to_their_order() {
    // The energy account K + U + dissipated is constant for the exact flow; each method books
    // the dissipated work with a quadrature of its own order (backward Euler's h·P(end) for
    // linearly implicit Euler, the trapezoidal rule for BDF2 and RATTLE), so the balance error
    // falls by 2ᵖ per halving of h (allow ±30 %).
    let scene = Scenario::from_file("scenarios/damped_spring.toml").unwrap();
    let err = |name: &str, h: f64| {
        let out = run_steps(&scene, name, h, (1.0 / h).round() as u64);
        (out.final_energy.total - out.initial_energy.total).abs()
    };
    for (name, p) in [("linear_implicit_euler", 1), ("bdf2", 2), ("rattle", 2)] {
        let (e1, e2) = (err(name, 0.002), err(name, 0.001));
        let want = 2f64.powi(p);
        eprintln!("{name}: balance errors {e1:e} {e2:e}, ratio {}", e1 / e2);
        assert!(
            (e1 / e2 / want - 1.0).abs() < 0.3,
            "{name}: balance errors {e1:e} {e2:e}"
        );
    }
    // Implicit midpoint balances exactly on this (axially linear) scene: with u = (v + v')/2,
    // E' − E = h u·f(x_½, u) + (elastic and gravity terms, exact for a quadratic energy) =
    // −h P(x_½, u), which is precisely what it books. Up to the solver and rounding.
    let scale = run_steps(&scene, "analytic", 1.0, 1)
        .initial_energy
        .total
        .abs();
    for h in [0.1, 0.01, 0.001] {
        let e = err("implicit_midpoint", h);
        eprintln!("implicit_midpoint h = {h}: balance error {e:e}");
        assert!(e <= 1e-12 * scale, "h = {h}: {e:e}");
    }
}
