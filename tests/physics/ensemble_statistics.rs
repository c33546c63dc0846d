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
    r.add_ensemble(&sys, &s0, 0.01).unwrap();
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
            methods: vec!["symplectic_euler".into(), "rk4".into()],
            points: 4,
            frame_rates: false,
            ..AdviseConfig::default()
        },
    )
    .unwrap();
    assert_eq!(adv.metric, Metric::Statistics);
    assert_eq!(adv.horizon, 2.0);
    assert_eq!(adv.tolerance, 1.0);
    let err = adv.verified_error.expect("a pick");
    assert!(err <= 1.0, "{err}");
    assert!(adv.position_tolerance.source.contains("motion scale"));
}
