//! Energy behaviour on the undamped oscillator u'' = −ω²u, oracles from linear stability
//! theory: explicit Euler's one-step matrix [[1, h],[−hω², 1]] multiplies ω²u² + v² by exactly
//! (1 + h²ω²) each step; symplectic methods keep the energy error bounded (O(h²) for Verlet,
//! O(h) for symplectic Euler) over 10⁴ periods; implicit Euler multiplies it by 1/(1 + h²ω²).

mod common;
use common::*;

const K: f64 = 4.0; // ω = 2, period π

fn energy_ratio(name: &str, h: f64, steps: u64) -> (f64, f64) {
    let scene = oscillator(K, 0.0, 0.5, 0.0);
    let mut max_dev: f64 = 0.0;
    struct Watch<'a>(&'a mut f64, f64);
    impl springlab::run::Observer for Watch<'_> {
        fn observe(
            &mut self,
            _: u64,
            _: &springlab::model::State,
            e: &springlab::run::EnergyRecord,
        ) -> springlab::Result<()> {
            *self.0 = self.0.max((e.total / self.1 - 1.0).abs());
            Ok(())
        }
    }
    let sys = scene.build();
    let e0 = sys.state_energy(&scene.initial_state()).mechanical();
    let mut plan = springlab::run::RunPlan::new(h, steps);
    plan.blowup_factor = 1e300;
    let mut i = integ(name);
    let out = springlab::run::run(
        &sys,
        i.as_mut(),
        scene.initial_state(),
        &plan,
        &mut Watch(&mut max_dev, e0),
    )
    .unwrap();
    (out.final_energy.total / e0, max_dev)
}

#[test]
fn explicit_euler_energy_grows_exactly_as_theory() {
    let (h, n) = (0.01, 1000u64);
    let (ratio, _) = energy_ratio("explicit_euler", h, n);
    let theory = (1.0 + h * h * K).powi(n as i32);
    assert!(
        (ratio / theory - 1.0).abs() < 1e-10,
        "ratio {ratio}, theory {theory}"
    );
}

#[test]
fn implicit_euler_energy_decays_exactly_as_theory() {
    let (h, n) = (0.01, 1000u64);
    let (ratio, _) = energy_ratio("implicit_euler", h, n);
    let theory = (1.0 + h * h * K).powi(-(n as i32));
    assert!(
        (ratio / theory - 1.0).abs() < 1e-8,
        "ratio {ratio}, theory {theory}"
    );
}

#[test]
fn symplectic_methods_keep_energy_bounded_over_ten_thousand_periods() {
    // 10⁴ periods of π s at h = 0.05 (hω = 0.1): 628 319 steps.
    let h = 0.05;
    let steps = (1e4 * std::f64::consts::PI / h).round() as u64;
    let hw2 = h * h * K;
    // Exact invariants of the linear maps: Verlet conserves v² + ω²u²(1 − h²ω²/4), so starting
    // from rest |ΔE/E| oscillates in [0, (hω)²/4]; symplectic Euler conserves
    // v² + ω²u² − hω²uv, so |ΔE/E| ≤ (hω/2)/(1 − hω/2) (extremes of uv at fixed invariant).
    let hw = hw2.sqrt();
    let se_bound = (hw / 2.0) / (1.0 - hw / 2.0);
    for (name, bound) in [
        ("symplectic_euler", se_bound),
        ("velocity_verlet", hw2 / 4.0 * (1.0 + 1e-6)),
        ("position_verlet", hw2 / 4.0 * (1.0 + 1e-6)),
    ] {
        let (ratio, max_dev) = energy_ratio(name, h, steps);
        assert!(max_dev < bound, "{name}: max |ΔE/E| = {max_dev}");
        assert!((ratio - 1.0).abs() < bound, "{name}: final ratio {ratio}");
    }
}

#[test]
fn rk4_drifts_slowly_but_is_not_bounded_by_symplecticity() {
    // RK4's stability function on iω: |R(ihω)|² = 1 − (hω)⁶/72 + (hω)⁸/576, so energy decays
    // by exactly that factor per step.
    let (h, n) = (0.1, 2000u64);
    let (ratio, _) = energy_ratio("rk4", h, n);
    let z2: f64 = h * h * K;
    let per_step = 1.0 - z2.powi(3) / 72.0 + z2.powi(4) / 576.0;
    let theory = per_step.powi(n as i32);
    assert!(
        (ratio / theory - 1.0).abs() < 1e-9,
        "ratio {ratio}, theory {theory}"
    );
}
