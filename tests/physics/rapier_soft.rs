//! Rapier's soft bodies (`rapier_soft`, `rapier_soft_fem`) against closed forms.
//! Oracles: the under-damped oscillator x(t) = x_eq + A·e^(−ζω₀t)·(cos ω_d t + ζω₀/ω_d·sin ω_d t)
//! (any mechanics text; ω₀ = √(k/m), ω_d = ω₀√(1 − ζ²)); the reduced two-body oscillator
//! (period 2π√(μ/k), μ = m₁m₂/(m₁ + m₂)) and total momentum conservation (edge impulses are
//! equal and opposite); linear drag's exponential decay v(t) = v₀·e^(−ct/m); free fall
//! x = x₀ + v₀t − gt²/2. The engines step symplectic Euler with an implicit spring per
//! substep, so the error at a fixed frame rate falls as the first power of the substep.
use crate::rapier_support::*;
use springlab::scenario::Scenario;

/// Both soft-body methods.
const SOFT: [&str; 2] = ["rapier_soft", "rapier_soft_fem"];

fn scene(toml: &str) -> Scenario {
    Scenario::from_toml_str(toml, "soft.toml").expect("valid scene")
}

/// A 1 kg bob on a k = 100 N/m, c = 2 N·s/m spring (ζ = 0.1) hanging from a pinned anchor,
/// released 0.5 m below its rest length (no gravity, so the equilibrium is the rest length).
const DAMPED: &str = r#"
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true
[[particle]]
position = [0.0, -1.5, 0.0]
mass = 1.0
[[spring]]
between = [0, 1]
stiffness = 100.0
rest_length = 1.0
damping = 2.0
"#;

/// Largest |y(t) − closed form| over a run of `frames` at 60 Hz with `substeps`.
fn damped_error(name: &str, substeps: usize, frames: u64) -> f64 {
    let (k, m, c, a) = (100.0_f64, 1.0_f64, 2.0_f64, -0.5_f64);
    let w0 = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    let exact = |t: f64| {
        -1.0 + a * (-zeta * w0 * t).exp() * ((wd * t).cos() + zeta * w0 / wd * (wd * t).sin())
    };
    let (rec, out) = record(&scene(DAMPED), name, 1.0 / 60.0, substeps, frames);
    assert!(out.status.is_ok(), "{name}: {:?}", out.status);
    rec.x
        .iter()
        .zip(&rec.energy)
        .map(|(x, e)| (x[1].y - exact(e.0)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_damped_spring_follows_its_closed_form_at_60_hz_and_64_substeps() {
    for name in SOFT {
        let err = damped_error(name, 64, 180);
        eprintln!("{name}: max |y − y_exact| over 3 s = {err:.3e} m of a 0.5 m swing");
        // "Within a few percent of the amplitude": 3 % of 0.5 m.
        assert!(err < 0.015, "{name}: {err}");
    }
}

#[test]
fn the_damped_spring_error_is_first_order_in_the_substep() {
    for name in SOFT {
        let (e16, e64) = (damped_error(name, 16, 180), damped_error(name, 64, 180));
        let order = (e16 / e64).ln() / 4f64.ln();
        eprintln!("{name}: error {e16:.3e} at 16, {e64:.3e} at 64 substeps: order {order:.2}");
        // First order: a quarter of the substep gives a quarter of the error (order 1 ± 0.25).
        assert!((order - 1.0).abs() < 0.25, "{name}: order {order}");
    }
}

/// Unequal masses 1 kg and 3 kg on a k = 30 N/m spring, stretched 0.2 m, the pair drifting at
/// (0.3, 0.1, 0) m/s overall (no gravity).
const PAIR: &str = r#"
[[particle]]
position = [0.0, 0.0, 0.0]
velocity = [0.3, 0.1, 0.0]
mass = 1.0
[[particle]]
position = [1.2, 0.0, 0.0]
velocity = [0.3, 0.1, 0.0]
mass = 3.0
[[spring]]
between = [0, 1]
stiffness = 30.0
rest_length = 1.0
"#;

#[test]
fn an_unequal_free_pair_keeps_its_momentum_and_its_reduced_period() {
    let mu: f64 = 1.0 * 3.0 / 4.0;
    let period = std::f64::consts::TAU * (mu / 30.0).sqrt();
    let p0 = springlab::model::Vec3::new(1.2, 0.4, 0.0);
    for name in SOFT {
        let frames = (4.0 * period * 60.0) as u64;
        let (rec, out) = record(&scene(PAIR), name, 1.0 / 60.0, 64, frames);
        assert!(out.status.is_ok());
        let drift = rec
            .v
            .iter()
            .map(|v| (v[0] * 1.0 + v[1] * 3.0 - p0).norm())
            .fold(0.0, f64::max);
        let t: Vec<f64> = rec.energy.iter().map(|e| e.0).collect();
        let ext: Vec<f64> = rec.x.iter().map(|x| (x[1] - x[0]).norm() - 1.0).collect();
        let c = upward_crossings(&t, &ext);
        let measured = (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64;
        let rel = (measured - period).abs() / period;
        eprintln!("{name}: |ΔP| ≤ {drift:.2e} kg·m/s; period {measured:.5} s vs {period:.5} s");
        // Momentum: the constraint solver's edge impulses are equal and opposite, so it keeps
        // P to round-off; the FEM solver's conjugate gradient stops at a relative residual of
        // 1e-5 (Rapier's default `linear_tolerance`), so it keeps P to that fraction of |P₀|.
        let bound = if name == "rapier_soft" { 1e-12 } else { 1e-5 } * p0.norm();
        assert!(drift < bound, "{name}: momentum drifts by {drift}");
        // Period: within a few percent, the frame (1/60 s) being 1/27 of the period.
        assert!(rel < 0.03, "{name}: period {measured} vs {period}");
    }
}

#[test]
fn drag_decays_a_pair_exponentially_and_gravity_is_free_fall() {
    // Two 0.1 kg particles at rest length moving together at 1 m/s, drag c = 0.05 N·s/m:
    // v(2 s) = e^(−c·2/m) = e⁻¹.
    let drag = scene(
        r#"
[world]
drag = 0.05
[[particle]]
position = [0.0, 0.0, 0.0]
velocity = [1.0, 0.0, 0.0]
mass = 0.1
[[particle]]
position = [0.0, 1.0, 0.0]
velocity = [1.0, 0.0, 0.0]
mass = 0.1
[[spring]]
between = [0, 1]
stiffness = 10.0
"#,
    );
    // A free pair falling from rest under g = 9.81 m/s² for 1 s: y = −g/2.
    let fall = scene(
        r#"
[world]
gravity = [0.0, -9.81, 0.0]
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 0.1
[[particle]]
position = [0.5, 0.0, 0.0]
mass = 0.1
[[spring]]
between = [0, 1]
stiffness = 10.0
"#,
    );
    for name in SOFT {
        let (rec, _) = record(&drag, name, 1.0 / 60.0, 8, 120);
        let v = rec.v.last().unwrap()[0].x;
        let exact = (-1.0f64).exp();
        eprintln!("{name}: v(2 s) = {v:.5} vs e⁻¹ = {exact:.5}");
        // Rapier damps once per frame H, v ← v/(1 + H·c/m) (its documented law): exactly
        // (1 + H·c/m)^(−120) after 120 frames, which is e⁻¹ to first order, the relative
        // error being t·(c/m)²·H/2 = 4.2e-3.
        let law = (1.0 + 0.5 / 60.0_f64).powi(-120);
        assert!((v - law).abs() < 1e-9, "{name}: {v} vs Rapier's law {law}");
        assert!((v - exact).abs() < 4.5e-3 * exact, "{name}: {v}");
        let (rec, _) = record(&fall, name, 1.0 / 60.0, 8, 60);
        let y = rec.x.last().unwrap()[0].y;
        // Symplectic Euler's free fall over n substeps of h = t/n (kick then drift):
        // y = −g·h²·n(n + 1)/2 = −g·t²/2·(1 + 1/n), n = 60 frames × 8 substeps.
        let exact = -0.5 * 9.81 * (1.0 + 1.0 / 480.0);
        eprintln!("{name}: y(1 s) = {y:.6} vs −g/2·(1 + 1/480) = {exact:.6}");
        assert!((y - exact).abs() < 1e-9, "{name}: {y}");
    }
}

#[test]
fn a_pinned_particle_stays_where_it_was() {
    for name in SOFT {
        let (rec, _) = record(&scene(DAMPED), name, 1.0 / 60.0, 4, 60);
        assert!(rec.x.iter().all(|x| x[0].norm() == 0.0), "{name}");
    }
}

#[test]
fn what_a_soft_body_cannot_express_is_refused_with_the_reason_and_its_twin_runs() {
    const ROD: &str = r#"
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true
[[particle]]
position = [1.0, 0.0, 0.0]
mass = 1.0
[[constraint]]
between = [0, 1]
"#;
    let rod = scene(ROD);
    let compliant_rod = scene(&format!("{ROD}compliance = 0.001\n"));
    let unequal_drag = scene(&format!("[world]\ndrag = 0.1\n{PAIR}"));
    let opts = springlab::method::MethodOptions::default();
    for name in SOFT {
        let m = springlab::method::create(name, &opts).unwrap();
        let why = m.check(&rod.build()).unwrap_err();
        assert!(why.contains("rigid rod"), "{name}: {why}");
        assert!(m.check(&compliant_rod.build()).is_ok(), "{name}");
        let why = m.check(&unequal_drag.build()).unwrap_err();
        assert!(
            why.contains("drag") && why.contains("unequal mass"),
            "{name}: {why}"
        );
        assert!(m.check(&scene(PAIR).build()).is_ok(), "{name}");
    }
}

// Oracle: the one-step scheme Rapier's impulse-joint springs were measured to follow
// (substepped symplectic Euler with the spring implicit per substep, `scheme_prediction`):
// a soft-body edge is the same soft constraint, so on one spring between two free masses the
// soft methods' energy follows the same predicted curve.
#[test]
fn soft_energy_follows_the_engines_predicted_scheme() {
    let scene = Scenario::from_file("scenarios/two_body.toml").unwrap();
    let sys = scene.build();
    let impulse = springlab::rapier::Mode::of("rapier_impulse").unwrap();
    for name in SOFT {
        for (h, n) in [(1.0 / 60.0, 4), (1.0 / 600.0, 1), (0.01, 2)] {
            let steps = 120;
            let (rec, _) = record(&scene, name, h, n, steps);
            let p = springlab::rapier::scheme_prediction(
                impulse,
                &sys,
                &scene.initial_state(),
                h,
                n,
                steps,
            )
            .unwrap();
            let e0 = p.curve[0].1;
            let worst = rec
                .energy
                .iter()
                .zip(&p.curve)
                .map(|(m, q)| (m.1 - q.1).abs() / e0)
                .fold(0.0, f64::max);
            eprintln!("{name} h {h} n {n}: energy off the predicted scheme by {worst:.1e} of E0");
            // The FEM solver's conjugate gradient stops at a relative residual of 1e-5.
            let bound = if name == "rapier_soft" { 1e-9 } else { 1e-4 };
            assert!(worst < bound, "{name} h {h} n {n}: {worst}");
        }
    }
}
