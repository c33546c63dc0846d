//! Bring your own integrator: implement `Integrator` for the scheme in your game, build a scene
//! in code, and run it through springlab side by side with the built-in methods.
//!
//! Run with `cargo run --example custom_integrator`.

use springlab::integrate::{Integrator, StepStats};
use springlab::model::{State, System, Vec3};
use springlab::run::{run, NoObserver, RunPlan};
use springlab::scenario::file::{ParticleSpec, RunSpec, ScenarioFile, SpringSpec};
use springlab::scenario::{Scenario, SpringLaw};

/// The "game loop" scheme many engines ship: symplectic Euler with a velocity damping factor
/// per frame (v *= 0.999), which quietly removes energy.
struct GameEuler {
    a: Vec<Vec3>,
}

impl Integrator for GameEuler {
    fn name(&self) -> &str {
        "game_euler"
    }
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> springlab::Result<StepStats> {
        self.a.resize(s.len(), Vec3::zeros());
        sys.accelerations(&s.x, &s.v, &mut self.a);
        for p in 0..s.len() {
            s.v[p] = (s.v[p] + self.a[p] * h) * 0.999;
            s.x[p] += s.v[p] * h;
        }
        s.t += h;
        Ok(StepStats {
            force_evals: 1,
            dissipated: 0.0,
        })
    }
}

fn main() -> springlab::Result<()> {
    // A mass on an anchored spring, built in code (the same scene as scenarios/anchored_spring).
    let particle = |x: f64, fixed: bool| ParticleSpec {
        position: [x, 0.0, 0.0],
        velocity: [0.0; 3],
        mass: 1.0,
        fixed,
        radius: 0.0,
    };
    let scene = Scenario::from_spec(ScenarioFile {
        name: Some("code_spring".into()),
        particle: vec![particle(0.0, true), particle(1.5, false)],
        spring: vec![SpringSpec {
            between: [0, 1],
            stiffness: 4.0,
            rest_length: Some(1.0),
            damping: 0.0,
            law: SpringLaw::Hooke,
        }],
        run: Some(RunSpec {
            dt: Some(1.0 / 60.0),
            duration: Some(10.0),
            ..Default::default()
        }),
        ..Default::default()
    })?;
    let sys = scene.build();
    let plan = RunPlan::for_duration(1.0 / 60.0, 10.0);
    let exact = run(
        &sys,
        springlab::method::create("analytic", &Default::default())?.as_mut(),
        scene.initial_state(),
        &plan,
        &mut NoObserver,
    )?;
    let mut mine: Vec<Box<dyn Integrator>> = vec![Box::new(GameEuler { a: Vec::new() })];
    for name in ["symplectic_euler", "velocity_verlet", "rk4"] {
        mine.push(springlab::method::create(name, &Default::default())?);
    }
    println!(
        "{:<18} {:>14} {:>14}",
        "integrator", "position error", "energy change"
    );
    for integ in mine.iter_mut() {
        let out = run(
            &sys,
            integ.as_mut(),
            scene.initial_state(),
            &plan,
            &mut NoObserver,
        )?;
        let err = (out.final_state.x[1] - exact.final_state.x[1]).norm();
        let de = out.final_energy.total / out.initial_energy.total - 1.0;
        println!("{:<18} {:>14.3e} {:>+14.3e}", integ.name(), err, de);
    }
    Ok(())
}
