//! Accuracy past the predictability horizon: runs judged against the reference's ensemble.
//!
//! Oracles: a 16×16 cloth pinned at two corners is chaotic within its 2 s (its reference says
//! so: a perturbation of 1e-12 of its size grows a million-fold before the end), so position
//! error past that time measures the chaos. A fine rk4 run (1 ms, error ~1e-5 m before the
//! horizon) is as good a solution as any ensemble member and must be consistent on every
//! observable; runs known to be wrong must not be: the same cloth with springs 100 times
//! softer (it stretches several-fold) and with dampers 250 times stronger (critically damped springs: it barely swings),
//! each measured against the true scene's ensemble.

use springlab::measure::advise::{advise, AdviseConfig};
use springlab::measure::case::{run_case, CaseResult, CaseSettings};
use springlab::measure::compare::{compare, CompareConfig};
use springlab::measure::framerate::{framerate, FramerateConfig};
use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::Reference;
use springlab::measure::statistics::ENSEMBLE_SIZE;
use springlab::measure::tolerance::Metric;
use springlab::scenario::Scenario;

fn cloth(stiffness: f64, damping: f64) -> Scenario {
    Scenario::from_toml_str(
        &format!(
            r#"
name = "cloth16"
[world]
gravity = [0.0, -9.81, 0.0]
[[cloth]]
origin = [0.0, 0.0, 0.0]
size = [1.0, 1.0]
count = [16, 16]
mass = 0.002
stiffness = {stiffness:?}
damping = {damping:?}
bend_stiffness = 20.0
plane = "xz"
fix = ["top_left", "top_right"]
[run]
dt = 0.001
duration = 2.0
"#
        ),
        "cloth16.toml",
    )
    .unwrap()
}

/// The true cloth's reference with its ensemble, and `scene`'s rk4 run against it.
fn judged(reference: &Reference, scene: &Scenario) -> CaseResult {
    let set = CaseSettings {
        repeat_short: false,
        ..CaseSettings::default()
    };
    run_case(
        &scene.build(),
        &scene.initial_state(),
        reference,
        0,
        "rk4",
        &set,
    )
    .unwrap()
}

#[test]
fn a_fine_run_is_consistent_and_a_stretched_or_overdamped_cloth_is_not() {
    let truth = cloth(200.0, 0.002);
    let (sys, s0) = (truth.build(), truth.initial_state());
    let grid = TimeGrid::new(1e-3, 2000, 2001);
    let mut r = Reference::compute(&sys, &s0, &[grid], 2.0).unwrap();
    let h = r.info.predictability_horizon.expect("the cloth is chaotic");
    assert!(h < 1.5, "horizon {h}");
    r.add_ensemble(&sys, &s0, 0.01, grid).unwrap();
    let e = r.ensemble.as_ref().expect("an ensemble past the horizon");
    assert_eq!(e.members.len(), ENSEMBLE_SIZE);
    assert_eq!(e.start, h);

    let fine = judged(&r, &truth);
    let m = fine.metrics.as_ref().expect("ok");
    assert!(
        m.error_max_predictable < 1e-3,
        "{}",
        m.error_max_predictable
    );
    let stats = m.statistics.as_ref().expect("statistics past the horizon");
    for (name, s) in stats {
        assert!(s.consistent, "fine rk4 {name}: {s:?}");
    }

    let soft = judged(&r, &cloth(2.0, 0.002));
    let st = soft
        .metrics
        .as_ref()
        .expect("ok")
        .statistics
        .clone()
        .unwrap();
    assert!(st["strain_max"].run_mean > 2.0 * st["strain_max"].ensemble_mean);
    assert!(!st["strain_max"].consistent, "{:?}", st["strain_max"]);

    let damped = judged(&r, &cloth(200.0, 0.5));
    let st = damped
        .metrics
        .as_ref()
        .expect("ok")
        .statistics
        .clone()
        .unwrap();
    assert!(st["kinetic_energy"].run_mean < st["kinetic_energy"].ensemble_mean);
    assert!(
        !st["kinetic_energy"].consistent,
        "{:?}",
        st["kinetic_energy"]
    );
}

// Twin of the above for the answer: advice on the chaotic cloth judges by statistics over the
// whole 2 s (not only the predictable first part) and answers with a verified pick.
#[test]
fn advice_on_a_chaotic_cloth_answers_over_its_whole_duration() {
    let scene = cloth(200.0, 0.002);
    let adv = advise(
        &scene,
        &AdviseConfig {
            points: 4,
            frame_rates: false,
            common: springlab::measure::Common {
                methods: vec!["symplectic_euler".into(), "rk4".into()],
                ..AdviseConfig::default().common.clone()
            },
            ..AdviseConfig::default()
        },
    )
    .unwrap();
    assert_eq!(adv.judged.metric, Metric::Statistics);
    assert_eq!(adv.horizon, 2.0);
    assert_eq!(adv.judged.tolerance, 1.0);
    let err = adv.verified_error.expect("a pick");
    assert!(err <= 1.0, "{err}");
    assert!(adv
        .judged
        .position_tolerance
        .source
        .contains("motion scale"));
}

/// Two masses on stiff springs hung from a fixed point and released sideways: chaotic within
/// its 10 s (its reference's predictability horizon is near 6 s), and cheap to solve.
fn double_pendulum() -> Scenario {
    Scenario::from_toml_str(
        r#"
name = "double_pendulum"
[world]
gravity = [0.0, -9.81, 0.0]
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true
[[particle]]
position = [1.0, 0.0, 0.0]
mass = 1.0
[[particle]]
position = [1.6, 0.8, 0.0]
mass = 1.0
[[spring]]
between = [0, 1]
stiffness = 2000.0
[[spring]]
between = [1, 2]
stiffness = 2000.0
[run]
dt = 0.002
duration = 10.0
"#,
        "double_pendulum.toml",
    )
    .unwrap()
}

/// A document's value with its wall times taken out (they differ between any two runs).
fn without_wall(v: serde_json::Value) -> serde_json::Value {
    match v {
        serde_json::Value::Object(m) => m
            .into_iter()
            .filter(|(k, _)| !k.contains("wall") && k != "timing")
            .map(|(k, x)| (k, without_wall(x)))
            .collect(),
        serde_json::Value::Array(a) => a.into_iter().map(without_wall).collect(),
        x => x,
    }
}

fn advice_with(
    scene: &Scenario,
    ensemble: Option<springlab::measure::statistics::Ensemble>,
) -> serde_json::Value {
    let adv = advise(
        scene,
        &AdviseConfig {
            points: 4,
            frame_rates: false,
            ensemble,
            common: springlab::measure::Common {
                methods: vec!["symplectic_euler".into(), "rk4".into()],
                ..AdviseConfig::default().common.clone()
            },
            ..AdviseConfig::default()
        },
    )
    .unwrap();
    without_wall(serde_json::to_value(&adv).unwrap())
}

fn frame_rates_with(
    scene: &Scenario,
    ensemble: Option<springlab::measure::statistics::Ensemble>,
) -> serde_json::Value {
    let fr = framerate(
        scene,
        &FramerateConfig {
            rates: vec![60.0],
            max_substeps: 4,
            ensemble,
            common: springlab::measure::Common {
                methods: vec!["rk4".into()],
                ..FramerateConfig::default().common.clone()
            },
            ..FramerateConfig::default()
        },
    )
    .unwrap();
    without_wall(serde_json::to_value(&fr).unwrap())
}

fn compared_ensemble(scene: &Scenario, dt: f64) -> springlab::measure::statistics::Ensemble {
    compare(
        scene,
        &CompareConfig {
            dt: Some(dt),
            series_points: 0,
            common: springlab::measure::Common {
                methods: vec!["rk4".into()],
                ..CompareConfig::default().common.clone()
            },
            ..CompareConfig::default()
        },
    )
    .unwrap()
    .ensemble
    .expect("the double pendulum is chaotic within its run")
}

// Oracle: one truth. A study hands compare's ensemble to advice and frame rates; each command
// run alone makes the scene's ensemble itself. Both must give the same document, or the
// command a report prints would not re-create its numbers.
#[test]
fn advice_and_frame_rates_judge_against_the_scenes_ensemble_however_they_get_it() {
    let scene = double_pendulum();
    let shared = compared_ensemble(&scene, 0.002);
    let adv = advice_with(&scene, None);
    assert_eq!(adv["metric"], "statistics", "{adv}");
    assert_eq!(advice_with(&scene, Some(shared.clone())), adv);
    let fr = frame_rates_with(&scene, None);
    assert_eq!(fr["metric"], "statistics");
    assert_eq!(frame_rates_with(&scene, Some(shared)), fr);
}

// Twin: an ensemble made by a reference on another grid has another predictability horizon,
// so another window; handed over, it must be set aside, not used, or the answers would depend
// on how they were asked for. Compare itself, asked at another step, still judges against the
// scene's ensemble.
#[test]
fn an_ensemble_made_on_another_grid_is_not_the_scenes() {
    let scene = double_pendulum();
    let own = compared_ensemble(&scene, 0.002);
    assert_eq!(compared_ensemble(&scene, 0.001).start, own.start);
    let (sys, s0) = (scene.build(), scene.initial_state());
    let grid = TimeGrid::new(1.0 / 60.0, 600, 601);
    let mut r = Reference::compute(&sys, &s0, &[grid], 10.0).unwrap();
    r.add_ensemble(&sys, &s0, 0.01, grid).unwrap();
    let other = r.ensemble.unwrap_or_else(|| panic!("{:?}", r.info));
    assert_ne!(other.start, own.start, "another reference, another horizon");
    assert_eq!(
        advice_with(&scene, Some(other.clone())),
        advice_with(&scene, None)
    );
    assert_eq!(
        frame_rates_with(&scene, Some(other)),
        frame_rates_with(&scene, None)
    );
}
