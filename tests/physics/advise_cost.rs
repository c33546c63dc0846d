//! Advice ranks by a cost every method shares (modelled seconds per simulated second: counted
//! work, priced), so a Rapier method, which has no force-evaluation count, is never free; the
//! measured wall time beside it agrees where the gap is wide.
//!
//! Both tests compare costs from one run of the advisor (ratios, not timed thresholds).

use springlab::measure::advise::{advise, AdviseConfig};
use springlab::measure::tolerance::Metric;
use springlab::model::State;
use springlab::run::{run, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

fn is_rapier(name: &str) -> bool {
    springlab::method::Registry::builtin()
        .info(name)
        .unwrap()
        .engine
}

/// A 30-bead rope: k = 200 N/m, 50 g beads, first bead fixed, released horizontally under
/// gravity.
const ROPE: &str = r#"
name = "rope30"
[world]
gravity = [0.0, -9.81, 0.0]
[[chain]]
start = [0.0, 0.0, 0.0]
end = [1.0, 0.0, 0.0]
count = 30
mass = 0.05
stiffness = 200.0
fix = ["first"]
[run]
dt = 0.001
duration = 2.0
"#;

/// Oracle: none tuned — the comparison is between the costs the advisor itself found in this
/// run. A user's measurement: rapier_impulse meets a 10 cm tolerance on this rope at about
/// 700× velocity Verlet's wall time, so a ranking by a shared cost must not pick it, and the
/// clock, measured in the same run, must agree with the model on a gap that wide.
#[test]
fn rope_pick_is_native_and_no_slower_than_any_rapier_candidate() {
    let scene = Scenario::from_toml_str(ROPE, "rope30.toml").unwrap();
    let cfg = AdviseConfig {
        tolerance: Some(0.1),
        metric: Some(Metric::Position),
        horizon: Some(2.0),
        // A grid from 1 ms up (the default starts at dt/30, where Rapier's runs take seconds);
        // Rapier meets 10 cm from about 1.5 ms down.
        dt_min: Some(1e-3),
        points: 5,
        // The comparison needs Rapier run: with the screen it would not be, for the very gap
        // this test measures (the screen has its own tests, `advise_screen`).
        screen_factor: f64::INFINITY,
        // The game view is the frame-rate table's (`measure_advise` checks it).
        frame_rates: false,
        common: springlab::measure::Common {
            methods: vec![
                "velocity_verlet".into(),
                "symplectic_euler".into(),
                "rapier_impulse".into(),
            ],
            ..Default::default()
        },
        ..Default::default()
    };
    let adv = advise(&scene, &cfg).unwrap();
    let pick = adv.method.clone().expect("a method meets 10 cm");
    assert!(!is_rapier(&pick), "picked {pick}");
    let wall = adv.wall_per_second.unwrap();
    assert!(wall.is_finite() && wall > 0.0);
    let cost = adv.modelled_per_second.unwrap();
    assert!(cost.is_finite() && cost > 0.0);
    assert!(adv.cost_per_second.is_some_and(|c| c > 0.0));
    let rapier: Vec<_> = adv
        .alternatives
        .iter()
        .filter(|c| is_rapier(&c.method))
        .collect();
    assert!(
        !rapier.is_empty(),
        "rapier_impulse should meet 10 cm, else this test compares nothing: {:?}",
        adv.unable
    );
    for r in &rapier {
        assert!(
            cost <= r.modelled_per_second && wall <= r.wall_per_second,
            "pick {pick} {cost:e} ({wall:e}) s/s vs {} {:e} ({:e}) s/s",
            r.method,
            r.modelled_per_second,
            r.wall_per_second
        );
        // No force-evaluation count for Rapier: null with the reason, never 0.
        assert!(r.cost_per_second.is_none());
        assert!(r
            .cost_per_second_reason
            .as_deref()
            .is_some_and(|s| !s.is_empty()));
    }
    // advice.json states the measure; every candidate was timed by its rule.
    let json = serde_json::to_value(&adv).unwrap();
    assert_eq!(
        json["cost"]["measure"],
        "modelled_seconds_per_simulated_second"
    );
    assert!(json["cost"]["model"].as_str().is_some());
    assert!(json["cost"]["tie_rule"].as_str().is_some());
    for c in &adv.alternatives {
        assert!(c.timing.repetitions >= cfg.timing.cap_repetitions);
        assert!(c.timing.min_seconds <= c.timing.median_seconds);
        assert!(c.timing.median_seconds <= c.timing.max_seconds);
    }
    // The alternatives are in the ranking's order: a candidate never precedes one whose cost
    // is lower by more than the tie band.
    let band = springlab::measure::advise::TIE_BAND;
    for (i, a) in adv.alternatives.iter().enumerate() {
        for b in &adv.alternatives[i + 1..] {
            assert!(
                a.modelled_per_second <= (1.0 + band) * b.modelled_per_second,
                "{} before {}",
                a.method,
                b.method
            );
        }
    }
}

/// A particle dropped from rest at 10 m, for 1 s.
const FREE_FALL: &str = r#"
name = "free_fall"
[world]
gravity = [0.0, -9.81, 0.0]
[[particle]]
position = [0.0, 10.0, 0.0]
velocity = [0.0, 0.0, 0.0]
mass = 1.0
[run]
dt = 0.01
duration = 1.0
"#;

struct FallErr(f64, f64);
impl Observer for FallErr {
    fn observe(&mut self, step: u64, s: &State, _e: &EnergyRecord) -> springlab::Result<()> {
        let t = step as f64 * self.1;
        let y = 10.0 - 0.5 * 9.81 * t * t;
        let err = (s.x[0].x.powi(2) + (s.x[0].y - y).powi(2) + s.x[0].z.powi(2)).sqrt();
        self.0 = self.0.max(err);
        Ok(())
    }
}

/// Oracle: y(t) = 10 − g t²/2, evaluated here (1 s, g = 9.81 m/s²). Velocity Verlet integrates a constant
/// acceleration exactly (its position update is the Taylor series, which ends at t²), so it
/// meets any tolerance at the largest step of the grid; a Rapier method at a small step
/// cannot be cheaper, by the model or by the clock.
#[test]
fn free_fall_pick_is_exact_at_the_largest_grid_step() {
    let scene = Scenario::from_toml_str(FREE_FALL, "free_fall.toml").unwrap();
    let cfg = AdviseConfig {
        tolerance: Some(1e-3),
        metric: Some(Metric::Position),
        points: 6,
        // The Rapier candidates must run to be compared (the screen would leave them out).
        screen_factor: f64::INFINITY,
        ..Default::default()
    };
    let adv = advise(&scene, &cfg).unwrap();
    let pick = adv.method.clone().expect("velocity Verlet meets 1 mm");
    assert!(!is_rapier(&pick), "picked {pick}");
    let largest = adv.grid.iter().copied().fold(0.0, f64::max);
    assert_eq!(adv.dt, Some(largest), "pick {pick}");
    // Velocity Verlet is a candidate, exact at the largest step.
    let vv = adv
        .alternatives
        .iter()
        .find(|c| c.method == "velocity_verlet")
        .expect("velocity_verlet meets 1 mm");
    assert_eq!(vv.dt, largest);
    // The pick, re-run independently, is exact to round-off against the closed form.
    let mut stepper = springlab::method::create(&pick, &Default::default()).unwrap();
    let dt = adv.dt.unwrap();
    let steps = (1.0 / dt).round() as u64;
    let mut obs = FallErr(0.0, dt);
    let out = run(
        &scene.build(),
        &mut stepper,
        scene.initial_state(),
        &RunPlan::new(dt, steps),
        &mut obs,
    )
    .unwrap();
    assert!(out.status.is_ok());
    assert!(obs.0 <= 1e-9, "{pick} error {:e} at dt {dt}", obs.0);
    // The Rapier methods meet 1 mm only at the smallest steps (a user's pick was one at
    // dt = 4e-4); each costs at least as much wall time as the pick.
    let rapier: Vec<_> = adv
        .alternatives
        .iter()
        .filter(|c| is_rapier(&c.method))
        .collect();
    assert!(
        !rapier.is_empty(),
        "no Rapier candidate to compare: {:?}",
        adv.unable
    );
    for r in rapier {
        assert!(r.dt < 1e-3, "{} at {}", r.method, r.dt);
        assert!(adv.modelled_per_second.unwrap() <= r.modelled_per_second);
        assert!(adv.wall_per_second.unwrap() <= r.wall_per_second);
    }
}
