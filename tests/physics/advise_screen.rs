//! Advice's screen: a candidate whose least possible modelled cost is more than the screen
//! factor times the cheapest verified answer's is not run, and is named with the figures; a
//! candidate within the factor still runs; and the screen never changes the pick.
//!
//! Oracle: the engine's cost model, priced from the scene alone (`probe::seconds_per_step`,
//! called here by the test itself): Rapier's frame on the anchored spring costs about 60 times
//! a Verlet step, so at the grid's largest step it models tens of times the cost of velocity
//! Verlet's verified answer at a 1 cm tolerance, while RK4 (four force evaluations a step, and
//! a larger step at this tolerance) models within ten times it. The twin runs the same advice
//! with no screen (an infinite factor).

use springlab::measure::advise::{advise, step_grid_of, Advice, AdviseConfig, SCREEN_FACTOR};
use springlab::measure::probe::seconds_per_step;
use springlab::measure::tolerance::Metric;
use springlab::method::{MethodOptions, Registry};
use springlab::scenario::Scenario;

fn scene() -> Scenario {
    Scenario::from_file(std::path::Path::new("scenarios/anchored_spring.toml")).unwrap()
}

fn config(screen_factor: f64) -> AdviseConfig {
    AdviseConfig {
        tolerance: Some(1e-2),
        metric: Some(Metric::Position),
        frame_rates: false,
        screen_factor,
        common: springlab::measure::Common {
            methods: vec![
                "velocity_verlet".into(),
                "rk4".into(),
                "rapier_impulse".into(),
            ],
            ..Default::default()
        },
        ..Default::default()
    }
}

fn ran(adv: &Advice, method: &str) -> bool {
    adv.alternatives.iter().any(|c| c.method == method)
        || adv.unable.iter().any(|(m, _)| m == method)
}

#[test]
fn a_candidate_far_above_the_verified_answer_is_not_run_and_is_named_with_the_figure() {
    let scene = scene();
    let cfg = config(SCREEN_FACTOR);
    let adv = advise(&scene, &cfg).unwrap();
    assert_eq!(adv.method.as_deref(), Some("velocity_verlet"), "{adv:#?}");
    let pick_cost = adv.modelled_per_second.unwrap();
    // The engine's floor, priced independently: its frame at the grid's largest step.
    let (_, grid) = step_grid_of(&scene, &cfg).unwrap();
    let &(dt_max, steps) = grid.last().unwrap();
    let per_frame = seconds_per_step(
        &scene.build(),
        &scene.initial_state(),
        &Registry::builtin(),
        &MethodOptions::default(),
        "rapier_impulse",
        dt_max,
        steps,
    )
    .unwrap();
    let floor = per_frame / dt_max;
    assert!(
        floor > SCREEN_FACTOR * pick_cost,
        "the oracle's premise: {floor:e} vs {pick_cost:e}"
    );
    let s = adv
        .screened
        .iter()
        .find(|s| s.method == "rapier_impulse")
        .unwrap_or_else(|| panic!("rapier_impulse was not screened: {adv:#?}"));
    assert!(!ran(&adv, "rapier_impulse"));
    assert_eq!(s.finest_run, None);
    assert_eq!(s.modelled_per_second, floor);
    assert_eq!(s.dt, dt_max);
    assert_eq!(s.basis.method, "velocity_verlet");
    assert_eq!(s.basis.modelled_per_second, pick_cost);
    let ratio = springlab::error::significant(floor / pick_cost, 3);
    assert!(
        s.reason.starts_with("not run: at least ")
            && s.reason.contains(&format!(
                "{ratio}× the cost of velocity_verlet's verified answer"
            ))
            && s.reason.contains(&springlab::error::significant(floor, 3))
            && s.reason
                .contains(&springlab::error::significant(pick_cost, 3)),
        "{}",
        s.reason
    );
    // Twin: RK4, within the factor, ran and was verified.
    let rk4 = adv
        .alternatives
        .iter()
        .find(|c| c.method == "rk4")
        .unwrap_or_else(|| panic!("rk4 should run: {adv:#?}"));
    assert!(rk4.modelled_per_second <= SCREEN_FACTOR * pick_cost);
    assert!(!adv.screened.iter().any(|s| s.method == "rk4"));
}

#[test]
fn twin_without_a_screen_the_candidate_runs_and_the_pick_is_the_same() {
    let scene = scene();
    let screened = advise(&scene, &config(SCREEN_FACTOR)).unwrap();
    let open = advise(&scene, &config(f64::INFINITY)).unwrap();
    assert!(open.screened.is_empty(), "{:#?}", open.screened);
    assert!(ran(&open, "rapier_impulse"), "{open:#?}");
    // Whatever the engine's answer, the screen left out nothing a user would take: an answer
    // costs more than ten times the pick, or there is none (it could not meet the bound).
    match open
        .alternatives
        .iter()
        .find(|c| c.method == "rapier_impulse")
    {
        Some(r) => {
            assert!(r.modelled_per_second > SCREEN_FACTOR * open.modelled_per_second.unwrap())
        }
        None => assert!(
            open.unable.iter().any(|(m, _)| m == "rapier_impulse"),
            "{open:#?}"
        ),
    }
    assert_eq!(screened.method, open.method);
    assert_eq!(screened.dt, open.dt);
    assert_eq!(screened.verified_error, open.verified_error);
    assert_eq!(screened.modelled_per_second, open.modelled_per_second);
}

/// Every number of an advice but its wall times, as JSON.
fn without_wall_times(adv: &Advice) -> String {
    let mut v = serde_json::to_value(adv).unwrap();
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.retain(|k, _| k != "wall_per_second" && k != "timing");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v.to_string()
}

/// Oracle: the one-thread advice; the screen decides on modelled costs (counted work), so the
/// order of the waves, what is screened and every figure are the same bits on two threads.
#[test]
fn the_screen_decides_the_same_whatever_the_thread_count() {
    let scene = scene();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| advise(&scene, &config(SCREEN_FACTOR)).unwrap())
    };
    let (one, two) = (run(1), run(2));
    assert!(!one.screened.is_empty());
    assert_eq!(without_wall_times(&one), without_wall_times(&two));
}
