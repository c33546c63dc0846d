//! Global convergence orders on the anchored spring against the closed form u = u0 cos(ωt):
//! explicit, symplectic and implicit Euler 1; rk2, velocity and position Verlet 2; rk4 4
//! (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.3; Hairer, Lubich & Wanner, *GNI*, §I.1).

mod common;
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
