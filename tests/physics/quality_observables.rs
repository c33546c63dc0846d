//! The quality observables of every run (`strain_max`, `penetration_max`, `energy_drift_rate`,
//! `rest_jitter`) against oracles worked out here, each stated at its test: strains recomputed
//! from a recorded trajectory, closed-form energy growth of the Euler methods under a constant
//! force, the exact oscillator's kinetic energy, and penetrations read off recorded heights.

use crate::common::oscillator;
use springlab::measure::case::{run_case, CaseResult, CaseSettings};
use springlab::measure::compare::{compare, write_compare, CompareConfig};
use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::Reference;
use springlab::measure::{Metrics, QualityObserver};
use springlab::model::{State, Vec3};
use springlab::run::{self, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

/// The metrics of `name` on `scene` over `steps` steps of `dt` (compared every step), with
/// contact metrics on; the run must be ok.
fn measure(scene: &Scenario, name: &str, dt: f64, steps: u64) -> (CaseResult, Metrics) {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let grid = TimeGrid::new(dt, steps, steps + 1);
    let r = Reference::compute(&sys, &s0, &[grid], grid.time(steps)).unwrap();
    let set = CaseSettings {
        repeat_short: false,
        contacts: true,
        ..CaseSettings::default()
    };
    let c = run_case(&sys, &s0, &r, 0, name, &set).unwrap();
    assert!(c.ok(), "{name}: {:?}", c.unstable_reason);
    let m = c.metrics.clone().expect("an ok run has metrics");
    (c, m)
}

/// Every observed state's positions.
#[derive(Default)]
struct Positions(Vec<Vec<Vec3>>);

impl Observer for Positions {
    fn observe(&mut self, _step: u64, s: &State, _e: &EnergyRecord) -> springlab::Result<()> {
        self.0.push(s.x.clone());
        Ok(())
    }
}

/// The positions of every observed state of `name` on `scene` over `steps` steps of `dt`:
/// the same plan as [`measure`]'s run, so the same states bit for bit.
fn record(scene: &Scenario, name: &str, dt: f64, steps: u64) -> Vec<Vec<Vec3>> {
    let sys = scene.build();
    let mut stepper = springlab::method::create(name, &Default::default()).unwrap();
    let mut rec = Positions::default();
    let plan = RunPlan::new(dt, steps);
    let out = run::run(&sys, &mut stepper, scene.initial_state(), &plan, &mut rec).unwrap();
    assert!(out.status.is_ok());
    assert_eq!(rec.0.len() as u64, steps + 1);
    rec.0
}

/// A chain of three springs from a fixed anchor (the middle one with rest length 0.09 m at a
/// spacing of 0.1 m, so stretched 11 % at the start), a rigid 0.2 m rod hanging a 1 kg bob
/// from its end, and a zero-rest-length spring across the chain, under gravity.
const CHAIN_WITH_ROD: &str = "\
[world]
gravity = [0.0, -9.81, 0.0]
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true
[[particle]]
position = [0.1, 0.0, 0.0]
mass = 0.2
[[particle]]
position = [0.2, 0.0, 0.0]
mass = 0.2
[[particle]]
position = [0.3, 0.0, 0.0]
mass = 0.2
[[particle]]
position = [0.3, -0.2, 0.0]
mass = 1.0
[[spring]]
between = [0, 1]
stiffness = 2000.0
rest_length = 0.1
[[spring]]
between = [1, 2]
stiffness = 2000.0
rest_length = 0.09
[[spring]]
between = [2, 3]
stiffness = 2000.0
rest_length = 0.1
[[spring]]
between = [1, 3]
stiffness = 10.0
rest_length = 0.0
[[constraint]]
between = [3, 4]
length = 0.2
";

/// (i, j, rest length) of every spring and rod of [`CHAIN_WITH_ROD`] that has a strain, as
/// written in the scene (the zero-rest-length spring has none).
const CHAIN_LINKS: [(usize, usize, f64); 4] = [(0, 1, 0.1), (1, 2, 0.09), (2, 3, 0.1), (3, 4, 0.2)];

#[test]
fn strain_max_is_the_largest_strain_of_the_recorded_trajectory() {
    // Oracle: the definition, evaluated by hand on every recorded state (step 0 and every
    // frame): max over states and links of |l/l0 − 1|, l = √(dx² + dy² + dz²), with the rest
    // lengths as the scene file states them. Agreement to 1e-12 relative (only the rounding of
    // the length differs); the initial stretch 0.1/0.09 − 1 bounds it from below.
    let scene = Scenario::from_toml_str(CHAIN_WITH_ROD, "chain_with_rod.toml").unwrap();
    let (dt, steps) = (1e-3, 1000);
    for name in ["verlet_constraints", "rattle"] {
        let (_, m) = measure(&scene, name, dt, steps);
        let by_hand = record(&scene, name, dt, steps)
            .iter()
            .flat_map(|x| {
                CHAIN_LINKS.iter().map(move |&(i, j, l0)| {
                    let d = x[j] - x[i];
                    let l = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt();
                    (l / l0 - 1.0).abs()
                })
            })
            .fold(0.0, f64::max);
        eprintln!("{name}: strain_max {:e}, by hand {by_hand:e}", m.strain_max);
        assert!(by_hand >= 0.1 / 0.09 - 1.0 - 1e-12, "{name}: {by_hand}");
        assert!(
            (m.strain_max - by_hand).abs() <= 1e-12 * by_hand,
            "{name}: {} against {by_hand}",
            m.strain_max
        );
    }
}

#[test]
fn a_rod_of_unit_length_strains_exactly_as_much_as_it_is_violated() {
    // Oracle: for a rod of length L = 1 m, |l/L − 1| = |l − L|, bit for bit (division by 1 is
    // exact), so strain_max equals the constraint metric's constraint_max on the pendulum.
    let scene = Scenario::from_file("scenarios/pendulum_rod.toml").unwrap();
    let (_, m) = measure(&scene, "verlet_constraints", 1e-3, 500);
    let c = m.constraint_max.expect("a scene with a rod");
    assert!(c > 0.0, "the rod is violated a little: {c}");
    assert_eq!(m.strain_max, c);
}

#[test]
fn a_spring_stretched_ten_percent_reads_a_tenth_and_one_at_rest_reads_zero() {
    // Oracle: an anchored spring of rest length 1 m (k = 1e4 N/m, 1 kg: ω = 100 rad/s) let go
    // at rest from 1.1 m has strain 0.1 at step 0, and the exact solution (the analytic
    // method) swings within that amplitude, so the maximum is 0.1, whether the run is one step
    // or three periods. Twin: the same spring at its rest length never moves: exactly 0.
    let stretched = oscillator(1e4, 0.0, 0.1, 0.0);
    for steps in [1, 200] {
        let (_, m) = measure(&stretched, "analytic", 1e-3, steps);
        assert!(
            (m.strain_max - 0.1).abs() < 1e-12,
            "{steps} steps: {}",
            m.strain_max
        );
    }
    let at_rest = oscillator(1e4, 0.0, 0.0, 0.0);
    for name in ["analytic", "rk4"] {
        let (_, m) = measure(&at_rest, name, 1e-3, 200);
        assert_eq!(m.strain_max, 0.0, "{name}");
    }
}

/// One free particle of 2 kg under g = 10 m/s² (nothing else acts).
fn falling() -> Scenario {
    let toml = "[world]\ngravity = [0.0, -10.0, 0.0]\n\
                [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 2.0\n";
    Scenario::from_toml_str(toml, "falling.toml").unwrap()
}

#[test]
fn euler_methods_under_a_constant_force_drift_at_their_closed_form_rates() {
    // Oracle (by hand): under a constant acceleration −g, explicit Euler (y += h v, then
    // v −= g h) changes K + G per step by ½m((v − gh)² − v²) + m g h v = ½ m g² h², symplectic
    // Euler (v −= g h, then y += h v) by −m g h v + ½ m g² h² + m g h (v − g h) = −½ m g² h²,
    // and velocity Verlet is exact for a constant force. The balance is then exactly linear
    // in t, so its least-squares slope is ±½ m g² h = ±1 J/s (m = 2 kg, g = 10 m/s²,
    // h = 0.01 s) and 0 for Verlet, up to the rounding of the states' energies.
    let scene = falling();
    let (h, steps) = (0.01, 100);
    for (name, rate) in [
        ("explicit_euler", 1.0),
        ("symplectic_euler", -1.0),
        ("velocity_verlet", 0.0),
    ] {
        let (_, m) = measure(&scene, name, h, steps);
        eprintln!("{name}: energy_drift_rate {:e} J/s", m.energy_drift_rate);
        assert!(
            (m.energy_drift_rate - rate).abs() < 1e-9,
            "{name}: {} J/s against {rate}",
            m.energy_drift_rate
        );
    }
}

#[test]
fn the_exact_oscillator_has_no_energy_drift_rate() {
    // Oracle: the analytic method is the exact solution, so its energy balance is constant
    // up to rounding, |ΔE| ≤ δ with δ = 1e-12·E0 (a generous bound on the rounding of
    // E = ½kx² + ½mv² evaluated from cos/sin/exp). The least-squares slope of values bounded
    // by δ on a uniform grid over [0, T] is at most δ·Σ|t − t̄| / Σ(t − t̄)² ≈ 3δ/T.
    // Twin: explicit Euler on the same spring gains energy by the factor (1 + h²ω²) every
    // step, far above that bound.
    let (k, u0, h, steps) = (100.0, 0.1, 1e-3, 2000);
    let scene = oscillator(k, 0.0, u0, 0.0);
    let e0 = 0.5 * k * u0 * u0;
    let t = h * steps as f64;
    let bound = 3.0 * 1e-12 * e0 / t;
    let (_, exact) = measure(&scene, "analytic", h, steps);
    assert!(
        exact.energy_drift_rate.abs() <= bound,
        "{} J/s, bound {bound:e}",
        exact.energy_drift_rate
    );
    let (_, euler) = measure(&scene, "explicit_euler", h, steps);
    assert!(euler.energy_drift_rate > 1e6 * bound, "{euler:?}");
}

#[test]
fn a_damped_spring_comes_to_rest_and_an_undamped_one_keeps_its_energy_moving() {
    // Oracle: the undamped anchored spring (k = 100 N/m, 1 kg, ω = 10 rad/s) let go at rest from
    // u0 = 0.1 m has K(T) = ½ k u0² sin²(ωT), and its energy scale is E0 = ½ k u0² (no gravity,
    // no initial speed), so the exact solution's rest jitter is sin²(ωT): near 1 at
    // ωT = 51.84 rad. Twin: critically damped (c = 2√(km) = 20 N·s/m), u = u0 (1 + ωt) e^(−ωt),
    // so K(T)/E0 is of order (ωT)² e^(−2ωT) ≈ 1e-40 at ωT = 51.84: below 1e-12 for the exact
    // solution and for implicit Euler, which damps it more.
    let (k, u0, h, steps) = (100.0, 0.1, 1e-3, 5184u64);
    let t = h * steps as f64;
    let (_, undamped) = measure(&oscillator(k, 0.0, u0, 0.0), "analytic", h, steps);
    let expected = (10.0 * t).sin().powi(2);
    assert!(expected > 0.99);
    assert!(
        (undamped.rest_jitter - expected).abs() < 1e-9,
        "{} against {expected}",
        undamped.rest_jitter
    );
    for name in ["analytic", "implicit_euler"] {
        let (_, damped) = measure(&oscillator(k, 20.0, u0, 0.0), name, h, steps);
        assert!(damped.rest_jitter < 1e-12, "{name}: {}", damped.rest_jitter);
    }
}

#[test]
fn penetration_max_is_the_contact_metrics_deepest_penetration_and_absent_without_obstacles() {
    // Oracle: on the penalty bounce (a ball of radius r = 0.1 m on the plane y = 0) the
    // deepest penetration is the largest r − y over the recorded states; compare's
    // penetration_max must be that, and the very number contacts.json holds. Twin: a scene
    // without obstacles has no penetration: null in the metrics and an empty CSV cell.
    let scene = Scenario::from_file("scenarios/bounce_penalty.toml").unwrap();
    let (dt, duration) = (0.0005, 0.6);
    let names = ["symplectic_euler", "rk4"];
    let cfg = CompareConfig {
        duration: Some(duration),
        series_points: 0,
        common: springlab::measure::Common {
            methods: names.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        },
        ..Default::default()
    };
    let res = compare(&scene, &cfg).unwrap();
    assert_eq!((res.dt, res.steps), (dt, 1200));
    let dir = tempfile::tempdir().unwrap();
    write_compare(dir.path(), &res).unwrap();
    let csv = std::fs::read_to_string(dir.path().join("compare.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let cell = |name: &str, col: &str| {
        let i = header.iter().position(|h| *h == col).unwrap();
        let row = csv.lines().find(|l| l.starts_with(&format!("{name},")));
        row.unwrap().split(',').nth(i).unwrap().to_string()
    };
    for name in names {
        let r = res.entries.iter().find(|e| e.method == name).unwrap();
        let r = r.result.as_ref().unwrap();
        let m = r.metrics.as_ref().expect("ok");
        let contacts = r.contacts.as_ref().expect("a scene with obstacles");
        let pen = m.penetration_max.expect("a scene with obstacles");
        assert_eq!(pen.to_bits(), contacts.penetration.max.to_bits(), "{name}");
        let by_hand = record(&scene, name, dt, res.steps)
            .iter()
            .map(|x| (0.1 - x[0].y).max(0.0))
            .fold(0.0, f64::max);
        eprintln!("{name}: penetration_max {pen:e} m, by hand {by_hand:e} m");
        assert!(by_hand > 1e-3, "{name}: the ball sinks in: {by_hand}");
        assert!((pen - by_hand).abs() <= 1e-12, "{name}: {pen} vs {by_hand}");
        assert_eq!(cell(name, "penetration_max").parse::<f64>().unwrap(), pen);
        assert_eq!(
            cell(name, "strain_max").parse::<f64>().unwrap(),
            m.strain_max
        );
    }
    let (c, m) = measure(&oscillator(100.0, 0.0, 0.1, 0.0), "rk4", 1e-3, 100);
    assert!(c.contacts.is_none());
    assert_eq!(m.penetration_max, None);
    assert!(serde_json::to_value(&m).unwrap()["penetration_max"].is_null());
}

#[test]
fn quality_is_the_same_bits_with_one_and_two_threads() {
    // Oracle: the one-thread run. A 130 × 130 cloth takes the parallel spring path; strain is
    // a serial maximum and the energies are bit-identical across thread counts, so every
    // observable must be too.
    let toml = "[world]\ngravity=[0.0,-9.81,0.0]\n[[cloth]]\norigin=[0.0,0.0,0.0]\n\
                size=[1.0,1.0]\ncount=[130,130]\nmass=0.001\nstiffness=200.0\ndamping=0.002\n\
                plane=\"xz\"\nfix=[\"top_left\",\"top_right\"]\n";
    let scene = Scenario::from_toml_str(toml, "cloth.toml").unwrap();
    let sys = scene.build();
    assert!(sys.springs.is_parallel(sys.len()));
    let (dt, steps) = (1e-3, 4);
    let quality = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let s0 = scene.initial_state();
            let mut obs = QualityObserver::new(&sys, &s0, dt, dt * steps as f64);
            let mut stepper =
                springlab::method::create("symplectic_euler", &Default::default()).unwrap();
            let plan = RunPlan::new(dt, steps);
            let out = run::run(&sys, &mut stepper, s0.clone(), &plan, &mut obs).unwrap();
            assert!(out.status.is_ok());
            obs.quality()
        })
    };
    let (a, b) = (quality(1), quality(2));
    assert!(a.strain_max > 0.0 && a.rest_jitter > 0.0, "{a:?}");
    assert_eq!(a.strain_max.to_bits(), b.strain_max.to_bits());
    assert_eq!(a.energy_drift_rate.to_bits(), b.energy_drift_rate.to_bits());
    assert_eq!(a.rest_jitter.to_bits(), b.rest_jitter.to_bits());
}
