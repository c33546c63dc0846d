//! Rapier against the scheme we identified for it (src/rapier/scheme.rs).
mod common;

use springlab::integrate::IntegratorOptions;
use springlab::rapier::scheme_prediction;
use springlab::run::{run, NoObserver, RunPlan};
use springlab::scenario::Scenario;

struct Curve(Vec<(f64, f64)>);
impl springlab::run::Observer for Curve {
    fn observe(
        &mut self,
        _step: u64,
        s: &springlab::model::State,
        e: &springlab::run::EnergyRecord,
    ) -> springlab::Result<()> {
        self.0.push((s.t, e.mechanical()));
        Ok(())
    }
}

fn measured(scene: &Scenario, name: &str, h: f64, n: usize, steps: u64) -> Vec<(f64, f64)> {
    let sys = scene.build();
    let opts = IntegratorOptions { substeps: n, ..Default::default() };
    let mut i = springlab::backend::create(name, &opts).unwrap();
    let mut c = Curve(Vec::new());
    run(&sys, i.as_mut(), scene.initial_state(), &RunPlan::new(h, steps), &mut c).unwrap();
    c.0
}

#[test]
fn explore() {
    let scene = Scenario::from_file("scenarios/two_body.toml").unwrap();
    let sys = scene.build();
    for (h, n) in [(0.01, 4), (1.0 / 60.0, 4), (1.0 / 60.0, 1)] {
        let m = measured(&scene, "rapier_impulse", h, n, 100);
        let p = scheme_prediction(&sys, &scene.initial_state(), h, n, 100).unwrap();
        for k in [1, 10, 100] {
            eprintln!("h {h} n {n} step {k}: measured {} predicted {}", m[k].1, p.curve[k].1);
        }
    }
}
