//! Global convergence orders on the anchored spring against the closed form u = u0 cos(ωt):
//! explicit, symplectic, implicit and linearly implicit Euler 1; rk2, velocity and position
//! Verlet, implicit midpoint, BDF2 and RATTLE 2; rk4 4 (Hairer, Nørsett & Wanner, *Solving
//! ODEs I*, §II.3; Hairer & Wanner, *Solving ODEs II*, §III.1 and §IV.9 (BDF, linearly
//! implicit); Hairer, Lubich & Wanner, *GNI*, §I.1 and §VII.1 (RATTLE)).

use crate::common;
use common::*;

fn final_error(name: &str, h: f64) -> f64 {
    let t_end = 2.0;
    let scene = oscillator(4.0, 0.0, 0.5, 0.0);
    let steps = (t_end / h).round() as u64;
    let out = run_steps(&scene, name, h, steps);
    let t = steps as f64 * h;
    let (u, v) = (0.5 * (2.0 * t).cos(), -(2.0 * t).sin());
    let s = &out.final_state;
    ((s.x[1].x - 1.0 - u).powi(2) + (s.v[1].x - v).powi(2)).sqrt()
}

fn order(name: &str, hs: &[f64]) -> f64 {
    let errs: Vec<f64> = hs.iter().map(|&h| final_error(name, h)).collect();
    loglog_slope(hs, &errs)
}

fn assert_order(name: &str, expected: f64, hs: &[f64]) {
    let p = order(name, hs);
    eprintln!("{name}: observed order {p:.3} (theory {expected})");
    assert!(
        (p - expected).abs() <= 0.15,
        "{name}: observed order {p:.3}, theory {expected}"
    );
}

const FINE: [f64; 4] = [0.01, 0.005, 0.0025, 0.00125];

#[test]
fn euler_family_is_first_order() {
    for name in ["explicit_euler", "symplectic_euler", "implicit_euler"] {
        assert_order(name, 1.0, &FINE);
    }
}

#[test]
fn second_order_methods() {
    for name in ["rk2", "velocity_verlet", "position_verlet"] {
        assert_order(name, 2.0, &FINE);
    }
}

#[test]
fn rk4_is_fourth_order() {
    assert_order("rk4", 4.0, &[0.04, 0.02, 0.01, 0.005]);
}

#[test]
fn damped_second_order_methods_stay_second_order() {
    // With an axial damper the velocity-dependent force must not cost the Verlets an order.
    let ref_scene = oscillator(4.0, 0.4, 0.5, 0.0);
    let exact = run_steps(&ref_scene, "analytic", 0.5, 4).final_state;
    for name in ["velocity_verlet", "position_verlet", "rk2"] {
        let hs = [0.004, 0.002, 0.001, 0.0005];
        let errs: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let s = run_steps(&ref_scene, name, h, (2.0 / h).round() as u64).final_state;
                ((s.x[1] - exact.x[1]).norm_squared() + (s.v[1] - exact.v[1]).norm_squared()).sqrt()
            })
            .collect();
        let p = loglog_slope(&hs, &errs);
        assert!((p - 2.0).abs() <= 0.15, "{name} damped: order {p:.3}");
        eprintln!("{name} damped: order {p:.3}");
    }
}

#[test]
fn implicit_and_constrained_methods_keep_their_orders_on_the_damped_spring() {
    // Oracle: the closed form of the damped spring ("analytic", exact at any step).
    let ref_scene = oscillator(4.0, 0.4, 0.5, 0.0);
    let exact = run_steps(&ref_scene, "analytic", 0.5, 4).final_state;
    let hs = [0.004, 0.002, 0.001, 0.0005];
    for (name, expected) in [
        ("linear_implicit_euler", 1.0),
        ("implicit_midpoint", 2.0),
        ("bdf2", 2.0),
        ("rattle", 2.0),
    ] {
        let errs: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let s = run_steps(&ref_scene, name, h, (2.0 / h).round() as u64).final_state;
                ((s.x[1] - exact.x[1]).norm_squared() + (s.v[1] - exact.v[1]).norm_squared()).sqrt()
            })
            .collect();
        let p = loglog_slope(&hs, &errs);
        eprintln!("{name} damped: order {p:.3} (theory {expected})");
        assert!((p - expected).abs() <= 0.15, "{name} damped: order {p:.3}");
    }
}

#[test]
fn implicit_methods_keep_their_orders_on_a_nonlinear_damped_swing() {
    // A damped spring with rest length swinging in a plane is nonlinear (so linearly implicit
    // Euler is not backward Euler and Newton really iterates). No closed form: the oracle is
    // Richardson's, e(h) = |y_h − y_{h/2}| ~ C hᵖ for a method of order p.
    let scene = springlab::scenario::Scenario::from_toml_str(
        "[world]\ndrag=0.05\n[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.3,0.0,0.0]\nvelocity=[0.0,1.5,0.0]\nmass=1.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness=30.0\nrest_length=1.0\ndamping=0.3\n",
        "swing.toml",
    )
    .unwrap();
    let hs = [0.004, 0.002, 0.001, 0.0005];
    for (name, expected) in [
        ("implicit_euler", 1.0),
        ("linear_implicit_euler", 1.0),
        ("implicit_midpoint", 2.0),
        ("bdf2", 2.0),
    ] {
        let finals: Vec<_> = hs
            .iter()
            .map(|&h| run_steps(&scene, name, h, (2.0 / h).round() as u64).final_state)
            .collect();
        let gaps: Vec<f64> = finals
            .windows(2)
            .map(|w| {
                ((w[0].x[1] - w[1].x[1]).norm_squared() + (w[0].v[1] - w[1].v[1]).norm_squared())
                    .sqrt()
            })
            .collect();
        let p = loglog_slope(&hs[..3], &gaps);
        eprintln!("{name} nonlinear swing: order {p:.3} (theory {expected})");
        assert!(
            (p - expected).abs() <= 0.15,
            "{name} nonlinear: order {p:.3}"
        );
    }
}
