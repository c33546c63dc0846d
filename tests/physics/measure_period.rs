//! Period and phase are measured on one dominant mode or left out.
//!
//! Oracle (closed form): the chain wall–k–m–k–m–k–wall along x (m = 1 kg, k = 100 N/m) has
//! the normal modes ω1 = √(k/m) = 10 rad/s (both particles in step) and ω2 = √(3k/m) (in
//! opposition). Released at rest from displacements (u1, u2), particle 1's velocity is
//! −(c1 ω1 sin ω1t + c2 ω2 sin ω2t) with c1 = (u1 + u2)/2, c2 = (u1 − u2)/2: one mode when
//! c2 = 0 or c1 = 0, a mix otherwise, where the first mode's velocity share is
//! ε = |c2 ω2 / (c1 ω1)| of the second's.

use springlab::measure::case::{run_case, CaseSettings};
use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::{Reference, DOMINANT_MODE_UNCLEAR};
use springlab::scenario::Scenario;

const K: f64 = 100.0;
const DT: f64 = 0.01;
const STEPS: u64 = 500;

fn chain(u1: f64, u2: f64) -> Scenario {
    let text = format!(
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
         [[particle]]\nposition = [{}, 0.0, 0.0]\nmass = 1.0\n\
         [[particle]]\nposition = [{}, 0.0, 0.0]\nmass = 1.0\n\
         [[particle]]\nposition = [3.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = {K}\nrest_length = 1.0\n\
         [[spring]]\nbetween = [1, 2]\nstiffness = {K}\nrest_length = 1.0\n\
         [[spring]]\nbetween = [2, 3]\nstiffness = {K}\nrest_length = 1.0\n",
        1.0 + u1,
        2.0 + u2
    );
    Scenario::from_toml_str(&text, "two_modes.toml").unwrap()
}

/// The reference over 5 s and the metrics of `name` at DT against it.
fn measure(scene: &Scenario, name: &str) -> (Reference, springlab::measure::case::CaseResult) {
    measure_for(scene, name, STEPS)
}

/// As [`measure`], over `steps` steps of DT.
fn measure_for(
    scene: &Scenario,
    name: &str,
    steps: u64,
) -> (Reference, springlab::measure::case::CaseResult) {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let grids = [TimeGrid::new(DT, steps, 1000)];
    let r = Reference::compute(&sys, &s0, &grids, DT * steps as f64).unwrap();
    let set = CaseSettings {
        repeat_short: false,
        ..CaseSettings::default()
    };
    let c = run_case(&sys, &s0, &r, 0, name, &set).unwrap();
    assert!(c.ok(), "{name}: {:?}", c.unstable_reason);
    (r, c)
}

#[test]
fn a_mix_of_two_modes_has_no_period_or_phase() {
    // ε = 0.98: the crossings fall 80 % off their mean spacing, and at dt = 0.01 s an accurate
    // run (rk4, within 0.03 mm) sees a near-tangent zero of the velocity differently from the
    // reference; counting crossings read a period error of −8 % and a phase of −3.4 rad.
    for name in ["rk4", "velocity_verlet"] {
        let (r, c) = measure(&chain(0.1, 0.0278), name);
        let m = c.metrics.as_ref().expect("an ok run has metrics");
        eprintln!(
            "mix {name}: error max {:.2e} m, {} reference crossings, period {:?}, phase {:?}",
            m.error_max,
            r.crossings.len(),
            m.period_error,
            m.phase_error
        );
        assert!(r.crossings.len() >= 3, "{:?}", r.crossings);
        assert_eq!(r.dominant_period(), Err(DOMINANT_MODE_UNCLEAR));
        assert!(m.error_max < 1e-2, "{name}: {}", m.error_max);
        assert_eq!(
            (m.period, m.period_reference, m.period_error, m.phase_error),
            (None, None, None, None),
            "{name}"
        );
    }
}

#[test]
fn a_single_mode_gets_its_closed_form_period() {
    // The twins: each mode alone, T = 2π/ω exactly; rk4 at ω dt ≤ 0.17 keeps the period to
    // its own phase error, O((ω dt)⁴) per radian, far below 1e-4.
    for (u2, omega) in [(0.1, (K).sqrt()), (-0.1, (3.0 * K).sqrt())] {
        let t = std::f64::consts::TAU / omega;
        let (r, c) = measure(&chain(0.1, u2), "rk4");
        let m = c.metrics.as_ref().expect("an ok run has metrics");
        eprintln!(
            "mode ω = {omega:.4}: reference T {:.10} (closed form {t:.10}), rk4 period error {:?}, phase {:?}",
            r.dominant_period().unwrap(),
            m.period_error,
            m.phase_error
        );
        assert!((r.dominant_period().unwrap() - t).abs() < 1e-8);
        assert!((m.period_reference.unwrap() - t).abs() < 1e-8);
        assert!(m.period_error.unwrap().abs() < 1e-4, "{m:?}");
        assert!(m.phase_error.unwrap().abs() < 1e-2, "{m:?}");
    }
}

#[test]
fn a_single_mode_over_two_periods_keeps_its_period() {
    // Over 1 s the first mode (T = 0.628 s) crosses upwards only twice: the downward
    // crossings half way between show the one interval is a period, not a mix.
    let t = std::f64::consts::TAU / K.sqrt();
    let (r, c) = measure_for(&chain(0.1, 0.1), "rk4", 100);
    assert_eq!(r.crossings.len(), 2, "{:?}", r.crossings);
    assert!((r.dominant_period().unwrap() - t).abs() < 1e-8);
    assert!(
        c.metrics.as_ref().unwrap().period_error.unwrap().abs() < 1e-4,
        "{:?}",
        c.metrics
    );
}

#[test]
fn a_weak_second_mode_leaves_the_first_dominant() {
    // Near the edge, on the measured side: ε = 0.09 moves each crossing by at most
    // arcsin(ε)/ω1, so the mean spacing over n crossings is the first mode's period to within
    // 2·arcsin(ε)/(ω1 (n − 1)); an accurate run matches the reference's.
    let (u1, u2) = (0.1, 0.09);
    let (w1, w2) = ((K).sqrt(), (3.0 * K).sqrt());
    let eps = ((u1 - u2) * w2 / ((u1 + u2) * w1)).abs();
    let (r, c) = measure(&chain(u1, u2), "rk4");
    let n = r.crossings.len() as f64;
    let t = r.dominant_period().expect("one dominant mode");
    let bound = 2.0 * eps.asin() / (w1 * (n - 1.0));
    eprintln!(
        "ε = {eps:.3}: reference T {t:.6} vs 2π/ω1 {:.6} (bound {bound:.2e}), rk4 period error {:?}",
        std::f64::consts::TAU / w1,
        c.metrics.as_ref().unwrap().period_error
    );
    assert!((t - std::f64::consts::TAU / w1).abs() <= bound);
    assert!(c.metrics.as_ref().unwrap().period_error.unwrap().abs() < 1e-4);
}
