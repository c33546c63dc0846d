//! The `analytic` method against the textbook closed forms of the damped oscillator
//! m u'' + c u' + k u = 0 (e.g. Thomson & Dahleh, *Theory of Vibration*, §2.6), written here in
//! their classic per-case forms, independent of the implementation's unified propagators.

use crate::common;
use common::*;

/// Textbook solution for m = 1: returns (u, v) at time t.
fn closed_form(k: f64, c: f64, u0: f64, v0: f64, t: f64) -> (f64, f64) {
    let w0 = k.sqrt();
    let zeta = c / (2.0 * w0);
    if zeta < 1.0 {
        let wd = w0 * (1.0 - zeta * zeta).sqrt();
        let a = u0;
        let b = (v0 + zeta * w0 * u0) / wd;
        let e = (-zeta * w0 * t).exp();
        let u = e * (a * (wd * t).cos() + b * (wd * t).sin());
        let v = e
            * (-zeta * w0 * (a * (wd * t).cos() + b * (wd * t).sin())
                + wd * (-a * (wd * t).sin() + b * (wd * t).cos()));
        (u, v)
    } else if zeta == 1.0 {
        let b = v0 + w0 * u0;
        let e = (-w0 * t).exp();
        (e * (u0 + b * t), e * (b - w0 * (u0 + b * t)))
    } else {
        let s = w0 * (zeta * zeta - 1.0).sqrt();
        let (r1, r2) = (-zeta * w0 + s, -zeta * w0 - s);
        let c2 = (v0 - r1 * u0) / (r2 - r1);
        let c1 = u0 - c2;
        (
            c1 * (r1 * t).exp() + c2 * (r2 * t).exp(),
            c1 * r1 * (r1 * t).exp() + c2 * r2 * (r2 * t).exp(),
        )
    }
}

fn check_case(c: f64) {
    let (k, u0, v0) = (4.0, 0.3, -0.2);
    let scene = oscillator(k, c, u0, v0);
    let sys = scene.build();
    for &h in &[1e-3, 0.1, 1.0, 10.0] {
        let mut i = stepper("analytic");
        let mut s = scene.initial_state();
        for n in 1..=20 {
            i.step(&sys, &mut s, h).unwrap();
            let (u, v) = closed_form(k, c, u0, v0, n as f64 * h);
            let (gu, gv) = (s.x[1].x - 1.0, s.v[1].x);
            assert!(
                (gu - u).abs() < 1e-12 && (gv - v).abs() < 1e-12,
                "c={c} h={h} n={n}: got ({gu}, {gv}) want ({u}, {v})"
            );
        }
    }
}

#[test]
fn undamped_matches_cosine_at_any_step() {
    check_case(0.0);
}

#[test]
fn underdamped_matches_closed_form_at_any_step() {
    check_case(0.8); // ζ = 0.2
}

#[test]
fn critically_damped_matches_closed_form_at_any_step() {
    check_case(4.0); // ζ = 1
}

#[test]
fn overdamped_matches_closed_form_at_any_step() {
    check_case(10.0); // ζ = 2.5
}

#[test]
fn impulses_are_applied_exactly() {
    // A kick Δv at t = 0.35 (inside a step of 0.1): the exact answer is the closed form from
    // rest to 0.35, then from the kicked state. The runner splits the step at the impulse.
    let toml = "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
        [[particle]]\nposition=[1.3,0.0,0.0]\nmass=1.0\n\
        [[spring]]\nbetween=[0,1]\nstiffness=4.0\nrest_length=1.0\ndamping=0.8\n\
        [[impulse]]\ntime=0.35\nparticle=1\ndelta_v=[1.5,0.0,0.0]\n";
    let scene = springlab::scenario::Scenario::from_toml_str(toml, "kick.toml").unwrap();
    let out = run_steps(&scene, "analytic", 0.1, 10);
    let (u1, v1) = closed_form(4.0, 0.8, 0.3, 0.0, 0.35);
    let (u, v) = closed_form(4.0, 0.8, u1, v1 + 1.5, 1.0 - 0.35);
    let s = &out.final_state;
    assert!((s.x[1].x - 1.0 - u).abs() < 1e-12 && (s.v[1].x - v).abs() < 1e-12);
    // The energy account balances: total (with dissipated and injected work) is conserved.
    assert!(
        (out.final_energy.total - out.initial_energy.total).abs() < 1e-12,
        "{:?} {:?}",
        out.final_energy,
        out.initial_energy
    );
    assert!((out.final_energy.injected - 0.5 * ((v1 + 1.5).powi(2) - v1 * v1)).abs() < 1e-12);
}

#[test]
fn analytic_refuses_coupled_scenes() {
    let scene = springlab::scenario::Scenario::from_file("scenarios/two_body.toml").unwrap();
    let why = stepper("analytic").check(&scene.build()).unwrap_err();
    assert!(why.contains("coupled"), "{why}");
    let chain = springlab::scenario::Scenario::from_file("scenarios/hanging_chain.toml").unwrap();
    assert!(stepper("analytic").check(&chain.build()).is_err());
}
