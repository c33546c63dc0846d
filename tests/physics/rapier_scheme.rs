//! Rapier against the schemes identified for it (src/rapier/scheme.rs).
//! Oracles: closed forms of the schemes themselves — symplectic Euler free fall
//! x_M = x0 + v0·M·hs + g·hs²·M(M+1)/2 and the backward-Euler oscillator, whose energy
//! ½(v² + ω²e²) shrinks by exactly 1/(1 + (ω·hs)²) per step (hs = h/N substep).
use crate::common;
use crate::rapier_support;
use rapier_support::*;
use springlab::rapier::{scheme_prediction, Mode};
use springlab::scenario::Scenario;

#[test]
fn free_fall_is_symplectic_euler_at_the_substep() {
    let scene = Scenario::from_toml_str(
        "[world]\ngravity=[0.0,-9.81,0.0]\n[[particle]]\nposition=[0.0,10.0,0.0]\nvelocity=[1.0,2.0,0.0]\nmass=2.0\n",
        "fall.toml",
    )
    .unwrap();
    let (x0, v0, g) = (
        scene.initial_state().x[0],
        scene.initial_state().v[0],
        scene.build().gravity.unwrap(),
    );
    for name in METHODS {
        for (h, n) in [(1.0 / 60.0, 4), (1.0 / 600.0, 1), (0.05, 3)] {
            let (rec, _) = record(&scene, name, h, n, 30);
            let hs = h / n as f64;
            for (f, x) in rec.x.iter().enumerate() {
                let m = (f * n) as f64;
                let want = x0 + v0 * (m * hs) + g * (hs * hs * m * (m + 1.0) / 2.0);
                assert!(
                    (x[0] - want).norm() < 1e-11,
                    "{name} h {h} n {n} frame {f}: {} vs {want}",
                    x[0]
                );
            }
            let p = scheme_prediction(
                Mode::of(name).unwrap(),
                &scene.build(),
                &scene.initial_state(),
                h,
                n,
                30,
            )
            .unwrap();
            for (m, q) in rec.energy.iter().zip(&p.curve) {
                assert!((m.1 - q.1).abs() < 1e-9 * m.1.abs().max(1.0));
            }
        }
    }
}

#[test]
fn impulse_spring_energy_decays_like_backward_euler() {
    let w = 2.0; // k = 4, m = 1
    let scene = common::oscillator(w * w, 0.0, 0.1, 0.3);
    for (h, n) in [(1.0 / 60.0, 4), (1.0 / 600.0, 1), (0.1, 2)] {
        let (rec, _) = record(&scene, "rapier_impulse", h, n, 200);
        let hs = h / n as f64;
        let e0 = rec.energy[0].1;
        for (f, e) in rec.energy.iter().enumerate() {
            let want = e0 * (1.0 + (w * hs).powi(2)).powi(-((f * n) as i32));
            assert!(
                (e.1 - want).abs() < 1e-12 * e0,
                "h {h} n {n} frame {f}: {} vs {want}",
                e.1
            );
        }
    }
}

#[test]
fn multibody_springs_claim_no_scheme() {
    let scene = common::oscillator(4.0, 0.0, 0.1, 0.0);
    let sys = scene.build();
    assert!(
        scheme_prediction(Mode::Multibody, &sys, &scene.initial_state(), 0.01, 4, 10).is_none()
    );
    assert!(scheme_prediction(
        Mode::of("rapier_impulse").unwrap(),
        &sys,
        &scene.initial_state(),
        0.01,
        4,
        10
    )
    .is_some());
}
