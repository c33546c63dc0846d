//! RATTLE on the rigid pendulum: a 1 kg bob on a 1 m rod (`[[constraint]]`), released at 90°
//! under g = 9.81 m/s² (a 9.81 J swing). Oracles: RATTLE is symplectic and second order
//! (Hairer, Lubich & Wanner, *GNI*, §VII.1 and §IX.8), so its energy error stays bounded and
//! shrinks as h²; the exact period is 4 √(L/g) K(sin 45°) = 1.180341 · 2π √(L/g) (complete
//! elliptic integral K, computed here by the arithmetic-geometric mean).

use springlab::model::State;
use springlab::run::{run, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

fn pendulum() -> Scenario {
    Scenario::from_toml_str(
        "[world]\ngravity=[0.0,-9.81,0.0]\n\
         [[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.0,0.0,0.0]\nmass=1.0\n\
         [[constraint]]\nbetween=[0,1]\nlength=1.0\n",
        "pendulum90.toml",
    )
    .unwrap()
}

/// Records the bob's x and the largest |E − E₀| (J).
struct Watch {
    e0: f64,
    max_dev: f64,
    xs: Vec<(f64, f64)>,
}

impl Observer for Watch {
    fn observe(&mut self, _: u64, s: &State, e: &EnergyRecord) -> springlab::Result<()> {
        self.max_dev = self.max_dev.max((e.total - self.e0).abs());
        self.xs.push((s.t, s.x[1].x));
        Ok(())
    }
}

fn swing(name: &str, dt: f64, seconds: f64) -> Watch {
    let scene = pendulum();
    let sys = scene.build();
    let s0 = scene.initial_state();
    let e0 = sys.state_energy(&s0).mechanical();
    let mut w = Watch {
        e0,
        max_dev: 0.0,
        xs: vec![(0.0, 1.0)],
    };
    let mut stepper = springlab::method::create(name, &Default::default()).unwrap();
    let plan = RunPlan::new(dt, (seconds / dt).round() as u64);
    let out = run(&sys, &mut stepper, s0, &plan, &mut w).unwrap();
    assert!(out.status.is_ok(), "{name} at {dt}");
    w
}

/// Mean period from the bob's passages through the bottom (x = 0), linearly interpolated.
fn period(xs: &[(f64, f64)]) -> f64 {
    let mut down = Vec::new();
    let mut up = Vec::new();
    for w in xs.windows(2) {
        let ((t0, x0), (t1, x1)) = (w[0], w[1]);
        if x0.signum() != x1.signum() && x1 != 0.0 {
            let t = t0 + (t1 - t0) * x0 / (x0 - x1);
            if x0 > 0.0 { &mut down } else { &mut up }.push(t);
        }
    }
    let spans: Vec<f64> = [down, up]
        .iter()
        .filter(|c| c.len() >= 2)
        .map(|c| (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64)
        .collect();
    assert!(!spans.is_empty(), "no full period");
    spans.iter().sum::<f64>() / spans.len() as f64
}

fn exact_period() -> f64 {
    // K(k) = π / (2 AGM(1, √(1 − k²))), k = sin 45°.
    let (mut a, mut b) = (1.0f64, (0.5f64).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    let k = std::f64::consts::PI / (2.0 * a);
    4.0 * (1.0f64 / 9.81).sqrt() * k
}

#[test]
fn rattle_energy_error_is_bounded_and_second_order() {
    let dts = [1e-3, 5e-4, 2.5e-4];
    let devs: Vec<f64> = dts
        .iter()
        .map(|&dt| swing("rattle", dt, 6.0).max_dev)
        .collect();
    let slope = (devs[0] / devs[2]).ln() / (dts[0] / dts[2]).ln();
    let vc = swing("verlet_constraints", 1e-3, 6.0);
    eprintln!(
        "rattle max |ΔE| over 6 s: {devs:?} J at dt = {dts:?} (order {slope:.3}); verlet_constraints at 1e-3: {:.3} J",
        vc.max_dev
    );
    assert!((slope - 2.0).abs() <= 0.15, "energy error order {slope}");
    // Bounded: ten times longer, no larger error (a symplectic method's error oscillates).
    let long = swing("rattle", 1e-3, 60.0).max_dev;
    eprintln!("rattle max |ΔE| over 60 s at 1e-3: {long:e} J");
    assert!(long <= 1.05 * devs[0], "60 s: {long}, 6 s: {}", devs[0]);
}

#[test]
fn rattle_swings_with_the_elliptic_period() {
    let exact = exact_period();
    assert!(
        (exact / (2.0 * std::f64::consts::PI * (1.0f64 / 9.81).sqrt()) - 1.180341).abs() < 1e-6
    );
    let t = period(&swing("rattle", 1e-3, 6.0).xs);
    let vc = period(&swing("verlet_constraints", 1e-3, 6.0).xs);
    eprintln!(
        "period: exact {exact:.7} s, rattle {t:.7} s ({:+.2e}), verlet_constraints {vc:.7} s ({:+.2e})",
        t / exact - 1.0,
        vc / exact - 1.0
    );
    // Second order: (hω)² ≈ 1e-5 at h = 1e-3, ω = √(g/L).
    assert!(
        (t / exact - 1.0).abs() < 1e-5,
        "rattle period {t}, exact {exact}"
    );
}

#[test]
fn rattle_refuses_compliant_constraints_and_says_why() {
    let scene = Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.0,0.0,0.0]\nmass=1.0\n\
         [[constraint]]\nbetween=[0,1]\nlength=1.0\ncompliance=1e-3\n",
        "soft.toml",
    )
    .unwrap();
    let stepper = springlab::method::create("rattle", &Default::default()).unwrap();
    let why = stepper.check(&scene.build()).unwrap_err();
    assert!(why.contains("compliant") && why.contains("spring"), "{why}");
    assert!(stepper.check(&pendulum().build()).is_ok());
}
