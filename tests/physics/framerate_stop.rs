//! A search that only needs whether a run passes ends a run once it has failed for good: its
//! largest position error before the predictability horizon only grows, so once it passes the
//! tolerance no later step can bring it back (`measure::case::CaseSettings::stop`).
//!
//! Oracle (closed form): the anchored spring (1 kg, ω = 2 rad/s, released 0.5 m from rest;
//! the closed-form reference). Explicit Euler multiplies the amplitude by √(1 + (hω)²) each
//! step: at h = 0.05 s that is 1.005 per step, so its error passes 1 cm within the first
//! seconds and the run ends there, with no number. The twin: velocity Verlet at h = 0.01 s stays
//! within 2e-4 m over 10 s (phase error ≈ (hω)²/24 per radian), never passes 1 cm, runs to the
//! end, and its metrics are bit for bit those of the unjudged run.

use springlab::measure::case::{run_case, CaseSettings};
use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::Reference;
use springlab::scenario::Scenario;

const TOLERANCE: f64 = 0.01;

fn case(
    method: &str,
    dt: f64,
) -> (
    springlab::measure::case::CaseResult,
    springlab::measure::case::CaseResult,
    u64,
) {
    let scene = Scenario::from_file("scenarios/anchored_spring.toml").unwrap();
    let (sys, s0) = (scene.build(), scene.initial_state());
    let steps = (10.0 / dt).round() as u64;
    let grid = TimeGrid::new(dt, steps, steps + 1);
    let r = Reference::compute(&sys, &s0, &[grid], 10.0).unwrap();
    let set = CaseSettings {
        repeat_short: false,
        ..Default::default()
    };
    let whole = run_case(&sys, &s0, &r, 0, method, &set).unwrap();
    let stopping = CaseSettings {
        stop: Some((1.0, TOLERANCE)),
        ..set.clone()
    };
    let judged = run_case(&sys, &s0, &r, 0, method, &stopping).unwrap();
    (whole, judged, steps)
}

#[test]
fn a_run_past_the_tolerance_ends_there_with_no_number() {
    let (whole, judged, steps) = case("explicit_euler", 0.05);
    let err = whole.metrics.as_ref().unwrap().error_max_predictable;
    assert!(err > TOLERANCE, "{err}");
    assert_eq!(whole.steps_done, steps);
    assert!(
        judged.steps_done < steps / 2,
        "{} of {steps}",
        judged.steps_done
    );
    assert!(judged.metrics.is_none());
    assert!(judged.status.is_ok());
}

#[test]
fn twin_a_run_within_the_tolerance_runs_whole_with_the_same_numbers() {
    let (whole, judged, steps) = case("velocity_verlet", 0.01);
    let m = whole.metrics.as_ref().unwrap();
    assert!(
        m.error_max_predictable < 2e-4,
        "{}",
        m.error_max_predictable
    );
    assert_eq!(judged.steps_done, steps);
    let j = judged.metrics.as_ref().unwrap();
    assert_eq!(
        serde_json::to_string(m).unwrap(),
        serde_json::to_string(j).unwrap()
    );
}
