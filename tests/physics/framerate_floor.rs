//! With `[run] events = "frame"` a kick waits for the next frame boundary, and no substep count
//! removes that lag: `framerate` names the floor it puts under every error, and its size.
//!
//! Oracle (closed form): a free particle kicked by Δv at time t₀ moves Δv·δ less than the exact
//! one after the kick when the kick is applied δ later; with frames of h, δ = ⌈t₀/h⌉·h − t₀.

use springlab::measure::framerate::{framerate, FramerateConfig};
use springlab::scenario::Scenario;

fn kicked(events: &str) -> Scenario {
    let toml = format!(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n\
         [[impulse]]\ntime=0.01\nparticle=0\ndelta_v=[2.0,0.0,0.0]\n\
         [run]\ndt=0.01\nduration=0.5\nevents=\"{events}\"\n"
    );
    Scenario::from_toml_str(&toml, "kicked.toml").unwrap()
}

fn config() -> FramerateConfig {
    FramerateConfig {
        rates: vec![30.0],
        tolerance: Some(1e-3),
        max_substeps: 8,
        common: springlab::measure::Common {
            methods: vec!["symplectic_euler".into()],
            ..Default::default()
        },
        ..Default::default()
    }
}

#[test]
fn framerate_names_the_frame_event_floor_and_its_size() {
    let fr = framerate(&kicked("frame"), &config()).unwrap();
    let e = &fr.entries[0];
    // δ = 1/30 − 0.01 s, so the floor is 2 m/s · δ.
    let floor = 2.0 * (1.0 / 30.0 - 0.01);
    let got = e
        .frame_event_floor
        .expect("a frame-event scene has a floor");
    assert!((got - floor).abs() < 1e-6 * floor, "{got} against {floor}");
    assert!(e.fewest.is_none());
    let note = e.fewest_note.as_deref().unwrap();
    assert!(
        note.contains("no substep count removes")
            && note.contains(&springlab::error::significant(floor, 4)),
        "{note}"
    );
}

#[test]
fn exact_events_have_no_floor_and_meet_the_tolerance() {
    // Twin: the same kick at its own time; a free particle is exact for symplectic Euler.
    let fr = framerate(&kicked("exact"), &config()).unwrap();
    let e = &fr.entries[0];
    assert_eq!(e.frame_event_floor, None);
    assert!(e.fewest.is_some(), "{:?}", e.fewest_note);
}

// The wall-time rules of the table's runs: under `MEASURED_RUN` (a report's study) each
// stable row's wall time is the one run that measured it, nothing repeated; its twin under the
// command's own rule repeats every row at least as often as the rule asks.
#[test]
fn measured_run_timing_keeps_the_accuracy_runs_time_and_the_twin_repeats() {
    use springlab::measure::case::MEASURED_RUN;
    use springlab::measure::framerate::FRAMERATE_TIMING;
    let timed_rows = |rule| {
        let cfg = FramerateConfig {
            timing: rule,
            ..config()
        };
        let fr = framerate(&kicked("exact"), &cfg).unwrap();
        let e = fr.entries[0].clone();
        [Some(e.one_substep), e.fewest]
            .into_iter()
            .flatten()
            .filter(|r| r.status.is_ok())
            .map(|r| {
                (
                    r.timing.expect("a stable row is timed"),
                    r.wall_seconds_per_frame,
                )
            })
            .collect::<Vec<_>>()
    };
    let measured = timed_rows(MEASURED_RUN);
    assert!(!measured.is_empty());
    for (t, per_frame) in &measured {
        assert_eq!(t.repetitions, 1);
        assert!(per_frame.is_some_and(|w| w > 0.0));
    }
    for (t, _) in timed_rows(FRAMERATE_TIMING) {
        assert!(t.repetitions >= FRAMERATE_TIMING.cap_repetitions);
    }
}
