//! Bouncing scenes judged bounce by bounce (`impacts`): apex heights against the reference's.
//!
//! Oracle: a ball dropped from h0 = 1 m (its surface above the plane) with restitution e rises
//! to h0·e^(2n) after bounce n (each impact keeps e² of the energy). A run of the shipped
//! scene at a fine step meets 1 cm on apexes; a run of the same ball with e = 0.45 instead of
//! 0.5, judged against the true scene's reference, misses its first apex by
//! h0·(0.5² − 0.45²) = 0.0475 m whatever its timing.

use springlab::measure::case::{run_case, CaseSettings};
use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::Reference;
use springlab::scenario::Scenario;

fn bounce(restitution: f64) -> Scenario {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/bounce.toml"
    ))
    .unwrap()
    .replace(
        "restitution = 0.5",
        &format!("restitution = {restitution:?}"),
    );
    Scenario::from_toml_str(&text, "bounce.toml").unwrap()
}

#[test]
fn a_wrong_restitution_misses_the_apexes_and_a_fine_run_meets_them() {
    let truth = bounce(0.5);
    let (sys, s0) = (truth.build(), truth.initial_state());
    let grid = TimeGrid::new(2.5e-4, 8000, 8001);
    let r = Reference::compute(&sys, &s0, &[grid], 2.0).unwrap();
    let set = CaseSettings {
        repeat_short: false,
        ..CaseSettings::default()
    };
    let fine = run_case(&sys, &s0, &r, 0, "velocity_verlet", &set).unwrap();
    let apex = fine
        .metrics
        .as_ref()
        .unwrap()
        .apex_error
        .expect("it bounced");
    assert!(apex < 0.01, "fine run apex error {apex}");

    let wrong = bounce(0.45);
    let c = run_case(
        &wrong.build(),
        &wrong.initial_state(),
        &r,
        0,
        "velocity_verlet",
        &set,
    )
    .unwrap();
    let apex = c.metrics.as_ref().unwrap().apex_error.expect("it bounced");
    let first = 0.5f64.powi(2) - 0.45f64.powi(2);
    assert!(
        apex >= first - 2e-3,
        "wrong restitution apex error {apex} < {first}"
    );
}
