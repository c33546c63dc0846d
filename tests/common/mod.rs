//! Helpers shared by the integration tests.
#![allow(dead_code)]

use springlab::method::{Instance, MethodOptions};
use springlab::model::{State, System};
use springlab::run::{run, NoObserver, RunOutcome, RunPlan};
use springlab::scenario::Scenario;

/// The anchored spring: 1 kg on k = `k` N/m, rest length 1, started at x = 1 + `u0`, speed `v0`,
/// axial damping `c`. ω = √k, displacement u = x − 1.
pub fn oscillator(k: f64, c: f64, u0: f64, v0: f64) -> Scenario {
    let toml = format!(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[{x},0.0,0.0]\nvelocity=[{v0},0.0,0.0]\nmass=1.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness={k}\nrest_length=1.0\ndamping={c}\n",
        x = 1.0 + u0
    );
    Scenario::from_toml_str(&toml, "oscillator.toml").expect("valid oscillator")
}

/// A fresh stepper of the method `name`, with default options.
pub fn stepper(name: &str) -> Instance {
    springlab::method::create(name, &MethodOptions::default()).expect("known method")
}

/// Runs `name` on `scene` for `steps` of `dt` with no observer.
pub fn run_steps(scene: &Scenario, name: &str, dt: f64, steps: u64) -> RunOutcome {
    let sys = scene.build();
    let mut i = stepper(name);
    run(
        &sys,
        &mut i,
        scene.initial_state(),
        &RunPlan::new(dt, steps),
        &mut NoObserver,
    )
    .expect("run")
}

/// Steps `name` by hand `steps` times (no runner), returning the state.
pub fn step_n(sys: &System, s0: &State, name: &str, h: f64, steps: usize) -> State {
    let mut i = stepper(name);
    let mut s = s0.clone();
    for _ in 0..steps {
        i.step(sys, &mut s, h).expect("step");
    }
    s
}

/// Least-squares slope of log(err) against log(h).
pub fn loglog_slope(h: &[f64], err: &[f64]) -> f64 {
    let xs: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let ys: Vec<f64> = err.iter().map(|v| v.ln()).collect();
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}
