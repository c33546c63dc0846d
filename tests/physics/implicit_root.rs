//! Every implicit step is a root of its method's defining equation, to the solver's root
//! tolerance in the system's own units, or the step fails; and what follows from being a root
//! holds at any stiffness: free systems keep their linear momentum (internal forces sum to
//! zero), implicit midpoint keeps angular momentum (a quadratic invariant), backward Euler
//! meets its exact angular-momentum balance, and on a linear spring implicit Euler is the
//! backward-Euler step solved exactly.

use nalgebra::{Matrix2, Vector2};
use springlab::integrate::ImplicitSettings;
use springlab::method::MethodOptions;
use springlab::run::{run, NoObserver, RunPlan};
use springlab::scenario::Scenario;
use springlab::{method, perf, Error, Registry, State, System, Vec3};

/// The implicit methods, by the registry's fact (`MethodInfo::implicit`).
fn implicit_methods() -> Vec<&'static str> {
    Registry::builtin()
        .iter()
        .filter(|m| m.info.implicit)
        .map(|m| m.info.name)
        .collect()
}

/// The frame step of the scenes (30 Hz); stiffness is chosen for the hω wanted.
const H: f64 = 1.0 / 30.0;

/// The stiffnesses swept, as hω.
const H_OMEGA: [f64; 5] = [0.1, 1.0, 10.0, 100.0, 1000.0];

fn fresh(name: &str) -> springlab::method::Instance {
    method::create(name, &MethodOptions::default()).expect("known method")
}

/// `name` with at most `cap` Newton iterations a step (its `--max-newton` option).
fn capped(name: &str, cap: usize) -> springlab::method::Instance {
    use springlab::method::options::{OptionValue, MAX_NEWTON};
    let opts = MethodOptions::default().with(&MAX_NEWTON, OptionValue::Count(cap));
    method::create(name, &opts).expect("known method")
}

fn scene(toml: &str) -> Scenario {
    Scenario::from_toml_str(toml, "scene.toml").expect("valid scene")
}

/// Three free particles of 1, 2 and 3 kg at the corners of a triangle, on three springs each
/// 1 % longer than at rest, drifting and spinning about an axis off the triangle's normal.
/// The springs' stiffness is set so that the stiffest mode has hω ≈ `h_omega` at [`H`]
/// (ω² ≤ k (1/m_i + 1/m_j) summed over a particle's springs, ≤ 4k / 1 kg here).
fn spinning_triangle(h_omega: f64) -> Scenario {
    let k = (h_omega / H).powi(2) / 4.0;
    let x = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.1),
        Vec3::new(0.4, 0.9, 0.2),
    ];
    let m = [1.0, 2.0, 3.0];
    let com: Vec3 = (0..3).map(|i| x[i] * m[i]).sum::<Vec3>() / 6.0;
    let spin = Vec3::new(0.3, -0.4, 1.2);
    let drift = Vec3::new(0.1, 0.05, -0.02);
    let mut toml = String::new();
    for i in 0..3 {
        let v = drift + spin.cross(&(x[i] - com));
        toml += &format!(
            "[[particle]]\nposition=[{},{},{}]\nvelocity=[{},{},{}]\nmass={}\n",
            x[i].x, x[i].y, x[i].z, v.x, v.y, v.z, m[i]
        );
    }
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let rest = (x[j] - x[i]).norm() / 1.01;
        toml += &format!("[[spring]]\nbetween=[{i},{j}]\nstiffness={k}\nrest_length={rest}\n");
    }
    scene(&toml)
}

fn angular_momentum(sys: &System, x: &[Vec3], v: &[Vec3]) -> Vec3 {
    (0..x.len()).map(|p| x[p].cross(&v[p]) * sys.mass[p]).sum()
}

/// Σ m|v| + h Σ|f|: the magnitudes a step's momentum is summed from, so ε times it is the
/// step's round-off in momentum.
fn momentum_magnitude(sys: &System, s: &State, h: f64) -> f64 {
    let mut f = vec![Vec3::zeros(); s.len()];
    sys.forces(&s.x, &s.v, &mut f);
    (0..s.len())
        .map(|p| sys.mass[p] * s.v[p].norm() + h * f[p].norm())
        .sum()
}

/// The backward-Euler residual of a step from (x, v) to (x', v') by the model's own forces,
/// the mass-weighted RMS of v' − v − h f_p(x', v')/m_p over free particles, and the stage's
/// velocity scale (the largest component of v, v', h f/m or h g), as
/// [`ImplicitSettings::root_tol`] states them.
fn backward_euler_residual(
    sys: &System,
    x0: &[Vec3],
    v0: &[Vec3],
    s: &State,
    h: f64,
) -> (f64, f64) {
    let mut f = vec![Vec3::zeros(); s.len()];
    sys.forces(&s.x, &s.v, &mut f);
    let (mut sum, mut mass) = (0.0, 0.0);
    let mut scale = sys.gravity.map_or(0.0, |g| g.amax() * h);
    for p in 0..s.len() {
        if !sys.free[p] {
            continue;
        }
        assert!((s.x[p] - (x0[p] + s.v[p] * h)).amax() <= 1e-15 * (1.0 + x0[p].amax()));
        let kick = f[p] * (h * sys.inv_mass[p]);
        sum += sys.mass[p] * (s.v[p] - v0[p] - kick).norm_squared();
        mass += sys.mass[p];
        scale = scale.max(v0[p].amax()).max(s.v[p].amax()).max(kick.amax());
    }
    ((sum / mass).sqrt(), scale)
}

/// The list above is the registry's methods with an implicit solver.
#[test]
fn the_implicit_methods_are_the_registry_methods_with_a_newton_solver() {
    let mut found: Vec<&str> = Registry::builtin()
        .iter()
        .filter(|m| !m.info.engine && m.info.implicit)
        .map(|m| m.info.name)
        .collect();
    found.sort_unstable();
    let mut listed = implicit_methods();
    listed.sort_unstable();
    // The fact and the solver agree, and the four implicit methods carry both.
    assert_eq!(found, listed);
    assert_eq!(listed.len(), 4);
}

/// Oracle: Newton's third law. Springs act in equal and opposite pairs, so a free system's
/// forces sum to zero and every step that is a root of its stage keeps Σ m v exactly; what is
/// left is the round-off of summing momenta and impulses (ε × Σ m|v| + h Σ|f| per step).
#[test]
fn free_unequal_masses_keep_linear_momentum_at_any_stiffness() {
    let steps = 30;
    for h_omega in H_OMEGA {
        let sc = spinning_triangle(h_omega);
        let sys = sc.build();
        for name in implicit_methods() {
            let mut stepper = fresh(name);
            let mut s = sc.initial_state();
            let p0 = sys.momentum(&s.v);
            let mut allowed = 0.0;
            for k in 0..steps {
                allowed += 64.0 * f64::EPSILON * momentum_magnitude(&sys, &s, H);
                stepper
                    .step(&sys, &mut s, H)
                    .unwrap_or_else(|e| panic!("{name} at hω = {h_omega}, step {k}: {e}"));
                let drift = (sys.momentum(&s.v) - p0).amax();
                assert!(
                    drift <= allowed,
                    "{name} at hω = {h_omega}, step {k}: |ΔP| = {drift:.3e} > {allowed:.3e}"
                );
            }
        }
    }
}

/// Oracles: implicit midpoint keeps every quadratic invariant (Hairer, Lubich & Wanner,
/// Geometric Numerical Integration, §IV.2), angular momentum among them; backward Euler
/// changes it by exactly h Σ m v'×v (from x' = x + h v', M (v' − v) = h f(x') and
/// Σ x'×f(x') = 0 for central forces). A stage residual G changes L by Σ 2x_½×G (midpoint)
/// or Σ x'×G (backward Euler), at most 2 |x|_M |G|_M⁻¹ ≤ 2 × root_tol × V √(Σm|x|² Σm) per
/// step (Cauchy–Schwarz) for a root to the tolerance in the mass-weighted RMS norm (V: the
/// stage's velocity scale, bounded here by twice the largest speed seen).
#[test]
fn angular_momentum_follows_the_method_at_any_stiffness() {
    let root_tol = ImplicitSettings::default().root_tol;
    let steps = 30;
    for h_omega in H_OMEGA {
        let sc = spinning_triangle(h_omega);
        let sys = sc.build();
        for (name, balance) in [("implicit_midpoint", false), ("implicit_euler", true)] {
            let mut stepper = fresh(name);
            let mut s = sc.initial_state();
            let mut law_gap = 0.0f64;
            let mut allowed = 0.0;
            for _ in 0..steps {
                let (x0, v0) = (s.x.clone(), s.v.clone());
                stepper.step(&sys, &mut s, H).expect("step");
                let mut expected = angular_momentum(&sys, &x0, &v0);
                if balance {
                    expected += (0..3)
                        .map(|p| s.v[p].cross(&v0[p]) * (H * sys.mass[p]))
                        .sum::<Vec3>();
                }
                let speed = (0..3)
                    .map(|p| s.v[p].norm().max(v0[p].norm()))
                    .fold(0.0, f64::max);
                let reach = ((0..3)
                    .map(|p| sys.mass[p] * s.x[p].norm_squared().max(x0[p].norm_squared()))
                    .sum::<f64>()
                    * 6.0)
                    .sqrt();
                let l_scale = (0..3)
                    .map(|p| sys.mass[p] * s.x[p].norm() * s.v[p].norm())
                    .sum::<f64>();
                allowed += 2.0 * root_tol * 2.0 * speed * reach + 64.0 * f64::EPSILON * l_scale;
                law_gap = law_gap.max((angular_momentum(&sys, &s.x, &s.v) - expected).norm());
            }
            assert!(
                law_gap <= allowed,
                "{name} at hω = {h_omega}: angular momentum off its law by {law_gap:.3e} > {allowed:.3e}"
            );
        }
    }
}

/// Two free particles, 1 kg at x = 0 and 2 kg at x = 1.1, on one spring of rest length 1
/// along x, moving along x only: the spring force is linear in the positions (the spring
/// never turns or flips), with stiffness set for hω = `h_omega` (ω² = k/μ, μ = ⅔ kg).
fn linear_pair(h_omega: f64) -> (Scenario, f64) {
    let k = (h_omega / H).powi(2) * (2.0 / 3.0);
    let toml = format!(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nvelocity=[0.3,0.0,0.0]\nmass=1.0\n\
         [[particle]]\nposition=[1.1,0.0,0.0]\nvelocity=[0.0,0.0,0.0]\nmass=2.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness={k}\nrest_length=1.0\n"
    );
    (scene(&toml), k)
}

/// Oracle: the backward-Euler step of the linear pair solved exactly, (M + h²K) v' = M v +
/// h f(x) with K = k [[1, −1], [−1, 1]] on the x components (a dense 2×2 solve), and the exact
/// motion (centre of mass uniform, separation s − 1 = A cos ωt + B sin ωt with ω² = k/μ) to
/// measure both errors against. implicit_euler must make backward Euler's error, to 1e-9 of it
/// plus the round-off of the step itself (16ε of the velocity change h|f|/m and of v, times h,
/// summed over the steps: at hω = 1000 a force carries ε k|x| of rounding).
#[test]
fn implicit_euler_is_exact_backward_euler_on_a_linear_spring() {
    let steps = 30;
    let (m1, m2) = (1.0, 2.0);
    for h_omega in H_OMEGA {
        let (sc, k) = linear_pair(h_omega);
        let sys = sc.build();
        let mut stepper = fresh("implicit_euler");
        let mut s = sc.initial_state();
        let mass = Matrix2::new(m1, 0.0, 0.0, m2);
        let stiff = Matrix2::new(k, -k, -k, k);
        let lu = (mass + stiff * (H * H)).lu();
        let (mut x, mut v) = (Vector2::new(0.0, 1.1), Vector2::new(0.3, 0.0));
        let omega = (k * (m1 + m2) / (m1 * m2)).sqrt();
        let (com0, com_v) = ((m2 * 1.1) / 3.0, 0.3 * m1 / 3.0);
        let (a, b) = (0.1, -0.3 / omega); // s − 1 and its rate over ω at t = 0
        let mut roundoff = 0.0;
        for n in 1..=steps {
            let f = Vector2::new(k * (x[1] - x[0] - 1.0), -k * (x[1] - x[0] - 1.0));
            roundoff += 16.0 * f64::EPSILON * H * (v.amax() + H * f.amax() / m1);
            v = lu.solve(&(mass * v + f * H)).expect("SPD");
            x += v * H;
            stepper.step(&sys, &mut s, H).expect("step");
            let t = n as f64 * H;
            let sep = 1.0 + a * (omega * t).cos() + b * (omega * t).sin();
            let com = com0 + com_v * t;
            let exact = Vector2::new(com - sep * m2 / 3.0, com + sep * m1 / 3.0);
            let be_error = (x - exact).amax();
            let gap = (0..2).map(|p| (s.x[p].x - x[p]).abs()).fold(0.0, f64::max);
            assert!(
                gap <= 1e-9 * be_error + roundoff,
                "hω = {h_omega}, step {n}: implicit_euler is {gap:.3e} from exact backward Euler, \
                 whose error is {be_error:.3e}"
            );
            assert!(s.x.iter().chain(&s.v).all(|c| c.y == 0.0 && c.z == 0.0));
        }
    }
}

/// Oracle: the definition of backward Euler, M (v' − v) = h f(x + h v', v'), evaluated with the
/// model's forces apart from the solver. A stiff nonlinear stage whose Newton is capped at one
/// iteration is not a root and must fail as not converged; the same stage uncapped, and a soft
/// one (hω = 0.1) capped likewise, meet the equation to the root tolerance.
#[test]
fn a_capped_newton_is_reported_not_converged_and_its_twins_meet_the_root() {
    let root_tol = ImplicitSettings::default().root_tol;
    let stage = |h_omega: f64, max_newton: Option<usize>| {
        let sc = spinning_triangle(h_omega);
        let sys = sc.build();
        let mut stepper = match max_newton {
            Some(cap) => capped("implicit_euler", cap),
            None => fresh("implicit_euler"),
        };
        let mut s = sc.initial_state();
        let (x0, v0) = (s.x.clone(), s.v.clone());
        stepper
            .step(&sys, &mut s, H)
            .map(|_| backward_euler_residual(&sys, &x0, &v0, &s, H))
    };
    match stage(100.0, Some(1)) {
        Err(Error::Step(why)) => assert!(why.contains("did not converge"), "{why}"),
        other => panic!("a one-iteration Newton at hω = 100 should fail, got {other:?}"),
    }
    for (h_omega, cap) in [(100.0, None), (0.1, Some(1))] {
        let (worst, scale) = stage(h_omega, cap).expect("the stage converges");
        assert!(
            worst <= root_tol * scale,
            "hω = {h_omega}: residual {worst:.3e} above {root_tol:e} × {scale:.3e}"
        );
    }
}

/// The runner turns the failed stage into an unstable status that names the reason.
#[test]
fn the_runner_reports_a_stage_that_is_not_a_root() {
    let sc = spinning_triangle(100.0);
    let sys = sc.build();
    let mut stepper = capped("implicit_euler", 1);
    let out = run(
        &sys,
        &mut stepper,
        sc.initial_state(),
        &RunPlan::new(H, 5),
        &mut NoObserver,
    )
    .expect("run");
    assert!(!out.status.is_ok());
    assert!(
        format!("{:?}", out.status).contains("did not converge"),
        "{:?}",
        out.status
    );
    let mut stepper = fresh("implicit_euler");
    let out = run(
        &sys,
        &mut stepper,
        sc.initial_state(),
        &RunPlan::new(H, 5),
        &mut NoObserver,
    )
    .expect("run");
    assert!(out.status.is_ok(), "{:?}", out.status);
}

/// Oracle: the definition of backward Euler, as above, on the common case: a 32×32 cloth (two
/// corners pinned) falling from rest at 1/60 s, where the stage is stiff (hω ≫ 1) and the
/// solver's cheap stops end most stages.
#[test]
fn cloth_steps_meet_the_backward_euler_equation() {
    let root_tol = ImplicitSettings::default().root_tol;
    let h = 1.0 / 60.0;
    let sc = perf::cloth(32);
    let sys = sc.build();
    let mut stepper = fresh("implicit_euler");
    let mut s = sc.initial_state();
    for k in 0..10 {
        let (x0, v0) = (s.x.clone(), s.v.clone());
        stepper.step(&sys, &mut s, h).expect("step");
        let (worst, scale) = backward_euler_residual(&sys, &x0, &v0, &s, h);
        assert!(
            worst <= root_tol * scale,
            "step {k}: residual {worst:.3e} above {root_tol:e} × {scale:.3e}"
        );
    }
}
