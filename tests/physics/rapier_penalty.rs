//! Rapier on a penalty-contact scene: the penalty spring is applied to each Rapier body as a
//! user force evaluated at the start of each Rapier step and held over it (how a game adds a
//! custom force), and the obstacles are not Rapier colliders.
//!
//! Oracle: the scheme itself. One Rapier step with one solver substep and no joints is
//! symplectic Euler, v ← v + h(F/m + g), x ← x + h v; with the penalty force evaluated at the
//! start of the step that is exactly springlab's `symplectic_euler` on the same scene, so the
//! two trajectories must agree to round-off over a whole bouncing run. With more solver
//! substeps the force stays frozen over the frame while the body moves, so the run departs from
//! it, by less at a smaller frame step (first order in the frame step).

use springlab::method::MethodOptions;
use springlab::method::Registry;
use springlab::model::State;
use springlab::run::{run, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

struct Keep(Vec<State>);
impl Observer for Keep {
    fn observe(&mut self, _: u64, s: &State, _: &EnergyRecord) -> springlab::Result<()> {
        self.0.push(s.clone());
        Ok(())
    }
}

fn states(scene: &Scenario, name: &str, substeps: usize, dt: f64) -> Vec<State> {
    let sys = scene.build();
    let opts = MethodOptions::default().with_substeps(substeps);
    let mut stepper = Registry::builtin().create(name, &opts).unwrap();
    assert!(stepper.check(&sys).is_ok(), "{name} takes penalty contacts");
    let mut k = Keep(Vec::new());
    let out = run(
        &sys,
        &mut stepper,
        scene.initial_state(),
        &RunPlan::for_duration(dt, 2.0),
        &mut k,
    )
    .unwrap();
    assert!(out.status.is_ok(), "{name}: {:?}", out.status);
    k.0
}

fn max_distance(a: &[State], b: &[State]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| (p.x[0] - q.x[0]).norm())
        .fold(0.0, f64::max)
}

#[test]
fn rapier_with_a_held_penalty_force_is_symplectic_euler() {
    let scene = Scenario::from_file("scenarios/bounce_penalty.toml").unwrap();
    let mut frozen = Vec::new();
    for dt in [5e-4, 1e-4] {
        let se = states(&scene, "symplectic_euler", 1, dt);
        let one = states(&scene, "rapier_impulse", 1, dt);
        let d = max_distance(&one, &se);
        assert!(
            d <= 1e-12,
            "dt {dt}: one substep is {d:e} m from symplectic Euler"
        );
        let four = states(&scene, "rapier_impulse", 4, dt);
        frozen.push(max_distance(&four, &se));
    }
    // 5e-4 → 1e-4: a first-order departure shrinks about fivefold (2.5–10 accepted).
    let ratio = frozen[0] / frozen[1];
    assert!(
        frozen[1] > 0.0 && (2.5..=10.0).contains(&ratio),
        "{frozen:?}"
    );
}
