//! A backward-Euler stage past a cloth's fold (a crumpled cloth at a game frame: compressed
//! springs make the exact Newton matrix indefinite) converges to a root of the stage's
//! equations through Levenberg–Marquardt-shifted Newton steps, and its twin before the fold (the
//! same cloth stretched, every spring in tension) converges with no shift, in Newton's
//! quadratic few. Oracle: the definition of backward Euler, M (v' − v) = h f(x + h v', v'),
//! evaluated here with the model's own forces, independently of the solver's residual.

use springlab::integrate::Stepper;
use springlab::model::System;
use springlab::{perf, Vec3};

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

/// The 8×8 benchmark cloth's rest state scaled by `squeeze` in the plane, rumpled by
/// ±`rumple` m and thrown at up to `throw` m/s per component.
fn thrown_cloth(squeeze: f64, rumple: f64, throw: f64) -> (System, springlab::model::State) {
    thrown(perf::cloth(8), squeeze, rumple, throw)
}

/// `scene`'s rest state scaled, rumpled and thrown as [`thrown_cloth`] does.
fn thrown(
    scene: springlab::scenario::Scenario,
    squeeze: f64,
    rumple: f64,
    throw: f64,
) -> (System, springlab::model::State) {
    let sys = scene.build();
    let mut s = scene.initial_state();
    let mut rnd = Lcg(6364136223846793005u64.wrapping_add(1442695040888963407));
    for p in 0..s.len() {
        s.x[p][0] *= squeeze;
        s.x[p][2] *= squeeze;
        if !sys.free[p] {
            continue;
        }
        s.x[p][1] += rumple * rnd.next();
        for k in 0..3 {
            s.v[p][k] = 2.0 * throw * rnd.next();
        }
    }
    (sys, s)
}

/// One implicit-Euler stage of the 8×8 benchmark cloth at 1/60 s from [`thrown_cloth`];
/// returns (Newton iterations, shifted iterations, max |v' − v − h M⁻¹f| / its scale).
fn stage(squeeze: f64, rumple: f64, throw: f64) -> (u64, u64, f64) {
    let h = 1.0 / 60.0;
    let (sys, mut s) = thrown_cloth(squeeze, rumple, throw);
    let (x0, v0) = (s.x.clone(), s.v.clone());
    let mut stepper = springlab::integrate::ImplicitEuler::default();
    {
        // Only the tight stop: the truncation-error stop would end the stage early.
        let set = &mut stepper.newton_mut().settings;
        set.kappa = 0.0;
        // A cloth squeezed to half its size starts far from the stage's root: the cap is
        // raised so that the test measures convergence, not the default budget.
        set.max_newton = 200;
    }
    stepper.step(&sys, &mut s, h).expect("the stage converges");
    let nw = stepper.newton();
    let rel = backward_euler_defect(&sys, &x0, &v0, &s.x, &s.v, h);
    println!(
        "squeeze {squeeze}: Newton {} iterations, {} shifted; max |v' − v − h M⁻¹f| / scale = {rel:.3e}",
        nw.newton_iterations, nw.shifted_iterations
    );
    (nw.newton_iterations, nw.shifted_iterations, rel)
}

/// max |v' − v − h M⁻¹ f(x', v')| over the free particles, relative to the stage's velocity
/// scale (the largest |v|, |v'|, h|f|/m component); also checks x' = x + h v'.
fn backward_euler_defect(
    sys: &System,
    x0: &[Vec3],
    v0: &[Vec3],
    x: &[Vec3],
    v: &[Vec3],
    h: f64,
) -> f64 {
    let mut f = vec![Vec3::zeros(); x.len()];
    sys.forces(x, v, &mut f);
    let (mut scale, mut worst) = (0.0f64, 0.0f64);
    for p in 0..x.len() {
        if !sys.free[p] {
            continue;
        }
        assert!((x[p] - (x0[p] + v[p] * h)).amax() <= 1e-15 * (1.0 + x0[p].amax()));
        let g = (v[p] - v0[p]) - f[p] * (h * sys.inv_mass[p]);
        worst = worst.max(g.amax());
        scale = scale.max(v[p].amax()).max(v0[p].amax());
        scale = scale.max((f[p] * (h * sys.inv_mass[p])).amax());
    }
    worst / scale
}

/// Past the fold: squeezed to half its size, rumpled by ±5 cm and thrown, many springs
/// compressed.
#[test]
fn crumpled_cloth_stage_converges_through_shifted_steps() {
    let (_, shifted, rel) = stage(0.5, 0.1, 1.0);
    assert!(shifted >= 1, "the crumpled stage should need a shift");
    assert!(rel <= 1e-9, "residual {rel:e} of the scale");
}

/// The twin before the fold: stretched by 2 % and at rest, every spring in tension, so the
/// exact matrix is positive definite: no shift, and Newton's quadratic convergence reaches the tight
/// tolerance in a few iterations.
#[test]
fn twin_stretched_cloth_stage_converges_unshifted_in_few_iterations() {
    let (newton, shifted, rel) = stage(1.02, 0.0, 0.0);
    assert_eq!(shifted, 0, "a stretched cloth needs no shift");
    assert!(newton <= 8, "{newton} Newton iterations");
    assert!(rel <= 1e-9, "residual {rel:e} of the scale");
}

/// A stage stopped by its iteration cap says how far from its root it stopped, and where.
/// Oracle: the definition of backward Euler. With a cap of 0 the iterate is the start
/// v' = v, whose residual is M⁻¹G = −h M⁻¹ f(x + h v, v): its mass-weighted RMS, the stage's
/// velocity scale (the largest |v| or h|f|/m component, or h|g|), their ratio and the particle
/// with the largest component are computed here from the model's forces and must be the ones
/// the error names, followed by the Newton matrix's lowest eigenvalue there.
#[test]
fn a_stage_out_of_iterations_names_its_residual() {
    use springlab::error::significant;
    let h = 1.0 / 60.0;
    let (sys, mut s) = thrown_cloth(0.5, 0.1, 1.0);
    let (x0, v0) = (s.x.clone(), s.v.clone());
    let n = sys.len();
    let xs: Vec<Vec3> = (0..n).map(|p| x0[p] + v0[p] * h).collect();
    let mut f = vec![Vec3::zeros(); n];
    sys.forces(&xs, &v0, &mut f);
    let kick = sys.gravity.map_or(0.0, |g| g.amax() * h);
    let (mut sum, mut mass, mut scale, mut worst) = (0.0, 0.0, kick, (0.0f64, 0usize));
    for p in (0..n).filter(|&p| sys.free[p]) {
        let r = f[p] * (h * sys.inv_mass[p]);
        sum += sys.mass[p] * r.norm_squared();
        mass += sys.mass[p];
        scale = scale.max(r.amax()).max(v0[p].amax());
        if r.amax() > worst.0 {
            worst = (r.amax(), p);
        }
    }
    let rms = (sum / mass).sqrt();
    let mut stepper = springlab::integrate::ImplicitEuler::default();
    stepper.newton_mut().settings.max_newton = 0;
    let err = stepper.step(&sys, &mut s, h).unwrap_err().to_string();
    let want = format!(
        "stopped at an RMS of {} m/s, {} of the stage's velocity scale of {} m/s (a root is \
         within 1e-6 of it), largest {} m/s at particle {}",
        significant(rms, 4),
        significant(rms / scale, 4),
        significant(scale, 4),
        significant(worst.0, 4),
        worst.1
    );
    assert!(err.contains(&want), "{err}\nwanted: {want}");
    assert!(rms / scale > 1e-6, "the start must be off the root");
    // And the matrix there (its estimate is checked against dense eigenvalues in the library).
    assert!(
        err.contains("; there the Newton matrix's lowest eigenvalue is at most "),
        "{err}"
    );
    // Its root path, capped alike, finds no root either.
    assert!(
        err.ends_with(
            "; followed from its base state in 16 pieces of its step, none of its roots were found"
        ),
        "{err}"
    );
}

/// Twin: the same stage with room to iterate (the cap [`stage`] gives it) reaches its root,
/// and the step succeeds.
#[test]
fn twin_the_same_stage_with_room_to_iterate_converges() {
    let (sys, mut s) = thrown_cloth(0.5, 0.1, 1.0);
    let mut stepper = springlab::integrate::ImplicitEuler::default();
    stepper.newton_mut().settings.max_newton = 200;
    stepper
        .step(&sys, &mut s, 1.0 / 60.0)
        .expect("the stage converges");
}

/// [`capped`] from the 8×8 cloth with air drag at rest length, rumpled by ±5 cm and thrown at
/// up to 3 m/s.
fn capped_stage(cap: usize) -> (bool, u64, u64, f64) {
    // With air drag, whose dissipation a patch does not sum, no patch is eliminated: the
    // path is the stage's only recourse.
    let scene = springlab::scenario::Scenario::from_toml_str(
        "[world]\ngravity = [0.0, -9.81, 0.0]\ndrag = 1e-4\n[[cloth]]\norigin = [0.0, 0.0, 0.0]\n\
         size = [1.0, 1.0]\ncount = [8, 8]\nmass = 0.001\nstiffness = 200.0\ndamping = 0.002\n\
         plane = \"xz\"\nfix = [\"top_left\", \"top_right\"]\n",
        "dragged_cloth.toml",
    )
    .expect("a valid scene");
    let (sys, s) = thrown(scene, 1.0, 0.1, 3.0);
    capped(&sys, s, cap)
}

/// One implicit-Euler stage of `sys` from `s` at 1/60 s with a cap of `cap` Newton
/// iterations at the tight stop alone: (whether the step succeeded, Newton iterations spent
/// in all, patch iterations, max |v' − v − h M⁻¹f| / its scale).
fn capped(sys: &System, mut s: springlab::model::State, cap: usize) -> (bool, u64, u64, f64) {
    let h = 1.0 / 60.0;
    let (x0, v0) = (s.x.clone(), s.v.clone());
    let mut stepper = springlab::integrate::ImplicitEuler::default();
    stepper.newton_mut().settings.kappa = 0.0;
    stepper.newton_mut().settings.max_newton = cap;
    let ok = stepper.step(sys, &mut s, h).is_ok();
    let rel = backward_euler_defect(sys, &x0, &v0, &s.x, &s.v, h);
    let nw = stepper.newton();
    println!(
        "cap {cap}: ok {ok}, {} Newton and {} patch iterations, defect {rel:.3e}",
        nw.newton_iterations, nw.patch_iterations
    );
    (ok, nw.newton_iterations, nw.patch_iterations, rel)
}

/// A stage that its iteration cap stops is solved along its root path (the stages of steps
/// h·k/16 from the same base, each from the last roots). Oracle: the definition of backward
/// Euler, the step's defect measured here from the model's forces. The direct iteration needs
/// 12 iterations ([`twin_the_same_stage_with_a_cap_it_fits_is_solved_directly`]), so a cap
/// of 8 stops it, and the iterations spent beyond 8 are the path's.
#[test]
fn a_stage_past_its_cap_is_solved_along_its_root_path() {
    let (ok, spent, patch, rel) = capped_stage(8);
    assert!(
        ok && patch == 0,
        "the path should solve the stage: {ok} {patch}"
    );
    assert!(
        spent > 8,
        "the direct iteration should have run out first: {spent}"
    );
    assert!(rel <= 1e-9, "residual {rel:e} of the scale");
}

/// Twin: with a cap of 12 the direct iteration reaches the root itself, within its cap.
#[test]
fn twin_the_same_stage_with_a_cap_it_fits_is_solved_directly() {
    let (ok, spent, _, rel) = capped_stage(12);
    assert!(ok && spent <= 12, "{ok} {spent}");
    assert!(rel <= 1e-9, "residual {rel:e} of the scale");
}

/// The 16×16 benchmark cloth at rest with the 2×2 block at its centre spun about the vertical
/// at `spin` m/s (tangential), its neighbours at rest.
fn spun_knot(spin: f64) -> (System, springlab::model::State) {
    let scene = perf::cloth(16);
    let sys = scene.build();
    let mut s = scene.initial_state();
    let centre = (s.x[7 * 16 + 7] + s.x[8 * 16 + 8]) * 0.5;
    for p in [7 * 16 + 7, 7 * 16 + 8, 8 * 16 + 7, 8 * 16 + 8] {
        let r = s.x[p] - centre;
        let t = Vec3::new(-r[2], 0.0, r[0]).normalize();
        s.v[p] = t * spin;
    }
    (sys, s)
}

/// One implicit-Euler stage of [`spun_knot`] at 1/60 s with a cap of `cap` Newton iterations
/// at the tight stop alone: (whether it succeeded, Newton iterations, patch iterations,
/// max |v' − v − h M⁻¹f| / its scale).
fn knot_stage(spin: f64, cap: usize) -> (bool, u64, u64, f64) {
    let (sys, s) = spun_knot(spin);
    capped(&sys, s, cap)
}

/// A knot spun at 6 m/s (its springs turn through about a radian within the step) stops the
/// direct iteration at a cap of 10; the stage is solved by eliminating the patch that holds
/// its residual, minimised alone by trust-region Newton steps, and the iteration resumed.
/// Oracle: the definition of backward Euler, the step's defect measured here.
#[test]
fn a_spun_knot_past_its_cap_is_solved_by_eliminating_its_patch() {
    let (ok, _, patch, rel) = knot_stage(6.0, 10);
    assert!(ok && patch > 0, "{ok} {patch}");
    assert!(rel <= 1e-9, "residual {rel:e} of the scale");
}

/// Twin: with a cap it fits (the direct iteration needs 24) the same stage is solved with no
/// patch eliminated.
#[test]
fn twin_the_same_knot_with_room_to_iterate_needs_no_elimination() {
    let (ok, newton, patch, rel) = knot_stage(6.0, 50);
    assert!(ok && patch == 0 && newton <= 50, "{ok} {newton} {patch}");
    assert!(rel <= 1e-9, "residual {rel:e} of the scale");
}

/// A stage whose knot needs more eliminations than the first eight goes on eliminating while
/// they gain: at a cap of 1 each elimination takes one trust-region iteration and the resumed
/// iteration one Newton iteration, and the spun knot reaches its root at the ninth. Oracle: the
/// definition of backward Euler, the step's defect measured here (the root tolerance, 10⁻⁶ of
/// the scale, met in max norm).
#[test]
fn a_knot_that_needs_a_ninth_elimination_reaches_its_root() {
    let (ok, _, patch, rel) = knot_stage(6.0, 1);
    assert!(ok && patch > 8, "{ok} {patch}");
    assert!(rel <= 1e-6, "residual {rel:e} of the scale");
}

/// A stage that stays off its root after its patch eliminations says so, with how many were
/// made. The knot spun at 60 m/s travels a metre within the step, the cloth's own size; at a
/// cap of 2 its third elimination gains nothing, which ends them. Oracle: the rule stated in
/// the error's own terms, and its count: each elimination takes at least one and at most the
/// cap's two trust-region iterations, so the two made and the third tried took 2 to 6.
#[test]
fn a_knot_left_off_its_root_after_its_eliminations_says_so() {
    let (sys, mut s) = spun_knot(60.0);
    let mut stepper = springlab::integrate::ImplicitEuler::default();
    stepper.newton_mut().settings.kappa = 0.0;
    stepper.newton_mut().settings.max_newton = 2;
    let err = stepper
        .step(&sys, &mut s, 1.0 / 60.0)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(
            "Newton did not converge in 2 iterations, nor after eliminating its stalled patch 2 \
             times: its residual"
        ),
        "{err}"
    );
    let patch = stepper.newton().patch_iterations;
    assert!((2..=6).contains(&patch), "{patch} patch iterations");
}

/// Twin of both: at a cap of 2 the knot spun at 6 m/s reaches its root within eight
/// eliminations, at most 8 × 2 = 16 trust-region iterations, and the step succeeds there
/// (accepted at its cap within the root tolerance, 10⁻⁶ of the scale, met here in max norm).
#[test]
fn twin_the_same_knot_with_two_iterations_per_solve_reaches_its_root() {
    let (ok, _, patch, rel) = knot_stage(6.0, 2);
    assert!(ok && patch > 0 && patch <= 16, "{ok} {patch}");
    assert!(rel <= 1e-6, "residual {rel:e} of the scale");
}
