//! Energy behaviour on the undamped oscillator u'' = −ω²u, oracles from linear stability
//! theory: explicit Euler's one-step matrix [[1, h],[−hω², 1]] multiplies ω²u² + v² by exactly
//! (1 + h²ω²) each step; symplectic methods keep the energy error bounded (O(h²) for Verlet,
//! O(h) for symplectic Euler) over 10⁴ periods; implicit Euler multiplies it by 1/(1 + h²ω²);
//! implicit midpoint keeps every quadratic invariant (Hairer, Lubich & Wanner, *GNI*, §IV.2),
//! so a linear spring's energy is kept at any step up to the solver's tolerance.

use crate::common;
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
    let mut i = stepper(name);
    let out = springlab::run::run(
        &sys,
        &mut i,
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

#[test]
fn implicit_midpoint_keeps_linear_spring_energy_at_any_step() {
    // A zero-rest-length spring is exactly linear (f = −k d) in 3-D, so its energy is a
    // quadratic invariant; the bob orbits its anchor on an ellipse. (The anchored spring with
    // rest length is linear only while it does not pass its anchor: at hω ≳ 10 Newton's first
    // iterate crosses it, where |d| folds the force law, and finds another root.) Bound: the
    // Newton tolerance (1e-10 of the velocity scale) per step, over n steps.
    let scene = springlab::scenario::Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[0.5,0.0,0.0]\nvelocity=[0.0,0.4,0.3]\nmass=1.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness=4.0\nrest_length=0.0\n",
        "linear.toml",
    )
    .unwrap();
    let sys = scene.build();
    let e0 = sys.state_energy(&scene.initial_state()).mechanical();
    let n = 1000u64;
    let tol = springlab::integrate::ImplicitSettings::default().newton_tol;
    for h in [0.1, 1.0, 10.0, 100.0] {
        let mut i = stepper("implicit_midpoint");
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
        springlab::run::run(
            &sys,
            &mut i,
            scene.initial_state(),
            &springlab::run::RunPlan::new(h, n),
            &mut Watch(&mut max_dev, e0),
        )
        .unwrap();
        eprintln!(
            "implicit_midpoint hω = {}: max |ΔE/E| = {max_dev:e}",
            2.0 * h
        );
        assert!(max_dev <= n as f64 * tol, "hω = {}: {max_dev}", 2.0 * h);
    }
}

#[test]
fn implicit_midpoint_keeps_a_linear_chain_energy_where_cg_iterates() {
    // Three unequal masses on zero-rest-length springs (exactly linear in 3-D) under gravity:
    // the energy is still quadratic, and CG now needs several iterations per Newton step.
    let scene = springlab::scenario::Scenario::from_toml_str(
        "[world]\ngravity=[0.0,-9.81,0.0]\n\
         [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[0.3,-0.2,0.1]\nvelocity=[0.0,0.0,1.0]\nmass=1.0\n\
         [[particle]]\nposition=[0.5,-0.6,0.0]\nmass=0.5\n\
         [[particle]]\nposition=[0.2,-0.9,-0.3]\nvelocity=[1.0,0.0,0.0]\nmass=2.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness=100.0\nrest_length=0.0\n\
         [[spring]]\nbetween=[1,2]\nstiffness=300.0\nrest_length=0.0\n\
         [[spring]]\nbetween=[2,3]\nstiffness=50.0\nrest_length=0.0\n\
         [[spring]]\nbetween=[1,3]\nstiffness=80.0\nrest_length=0.0\n",
        "chain.toml",
    )
    .unwrap();
    let sys = scene.build();
    let e0 = sys.state_energy(&scene.initial_state()).mechanical();
    let n = 500u64;
    let tol = springlab::integrate::ImplicitSettings::default().newton_tol;
    for h in [0.01, 0.1, 1.0] {
        let mut i = stepper("implicit_midpoint");
        let out = springlab::run::run(
            &sys,
            &mut i,
            scene.initial_state(),
            &springlab::run::RunPlan::new(h, n),
            &mut springlab::run::NoObserver,
        )
        .unwrap();
        let dev = (out.final_energy.total - e0).abs() / e0.abs();
        eprintln!("implicit_midpoint chain h = {h}: |ΔE/E| = {dev:e}");
        assert!(dev <= n as f64 * tol, "h = {h}: {dev}");
    }
}
