//! One or two steps of every integrator on a 1-D oscillator, against values computed by hand
//! from each method's defining formulas (the oracle is the textbook update rule itself, written
//! out here independently of the implementation).

mod common;
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
