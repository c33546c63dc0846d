//! One or two steps of every method on a 1-D oscillator, against values computed by hand
//! from each method's defining formulas (the oracle is the textbook update rule itself, written
//! out here independently of the implementation).

use crate::common;
use common::*;

// m = 1, k = 4 (ω² = 4), rest length 1, u0 = 0.5 (x0 = 1.5), v0 = 0; a(u) = −4u.
const H: f64 = 0.1;
const K: f64 = 4.0;
const U0: f64 = 0.5;

fn one(name: &str, steps: usize) -> (f64, f64) {
    let scene = oscillator(K, 0.0, U0, 0.0);
    let s = step_n(&scene.build(), &scene.initial_state(), name, H, steps);
    (s.x[1].x - 1.0, s.v[1].x)
}

fn close(got: (f64, f64), want: (f64, f64)) {
    assert!(
        (got.0 - want.0).abs() < 1e-14 && (got.1 - want.1).abs() < 1e-14,
        "got {got:?}, want {want:?}"
    );
}

#[test]
fn explicit_euler_uses_old_state() {
    // u1 = u0 + h v0 = 0.5; v1 = v0 + h(−4 u0) = −0.2
    close(one("explicit_euler", 1), (0.5, -0.2));
    // u2 = 0.5 + 0.1(−0.2) = 0.48; v2 = −0.2 − 0.4·0.5 = −0.4
    close(one("explicit_euler", 2), (0.48, -0.4));
}

#[test]
fn symplectic_euler_kicks_then_drifts() {
    // v1 = −0.2; u1 = 0.5 + 0.1(−0.2) = 0.48
    close(one("symplectic_euler", 1), (0.48, -0.2));
    // v2 = −0.2 − 0.4·0.48 = −0.392; u2 = 0.48 − 0.0392 = 0.4408
    close(one("semi_implicit_euler", 2), (0.4408, -0.392));
}

#[test]
fn implicit_euler_solves_backward_step() {
    // v1 = v0 − h·4·u1, u1 = u0 + h v1  ⇒  u1 = u0 / (1 + 4h²) = 0.5/1.04, v1 = −0.4 u1.
    let u1 = 0.5 / 1.04;
    let (u, v) = one("implicit_euler", 1);
    assert!(
        (u - u1).abs() < 1e-12 && (v + 0.4 * u1).abs() < 1e-11,
        "{u} {v}"
    );
}

#[test]
fn rk2_midpoint() {
    // k1 = (v0, a0) = (0, −2); mid: u = 0.5, v = −0.1 ⇒ k2 = (−0.1, −2).
    // u1 = 0.5 + 0.1(−0.1) = 0.49; v1 = 0 + 0.1(−2) = −0.2
    close(one("rk2", 1), (0.49, -0.2));
}

#[test]
fn rk4_classic() {
    // k1 = (0, −2); k2: u = 0.5, v = −0.1 → (−0.1, −2); k3: u = 0.495, v = −0.1 → (−0.1, −1.98);
    // k4: u = 0.49, v = −0.198 → (−0.198, −1.96).
    // u1 = 0.5 + 0.1/6 (0 − 0.2 − 0.2 − 0.198) = 0.5 − 0.00996666…
    // v1 = 0.1/6 (−2 − 4 − 3.96 − 1.96) = −0.198666…
    let u1 = 0.5 + 0.1 / 6.0 * (0.0 - 0.2 - 0.2 - 0.198);
    let v1 = 0.1 / 6.0 * (-2.0 - 4.0 - 3.96 - 1.96);
    close(one("rk4", 1), (u1, v1));
}

#[test]
fn velocity_verlet_kick_drift_kick() {
    // v½ = −0.1; u1 = 0.5 − 0.01 = 0.49; a1 = −1.96; v1 = −0.1 − 0.098 = −0.198
    close(one("velocity_verlet", 1), (0.49, -0.198));
}

#[test]
fn position_verlet_stormer_two_step() {
    // Start: u1 = u0 + h v0 + h²/2 a0 = 0.5 − 0.01 = 0.49; v1 = (u1 − u0)/h + h/2 a1 = −0.1 − 0.098.
    close(one("position_verlet", 1), (0.49, -0.198));
    // Störmer: u2 = 2u1 − u0 + h² a1 = 0.98 − 0.5 − 0.0196 = 0.4604;
    // a2 = −1.8416; v2 = (0.4604 − 0.49)/0.1 + 0.05(−1.8416) = −0.296 − 0.09208
    close(one("position_verlet", 2), (0.4604, -0.296 - 0.09208));
}

#[test]
fn verlet_constraints_without_constraints_is_jakobsen_verlet() {
    // x* = x + h v + h² a: u1 = 0.5 + 0 − 0.02 = 0.48; v1 = (u1 − u0)/h = −0.2
    close(one("verlet_constraints", 1), (0.48, -0.2));
}

#[test]
fn analytic_is_the_cosine() {
    // u = 0.5 cos(2t), v = −sin(2t) at t = 0.1.
    close(one("analytic", 1), (0.5 * (0.2f64).cos(), -(0.2f64).sin()));
}

#[test]
fn verlet_constraints_projects_a_rod() {
    // Bob at (1, 0) on a rod of length 1 from a fixed pivot, moving at v = (0, 1): one step of
    // h = 0.1 predicts (1, 0.1), and projection onto the circle gives (1, 0.1)/|(1, 0.1)|.
    let scene = springlab::scenario::Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.0,0.0,0.0]\nvelocity=[0.0,1.0,0.0]\nmass=1.0\n\
         [[constraint]]\nbetween=[0,1]\n",
        "rod.toml",
    )
    .unwrap();
    let s = step_n(
        &scene.build(),
        &scene.initial_state(),
        "verlet_constraints",
        0.1,
        1,
    );
    let r = (1.0f64 + 0.01).sqrt();
    assert!((s.x[1].x - 1.0 / r).abs() < 1e-15 && (s.x[1].y - 0.1 / r).abs() < 1e-15);
    assert!((s.v[1].y - 0.1 / r / 0.1).abs() < 1e-13);
}

#[test]
fn implicit_midpoint_is_the_cayley_map() {
    // u1 = u0 + h(v0 + v1)/2, v1 = v0 − h·4(u0 + u1)/2 with v0 = 0, h = 0.1:
    // v1 = −0.2(u0 + u1), u1 = u0 − 0.01(u0 + u1) ⇒ u1 = 0.5·0.99/1.01, v1 = −0.2/1.01.
    let (u, v) = one("implicit_midpoint", 1);
    let want = (0.5 * 0.99 / 1.01, -0.2 / 1.01);
    assert!(
        (u - want.0).abs() < 1e-14 && (v - want.1).abs() < 1e-14,
        "{u} {v}, want {want:?}"
    );
}

#[test]
fn bdf2_starts_with_backward_euler_then_uses_two_steps() {
    // Start (documented): one backward-Euler step, u1 = u0/(1 + 4h²), v1 = −0.4 u1.
    let u1 = 0.5 / 1.04;
    let v1 = -0.4 * u1;
    let (u, v) = one("bdf2", 1);
    assert!((u - u1).abs() < 1e-14 && (v - v1).abs() < 1e-14, "{u} {v}");
    // BDF2: y2 − (4/3) y1 + (1/3) y0 = (2h/3) F(y2), β = 2h/3 = 1/15:
    // u2 = û + β v2, v2 = v̂ − 4β u2 with û = (4u1 − u0)/3, v̂ = (4v1 − v0)/3
    // ⇒ u2 = (û + β v̂)/(1 + 4β²), v2 = v̂ − 4β u2.
    let (uh, vh, beta) = ((4.0 * u1 - U0) / 3.0, (4.0 * v1) / 3.0, 2.0 * H / 3.0);
    let u2 = (uh + beta * vh) / (1.0 + K * beta * beta);
    let v2 = vh - K * beta * u2;
    let (u, v) = one("bdf2", 2);
    assert!((u - u2).abs() < 1e-14 && (v - v2).abs() < 1e-14, "{u} {v}");
}

#[test]
fn linear_implicit_euler_solves_once_with_the_start_jacobian() {
    // Nonlinear case (so that it differs from backward Euler): anchor at 0, bob at (1.5, 0, 0)
    // moving at (0, 1, 0), k = 4, rest length 1, m = 1, h = 0.1. At the start
    // f0 = (−2, 0, 0) and ∂f/∂x = −4 diag(1, 1/3, 1/3) (axial k, transverse k(1 − l0/L)), so
    // (I − h² ∂f/∂x) Δv = h (f0 + h ∂f/∂x v0) is diagonal:
    // Δv = (−0.2/1.04, −(0.04/3)/(1 + 0.04/3), 0), v1 = v0 + Δv, x1 = x0 + h v1.
    let scene = springlab::scenario::Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.5,0.0,0.0]\nvelocity=[0.0,1.0,0.0]\nmass=1.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness=4.0\nrest_length=1.0\n",
        "swing.toml",
    )
    .unwrap();
    let s = step_n(
        &scene.build(),
        &scene.initial_state(),
        "linear_implicit_euler",
        0.1,
        1,
    );
    let v1 = [-0.2 / 1.04, 1.0 - (0.04 / 3.0) / (1.0 + 0.04 / 3.0), 0.0];
    let x1 = [1.5 + 0.1 * v1[0], 0.1 * v1[1], 0.0];
    for c in 0..3 {
        assert!((s.v[1][c] - v1[c]).abs() < 1e-14, "v {:?}", s.v[1]);
        assert!((s.x[1][c] - x1[c]).abs() < 1e-14, "x {:?}", s.x[1]);
    }
    assert_eq!(s.x[0], springlab::model::Vec3::zeros(), "the anchor stays");
}

#[test]
fn rattle_shakes_along_the_old_rod_then_projects_the_velocity() {
    // Bob at (1, 0) on a rigid rod of length 1 from a fixed pivot, v = (0, 1), no forces,
    // h = 0.1. SHAKE moves the unconstrained x* = (1, h) along the start-of-step rod direction
    // (1, 0) back onto the circle: x1 = (√(1 − h²), h). v½ = (x1 − x0)/h, and RATTLE's velocity
    // stage removes the component along the new rod x1: v1 = v½ − (v½·x1) x1.
    // (Jakobsen's projection, verlet_constraints above, moves radially instead.)
    let scene = springlab::scenario::Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.0,0.0,0.0]\nvelocity=[0.0,1.0,0.0]\nmass=1.0\n\
         [[constraint]]\nbetween=[0,1]\n",
        "rod.toml",
    )
    .unwrap();
    let h = 0.1f64;
    let s = step_n(&scene.build(), &scene.initial_state(), "rattle", h, 1);
    let c = (1.0 - h * h).sqrt();
    let vh = [(c - 1.0) / h, 1.0];
    let along = vh[0] * c + vh[1] * h;
    let v1 = [vh[0] - along * c, vh[1] - along * h];
    assert!(
        (s.x[1].x - c).abs() < 1e-15 && (s.x[1].y - h).abs() < 1e-15,
        "{:?}",
        s.x[1]
    );
    assert!(
        (s.v[1].x - v1[0]).abs() < 1e-14 && (s.v[1].y - v1[1]).abs() < 1e-14,
        "{:?}, want {v1:?}",
        s.v[1]
    );
}
