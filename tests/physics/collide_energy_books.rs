//! Energy books that cannot hide anything.
//!
//! Oracles: the definitions. `dissipated` is work against dampers, drag, friction and inelastic
//! contact: it starts at 0 and never decreases, so it is never negative; energy a contact stage
//! creates is booked apart in `created` (≥ 0, never decreasing). A compliant constraint of
//! compliance α is a spring of stiffness 1/α, so it stores ½·stretch²/α, computed here from
//! the positions alone.

use springlab::method::MethodOptions;
use springlab::method::Registry;
use springlab::model::State;
use springlab::run::{run, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

/// Checks the books at every accepted step.
#[derive(Default)]
struct Books {
    last: Option<EnergyRecord>,
    worst: Option<String>,
    created: f64,
}

impl Observer for Books {
    fn observe(&mut self, step: u64, _s: &State, e: &EnergyRecord) -> springlab::error::Result<()> {
        let (d0, c0) = self.last.map_or((0.0, 0.0), |l| (l.dissipated, l.created));
        if self.worst.is_none() && (e.dissipated < d0 || e.created < c0) {
            self.worst = Some(format!(
                "step {step}: dissipated {d0} -> {}, created {c0} -> {}",
                e.dissipated, e.created
            ));
        }
        self.created = e.created;
        self.last = Some(*e);
        Ok(())
    }
}

#[test]
fn dissipated_never_decreases_in_any_shipped_obstacle_scene_with_any_method() {
    let dir = format!("{}/scenarios", env!("CARGO_MANIFEST_DIR"));
    let mut scenes: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenes.sort();
    let mut checked = 0;
    for path in scenes {
        let scene = Scenario::from_file(&path).unwrap();
        if scene.collision.is_none() {
            continue;
        }
        let sys = scene.build();
        let dt = scene.run.dt.unwrap_or(1e-3);
        let duration = scene.run.duration.unwrap_or(1.0);
        for m in Registry::builtin().iter() {
            let mut stepper = m.create(&MethodOptions::default());
            if stepper.check(&sys).is_err() {
                continue;
            }
            // An engine whose modelled run would take minutes (the FEM soft body on the cloth
            // on a sphere) is left to the report; every other method runs the whole scene.
            let plan = RunPlan::for_duration(dt, duration);
            if stepper
                .modelled_frame_seconds(&sys)
                .is_some_and(|f| f * plan.steps as f64 > 5.0)
            {
                continue;
            }
            let mut books = Books::default();
            let out = run(&sys, &mut stepper, scene.initial_state(), &plan, &mut books).unwrap();
            let name = format!("{} / {}", scene.name, m.info.name);
            assert!(books.worst.is_none(), "{name}: {}", books.worst.unwrap());
            assert!(out.final_energy.dissipated >= 0.0, "{name}");
            checked += 1;
        }
    }
    assert!(checked >= 40, "only {checked} runs");
}

#[test]
fn the_rough_incline_books_no_negative_dissipation() {
    // A user's case: rk4 on the 30° e = 0.5 μ = 0.2 incline reached dissipated = −0.42 J.
    let scene = Scenario::from_toml_str(
        r#"
        [world]
        gravity = [0.0, -9.81, 0.0]
        [[particle]]
        position = [0.0, 0.0, 0.0]
        mass = 0.1
        [[obstacle]]
        shape = "plane"
        point = [0.0, 0.0, 0.0]
        normal = [-0.5, 0.8660254037844386, 0.0]
        friction = 0.2
        restitution = 0.5
        "#,
        "incline.toml",
    )
    .unwrap();
    let sys = scene.build();
    for name in ["rk4", "symplectic_euler", "velocity_verlet"] {
        let mut stepper = Registry::builtin()
            .create(name, &MethodOptions::default())
            .unwrap();
        let mut books = Books::default();
        let out = run(
            &sys,
            &mut stepper,
            scene.initial_state(),
            &RunPlan::new(1e-3, 1000),
            &mut books,
        )
        .unwrap();
        assert!(books.worst.is_none(), "{name}: {}", books.worst.unwrap());
        // Friction work over s = a t²/2 with a = g(sin θ − μ cos θ): μ m g cos θ · s.
        let th = 30f64.to_radians();
        let s = 0.5 * 9.81 * (th.sin() - 0.2 * th.cos());
        let friction_work = 0.2 * 0.1 * 9.81 * th.cos() * s;
        let d = out.final_energy.dissipated;
        eprintln!(
            "{name}: dissipated {d} J (friction work {friction_work} J), created {} J",
            books.created
        );
        assert!(d > 0.9 * friction_work, "{name}: dissipated {d} J");
    }
}

#[test]
fn compliant_rods_book_half_stretch_squared_over_compliance() {
    // A user's case: a double pendulum of compliance 1e-4 m/N stored 0.13-0.16 J that was
    // never booked.
    let alpha = 1e-4;
    let scene = Scenario::from_toml_str(
        &format!(
            "[world]\ngravity = [0.0, -9.81, 0.0]\n\
             [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
             [[particle]]\nposition = [1.0, 0.0, 0.0]\nmass = 1.0\n\
             [[particle]]\nposition = [2.0, 0.0, 0.0]\nmass = 1.0\n\
             [[constraint]]\nbetween = [0, 1]\nlength = 1.0\ncompliance = {alpha}\n\
             [[constraint]]\nbetween = [1, 2]\nlength = 1.0\ncompliance = {alpha}\n"
        ),
        "double.toml",
    )
    .unwrap();
    let sys = scene.build();
    let mut stepper = Registry::builtin()
        .create("verlet_constraints", &MethodOptions::default())
        .unwrap();
    let mut s = scene.initial_state();
    let mut peak: f64 = 0.0;
    for _ in 0..2000 {
        stepper.step(&sys, &mut s, 1e-3).unwrap();
        let stretch = |i: usize, j: usize| (s.x[j] - s.x[i]).norm() - 1.0;
        let expected = 0.5 * (stretch(0, 1).powi(2) + stretch(1, 2).powi(2)) / alpha;
        let booked = sys.energy(&s.x, &s.v).elastic;
        assert!(
            (booked - expected).abs() <= 1e-12 * expected.max(1.0),
            "{booked} vs {expected}"
        );
        peak = peak.max(booked);
    }
    eprintln!("compliant double pendulum: peak elastic {peak} J");
    assert!(peak > 1e-2, "the rods never stretched: {peak} J");
}
