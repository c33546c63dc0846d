//! Helpers shared by the Rapier tests (tests/physics/rapier_*.rs).
#![allow(dead_code)]

use springlab::method::MethodOptions;
use springlab::model::{State, Vec3};
use springlab::run::{run, EnergyRecord, Observer, RunOutcome, RunPlan};
use springlab::scenario::Scenario;

/// Records (t, mechanical energy) and the positions of every particle at every frame.
#[derive(Default)]
pub struct Record {
    /// (t, K + G + E).
    pub energy: Vec<(f64, f64)>,
    /// Positions per frame.
    pub x: Vec<Vec<Vec3>>,
    /// Velocities per frame.
    pub v: Vec<Vec<Vec3>>,
}

impl Observer for Record {
    fn observe(&mut self, _step: u64, s: &State, e: &EnergyRecord) -> springlab::Result<()> {
        self.energy.push((s.t, e.mechanical()));
        self.x.push(s.x.clone());
        self.v.push(s.v.clone());
        Ok(())
    }
}

/// Runs method `name` with `substeps` on `scene` for `steps` frames of `h`, recording.
pub fn record(
    scene: &Scenario,
    name: &str,
    h: f64,
    substeps: usize,
    steps: u64,
) -> (Record, RunOutcome) {
    let sys = scene.build();
    let opts = MethodOptions::default().with_substeps(substeps);
    let mut i = springlab::method::create(name, &opts).expect("method");
    i.check(&sys).expect("method accepts the scene");
    let mut rec = Record::default();
    let out = run(
        &sys,
        &mut i,
        scene.initial_state(),
        &RunPlan::new(h, steps),
        &mut rec,
    )
    .expect("run");
    (rec, out)
}

/// Times at which `f` crosses zero upwards (linear interpolation between frames).
pub fn upward_crossings(t: &[f64], f: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for k in 1..f.len() {
        if f[k - 1] < 0.0 && f[k] >= 0.0 {
            let a = f[k - 1] / (f[k - 1] - f[k]);
            out.push(t[k - 1] + a * (t[k] - t[k - 1]));
        }
    }
    out
}

/// Complete elliptic integral of the first kind K(k) = π / (2 AGM(1, √(1−k²))), by the
/// arithmetic-geometric mean (Abramowitz & Stegun 17.6).
pub fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    while (a - b).abs() > 1e-15 * a {
        let an = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = an;
    }
    std::f64::consts::PI / (2.0 * a)
}

/// The two methods.
pub const METHODS: [&str; 2] = ["rapier_impulse", "rapier_multibody"];
