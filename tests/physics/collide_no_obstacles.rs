//! A scene without obstacles pays nothing for collision.
//!
//! Oracle: counting. The thread-local parry counters must not move while such a scene is
//! built and run with every method (one test per binary, so nothing else runs on the
//! thread); the same run with one plane must move them (the counter works).

use springlab::collide::{build_count, query_count};
use springlab::method::create as by_name;
use springlab::method::MethodOptions;
use springlab::run::{run, NoObserver, RunPlan};
use springlab::scenario::Scenario;

#[test]
fn no_obstacles_no_queries() {
    let path = format!(
        "{}/scenarios/hanging_chain.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let scene = Scenario::from_file(&path).unwrap();
    assert!(scene.collision.is_none());
    let (q0, b0) = (query_count(), build_count());
    let sys = scene.build();
    assert!(sys.post_step.is_none());
    for name in [
        "symplectic_euler",
        "implicit_euler",
        "rk4",
        "verlet_constraints",
    ] {
        let mut m = by_name(name, &MethodOptions::default()).unwrap();
        run(
            &sys,
            &mut m,
            scene.initial_state(),
            &RunPlan::new(1e-3, 200),
            &mut NoObserver,
        )
        .unwrap();
    }
    assert_eq!(
        query_count(),
        q0,
        "parry queries in a scene without obstacles"
    );
    assert_eq!(
        build_count(),
        b0,
        "obstacle sets built for a scene without obstacles"
    );

    // Positive control: one plane the chain lies on makes the counters move (a plane far
    // below it would not: its distance bound rules every query out).
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n";
    let scene = Scenario::from_toml_str(&text, "chain_plane.toml").unwrap();
    let sys = scene.build();
    assert_eq!(build_count(), b0 + 1);
    let mut m = by_name("rk4", &MethodOptions::default()).unwrap();
    run(
        &sys,
        &mut m,
        scene.initial_state(),
        &RunPlan::new(1e-3, 10),
        &mut NoObserver,
    )
    .unwrap();
    assert!(query_count() >= q0 + 200, "20 particles × 10 steps");
}
