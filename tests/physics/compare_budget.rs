//! The compare budget's projection is what the run then books: a frame's substeps are priced
//! once, inside the frame, for a native method (N steps of dt/N) and an engine (one frame of N
//! solver substeps) alike.
//!
//! Oracle: the run's own books. The modelled cost is deterministic counted work
//! (`springlab::run::cost`), so the projection of a run that completes must equal the
//! modelled seconds that run books: exactly for an engine (its frame is priced from the scene
//! alone) and for symplectic Euler on a scene without contacts (one force evaluation per step,
//! the same work every step), up to the rounding of summing the frames.

use springlab::measure::compare::{compare, projected_cost, CompareConfig};
use springlab::scenario::Scenario;

const METHODS: [&str; 2] = ["rapier_impulse", "symplectic_euler"];

fn config(budget: f64) -> CompareConfig {
    CompareConfig {
        dt: Some(1.0 / 60.0),
        frame_substeps: Some(1024),
        series_points: 0,
        common: springlab::measure::Common {
            methods: METHODS.iter().map(|s| s.to_string()).collect(),
            options: springlab::method::MethodOptions::default().with_substeps(1024),
            budget_seconds: Some(budget),
            ..Default::default()
        },
        ..Default::default()
    }
}

#[test]
fn the_projection_of_a_substepped_run_is_what_the_run_books() {
    let scene = Scenario::from_file("scenarios/hanging_chain.toml").unwrap();
    let (sys, s0) = (scene.build(), scene.initial_state());
    let cfg = config(springlab::measure::probe::DEFAULT_BUDGET_SECONDS);
    let res = compare(&scene, &cfg).unwrap();
    for e in &res.entries {
        let r = e
            .result
            .as_ref()
            .unwrap_or_else(|| panic!("{} left out: {:?}", e.method, e.skip_reason));
        assert_eq!(r.steps_done, res.steps, "{}", e.method);
        let p = projected_cost(&sys, &s0, &cfg, &e.method, res.dt, res.steps);
        let rel = (p.projected - r.modelled_seconds).abs() / r.modelled_seconds;
        eprintln!(
            "{}: projected {:.4} s, booked {:.4} s ({:.3} ms per frame)",
            e.method,
            p.projected,
            r.modelled_seconds,
            p.per_unit * 1e3
        );
        assert!(
            rel < 1e-9,
            "{}: {} vs {}",
            e.method,
            p.projected,
            r.modelled_seconds
        );
    }
}

#[test]
fn twin_a_budget_just_below_a_run_leaves_it_out_with_its_figure() {
    let scene = Scenario::from_file("scenarios/hanging_chain.toml").unwrap();
    let (sys, s0) = (scene.build(), scene.initial_state());
    let probe = config(1.0);
    let dt = 1.0 / 60.0;
    let steps = springlab::scenario::Timing::resolve(&scene, Some(dt), None)
        .unwrap()
        .steps;
    let engine = projected_cost(&sys, &s0, &probe, "rapier_impulse", dt, steps).projected;
    let native = projected_cost(&sys, &s0, &probe, "symplectic_euler", dt, steps).projected;
    // The budget holds the cheaper run and 0.99 of the dearer: only the dearer is left out.
    let (dear, cheap) = if engine > native {
        ("rapier_impulse", native)
    } else {
        ("symplectic_euler", engine)
    };
    let budget = cheap + 0.99 * engine.max(native);
    let res = compare(&scene, &config(budget)).unwrap();
    for e in &res.entries {
        if e.method == dear {
            let why = e.skip_reason.as_deref().unwrap_or("");
            let figure = springlab::measure::probe::sig3(engine.max(native));
            assert!(
                why.contains(&format!("about {figure} s")) && why.contains("ms per frame"),
                "{}: {why}",
                e.method
            );
        } else {
            assert!(e.result.is_some(), "{}: {:?}", e.method, e.skip_reason);
        }
    }
}
