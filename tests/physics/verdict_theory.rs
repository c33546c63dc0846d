//! Stable means bounded, and the runner's one verdict agrees with linear theory: every method
//! with a linear stability limit is run at 0.9 and 1.1 times that limit on five scenes and must
//! read stable and unstable.
//!
//! Oracles, computed here and nowhere in springlab:
//! - each scene's natural frequencies: the springs' stiffness matrix K (for a Hooke spring of
//!   direction n, length l and rest length l₀: k[n nᵀ + (1 − l₀/l)(I − n nᵀ)]) and damper
//!   matrix C (c n nᵀ), assembled over the free coordinates, then the eigenvalues of
//!   M^-½ K M^-½ (undamped) or of the first-order matrix [[0, I], [−M⁻¹K, −M⁻¹C]] (damped)
//!   by nalgebra's eigen solvers;
//! - each method's textbook limit on x'' = −ω²x: hω < 2 for symplectic Euler, velocity and
//!   position Verlet (Hairer, Lubich & Wanner, GNI §I.1), hω < 2√2 for classic RK4; on a damped
//!   scene the largest h with |R(hλ)| ≤ 1 for every eigenvalue λ, R the stability polynomial
//!   (1 + z for explicit Euler, 1 + z + z²/2 for RK2, the degree-4 Taylor polynomial for RK4;
//!   Hairer & Wanner, Solving ODEs II, §IV.2).
//!
//! Each run starts at rest from the scene's equilibrium with every free particle displaced by
//! a small pseudo-random amount, so every mode is excited and the linear theory holds.

use nalgebra::{DMatrix, Matrix3, Vector3};
type Complex64 = nalgebra::Complex<f64>;
use springlab::run::{run, NoObserver, RunPlan};
use springlab::scenario::Scenario;

/// Steps of every undamped run: long enough for any ρ ≥ 1.01 to reach the cap many times over
/// (the damped scene computes its own from the growth its theory predicts).
const STEPS: u64 = 4000;

/// The scene's K and C over the free coordinates (3 per free particle) and their masses.
fn matrices(scene: &Scenario) -> (DMatrix<f64>, DMatrix<f64>, Vec<f64>) {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let free: Vec<usize> = (0..sys.len()).filter(|&p| sys.free[p]).collect();
    let index = |p: usize| free.iter().position(|&q| q == p);
    let n = 3 * free.len();
    let (mut k, mut c) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    let sp = &sys.springs;
    for s in 0..sp.len() {
        let (i, j) = (sp.i[s] as usize, sp.j[s] as usize);
        let d: Vector3<f64> = s0.x[j] - s0.x[i];
        let l = d.norm();
        let u = d / l;
        let nn = u * u.transpose();
        let ks = (nn + (Matrix3::identity() - nn) * (1.0 - sp.l0[s] / l)) * sp.k[s];
        let cs = nn * sp.c[s];
        for (a, sa) in [(i, 1.0), (j, -1.0)] {
            for (b, sb) in [(i, 1.0), (j, -1.0)] {
                if let (Some(ia), Some(ib)) = (index(a), index(b)) {
                    let mut kb = k.view_mut((3 * ia, 3 * ib), (3, 3));
                    kb += ks * (sa * sb);
                    let mut cb = c.view_mut((3 * ia, 3 * ib), (3, 3));
                    cb += cs * (sa * sb);
                }
            }
        }
    }
    let mass = free.iter().flat_map(|&p| [sys.mass[p]; 3]).collect();
    (k, c, mass)
}

/// Highest natural frequency of an undamped scene (rad/s).
fn omega_max(scene: &Scenario) -> f64 {
    let (k, _, m) = matrices(scene);
    let n = m.len();
    let scaled = DMatrix::from_fn(n, n, |a, b| k[(a, b)] / (m[a] * m[b]).sqrt());
    scaled.symmetric_eigenvalues().max().sqrt()
}

/// Eigenvalues of the damped scene's first-order system.
fn damped_eigenvalues(scene: &Scenario) -> Vec<Complex64> {
    let (k, c, m) = matrices(scene);
    let n = m.len();
    let a = DMatrix::from_fn(2 * n, 2 * n, |r, col| match (r < n, col < n) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(col - n == r)),
        (false, true) => -k[(r - n, col)] / m[r - n],
        (false, false) => -c[(r - n, col - n)] / m[r - n],
    });
    let all: Vec<Complex64> = a
        .complex_eigenvalues()
        .iter()
        .map(|z| Complex64::new(z.re, z.im))
        .collect();
    // Rigid motions (translation, rotation, out-of-plane sway at rest length) have λ = 0,
    // where every R is 1; the solver returns them as round-off, which would fake a limit.
    let top = all.iter().map(|z| z.norm()).fold(0.0, f64::max);
    all.into_iter().filter(|z| z.norm() > 1e-6 * top).collect()
}

/// Largest h with |R(hλ)| ≤ 1 for every λ (scan, then bisection; each method's region meets
/// every ray from the origin in one interval).
fn polynomial_limit(lams: &[Complex64], r: fn(Complex64) -> Complex64) -> f64 {
    let ok = |h: f64| lams.iter().all(|&l| r(l * h).norm() <= 1.0 + 1e-12);
    let mut lo = 1e-9;
    while ok(lo * 1.01) {
        lo *= 1.01;
    }
    let mut hi = lo * 1.01;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if ok(mid) {
            lo = mid
        } else {
            hi = mid
        }
    }
    lo
}

fn euler(z: Complex64) -> Complex64 {
    1.0 + z
}
fn rk2(z: Complex64) -> Complex64 {
    1.0 + z + z * z / 2.0
}
fn rk4(z: Complex64) -> Complex64 {
    1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0
}

/// The scene with every free particle displaced by up to `amp` (m) pseudo-randomly.
fn shaken(scene: &Scenario, amp: f64) -> springlab::model::State {
    let sys = scene.build();
    let mut s = scene.initial_state();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for p in (0..sys.len()).filter(|&p| sys.free[p]) {
        s.x[p] += Vector3::new(next(), next(), next()) * (2.0 * amp);
    }
    s
}

/// Whether `method` reads stable over `steps` steps of `h` from the shaken scene.
fn stable(scene: &Scenario, amp: f64, method: &str, h: f64, steps: u64) -> bool {
    let sys = scene.build();
    let mut stepper = springlab::method::create(method, &Default::default()).unwrap();
    let out = run(
        &sys,
        &mut stepper,
        shaken(scene, amp),
        &RunPlan::new(h, steps),
        &mut NoObserver,
    )
    .unwrap();
    out.status.is_ok()
}

/// Checks 0.9 × and 1.1 × `limit` for `method` on `scene`, each over `steps` steps.
fn brackets(scene: &Scenario, amp: f64, method: &str, limit: f64, steps: u64) {
    assert!(
        stable(scene, amp, method, 0.9 * limit, steps),
        "{}: {method} at 0.9 × its limit {limit:.4e} s read unstable",
        scene.name
    );
    assert!(
        !stable(scene, amp, method, 1.1 * limit, steps),
        "{}: {method} at 1.1 × its limit {limit:.4e} s read stable",
        scene.name
    );
}

/// The undamped methods' limits on a scene of highest frequency ω: (method, h_max).
fn undamped_limits(w: f64) -> [(&'static str, f64); 4] {
    [
        ("symplectic_euler", 2.0 / w),
        ("velocity_verlet", 2.0 / w),
        ("position_verlet", 2.0 / w),
        ("rk4", 2.0 * 2f64.sqrt() / w),
    ]
}

fn scene(toml: &str, name: &str) -> Scenario {
    Scenario::from_toml_str(toml, format!("{name}.toml")).unwrap()
}

#[test]
fn a_spring_pair_of_unequal_masses() {
    let s = scene(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n\
         [[particle]]\nposition=[1.0,0.0,0.0]\nmass=3.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness=50.0\n",
        "pair",
    );
    let w = omega_max(&s);
    // Closed form for two bodies: ω² = k (1/m₁ + 1/m₂).
    assert!((w * w - 50.0 * (1.0 + 1.0 / 3.0)).abs() < 1e-9);
    for (m, h) in undamped_limits(w) {
        brackets(&s, 0.01, m, h, STEPS);
    }
}

#[test]
fn a_stiff_spring_holding_a_light_mass() {
    let s = scene(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[0.0,-0.2,0.0]\nmass=0.01\n\
         [[spring]]\nbetween=[0,1]\nstiffness=1e5\n",
        "stiff",
    );
    let w = omega_max(&s);
    assert!((w - (1e5f64 / 0.01).sqrt()).abs() < 1e-6 * w);
    for (m, h) in undamped_limits(w) {
        brackets(&s, 1e-4, m, h, STEPS);
    }
}

#[test]
fn a_damped_triangle_of_three_springs() {
    let s = scene(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n\
         [[particle]]\nposition=[1.0,0.0,0.0]\nmass=2.0\n\
         [[particle]]\nposition=[0.4,0.8,0.0]\nmass=1.5\n\
         [[spring]]\nbetween=[0,1]\nstiffness=100.0\ndamping=2.0\n\
         [[spring]]\nbetween=[1,2]\nstiffness=150.0\ndamping=1.0\n\
         [[spring]]\nbetween=[2,0]\nstiffness=80.0\ndamping=3.0\n",
        "triangle",
    );
    let lams = damped_eigenvalues(&s);
    for (m, r) in [
        ("explicit_euler", euler as fn(Complex64) -> Complex64),
        ("rk2", rk2),
        ("rk4", rk4),
    ] {
        let limit = polynomial_limit(&lams, r);
        // A run long enough to see growth: the fastest-growing mode at 1.1 × the limit gains
        // 1e8 in energy (the seed holds about 1e-4 of the scene's energy scale).
        let rho2 = lams
            .iter()
            .map(|&l| r(l * 1.1 * limit).norm_sqr())
            .fold(1.0, f64::max);
        let steps = ((1e8f64.ln() / rho2.ln()).ceil() as u64).clamp(STEPS, 2_000_000);
        brackets(&s, 0.01, m, limit, steps);
    }
}

#[test]
fn a_thirty_bead_rope_fixed_at_both_ends() {
    let s = scene(
        "[[chain]]\nstart=[0.0,0.0,0.0]\nend=[3.0,0.0,0.0]\ncount=30\nmass=0.05\n\
         stiffness=200.0\nfix=[\"first\",\"last\"]\n",
        "rope",
    );
    let w = omega_max(&s);
    // A fixed-fixed chain of 28 free beads: ω_max = 2√(k/m) sin(28π/(2·29)).
    let closed = 2.0 * (200.0f64 / 0.05).sqrt() * (28.0 * std::f64::consts::PI / 58.0).sin();
    assert!((w - closed).abs() < 1e-9 * w, "{w} against {closed}");
    for (m, h) in undamped_limits(w) {
        brackets(&s, 1e-3, m, h, STEPS);
    }
}

#[test]
fn a_cloth_pinned_at_two_corners() {
    let s = scene(
        "[[cloth]]\norigin=[0.0,0.0,0.0]\nsize=[1.0,1.0]\ncount=[6,6]\nmass=0.01\n\
         stiffness=100.0\nfix=[\"top_left\",\"top_right\"]\n",
        "cloth",
    );
    let w = omega_max(&s);
    for (m, h) in undamped_limits(w) {
        brackets(&s, 1e-3, m, h, STEPS);
    }
}
