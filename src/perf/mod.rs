//! Scenes and timing helpers shared by the criterion benches and `springlab bench-scaling`.

mod baseline;
pub mod ratios;
pub mod stencil;

pub use baseline::hand_step;

use crate::error::Result;
use crate::integrate::Stepper;
use crate::method::MethodOptions;
use crate::scenario::Scenario;
use std::time::Instant;

/// A horizontal `n`×`n` cloth (1 m², 1 g per particle, k = 200 N/m, light axial damping,
/// gravity, two top corners pinned) with structural and shear springs only: about 4n² springs,
/// the benchmark scene (100×100 gives 39 402 springs).
pub fn cloth(n: usize) -> Scenario {
    let toml = format!(
        "name = \"cloth_{n}x{n}\"\n[world]\ngravity = [0.0, -9.81, 0.0]\n[[cloth]]\n\
         origin = [0.0, 0.0, 0.0]\nsize = [1.0, 1.0]\ncount = [{n}, {n}]\nmass = 0.001\n\
         stiffness = 200.0\ndamping = 0.002\nplane = \"xz\"\nfix = [\"top_left\", \"top_right\"]\n"
    );
    Scenario::from_toml_str(&toml, format!("cloth_{n}x{n}.toml")).expect("generated cloth is valid")
}

/// Time step each method is timed at: implicit methods and physics engines at a frame
/// (1/60 s; registry facts [`crate::method::MethodInfo::implicit`] and `engine`), explicit
/// methods at 1 ms (the cloth's stable step; cost per step does not depend on it, stability
/// over the timed steps does).
pub fn bench_dt(name: &str) -> f64 {
    if crate::method::Registry::builtin()
        .info(name)
        .is_ok_and(|m| m.implicit || m.engine)
    {
        1.0 / 60.0
    } else {
        1e-3
    }
}

/// Methods the scaling benchmarks leave out, with why: a cloth is not a tree, so
/// `rapier_multibody` falls back to impulse joints around its trees, and its step took 57 ms
/// on an 8×8 cloth, too slow to scale.
pub const NOT_SCALED: [(&str, &str); 1] = [(
    crate::rapier::MULTIBODY,
    "a cloth is not a tree: 57 ms per step on an 8×8 cloth",
)];

/// Every method that can step `scene`: native and engine methods whose
/// `check` accepts it (`analytic` refuses cloths), except [`NOT_SCALED`].
pub fn methods_for(scene: &Scenario) -> Vec<&'static str> {
    let sys = scene.build();
    crate::method::Registry::builtin()
        .names()
        .into_iter()
        .filter(|n| NOT_SCALED.iter().all(|(left_out, _)| left_out != n))
        .filter(|n| {
            crate::method::create(n, &MethodOptions::default())
                .map(|i| i.check(&sys).is_ok())
                .unwrap_or(false)
        })
        .collect()
}

/// Wall time of one step (s): the minimum over `reps` repetitions of `steps` steps each, every
/// repetition starting from the scene's initial state (so runs that grow unstable restart).
pub fn time_per_step(
    scene: &Scenario,
    stepper: &mut dyn Stepper,
    dt: f64,
    steps: usize,
    reps: usize,
) -> Result<f64> {
    let sys = scene.build();
    let s0 = scene.initial_state();
    let mut best = f64::INFINITY;
    let mut s = s0.clone();
    stepper.step(&sys, &mut s, dt)?; // warm-up: scratch buffers, caches
    for _ in 0..reps.max(1) {
        s.clone_from(&s0);
        stepper.reset();
        let t0 = Instant::now();
        for _ in 0..steps.max(1) {
            stepper.step(&sys, &mut s, dt)?;
        }
        best = best.min(t0.elapsed().as_secs_f64() / steps.max(1) as f64);
    }
    Ok(best)
}
