//! A backward-Euler stage on which clamped Newton stalls (a crumpled cloth at a game frame)
//! still converges to a root of the stage's equations, by switching to trust-region steps and
//! back. Oracle: the definition of backward Euler, M (v' − v) = h f(x + h v', v'), evaluated
//! here with the model's own forces, independently of the solver's residual.

use springlab::method::MethodOptions;
use springlab::{method, perf, Vec3};

/// A fixed linear congruential generator (Knuth's MMIX constants): uniform in [−½, ½).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }
}

#[test]
fn crumpled_cloth_stage_converges_through_both_strategies() {
    let h = 1.0 / 60.0;
    let scene = perf::cloth(8);
    let sys = scene.build();
    let mut s = scene.initial_state();
    // Squeezed to half its size in the plane, rumpled by ±5 cm and thrown at up to 1 m/s
    // per component: many springs compressed, so the exact Newton matrix is indefinite.
    let mut rnd = Lcg(6364136223846793005u64.wrapping_add(1442695040888963407));
    for p in 0..s.len() {
        if !sys.free[p] {
            continue;
        }
        s.x[p][0] *= 0.5;
        s.x[p][2] *= 0.5;
        s.x[p][1] += 0.1 * rnd.next();
        for k in 0..3 {
            s.v[p][k] = 2.0 * rnd.next();
        }
    }
    let (x0, v0) = (s.x.clone(), s.v.clone());
    let mut stepper = method::create("implicit_euler", &MethodOptions::default()).unwrap();
    {
        // Only the tight stop: the truncation-error stop would end the stage early.
        let set = &mut stepper.newton_mut().unwrap().settings;
        set.kappa = 0.0;
        set.max_newton = 200;
    }
    stepper.step(&sys, &mut s, h).expect("the stage converges");
    let nw = stepper.newton().unwrap();
    assert!(
        nw.strategy_switches >= 2,
        "the stage should stall in both strategies (switches: {})",
        nw.strategy_switches
    );
    let mut f = vec![Vec3::zeros(); s.len()];
    sys.forces(&s.x, &s.v, &mut f);
    let mut scale = 0.0f64;
    let mut worst = 0.0f64;
    for p in 0..s.len() {
        if !sys.free[p] {
            continue;
        }
        assert!((s.x[p] - (x0[p] + s.v[p] * h)).amax() <= 1e-15 * (1.0 + x0[p].amax()));
        let g = (s.v[p] - v0[p]) - f[p] * (h * sys.inv_mass[p]);
        worst = worst.max(g.amax());
        scale = scale.max(s.v[p].amax()).max(v0[p].amax());
        scale = scale.max((f[p] * (h * sys.inv_mass[p])).amax());
    }
    println!(
        "Newton {} iterations, {} switches; max |v' − v − h M⁻¹f| = {worst:.3e} (scale {scale:.3})",
        nw.newton_iterations, nw.strategy_switches
    );
    assert!(worst <= 1e-9 * scale, "residual {worst:e} at scale {scale}");
}
