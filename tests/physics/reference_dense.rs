//! One adaptive reference per scene and horizon, sampled anywhere by its dense output.
//!
//! Oracles: the undamped anchored spring's closed form u(t) = u₀ cos ωt (ω = √k for 1 kg),
//! and after an impulse Δv at τ the same oscillator's closed form from the state at τ
//! (u(τ) cos ω(t−τ) + (u̇(τ) + Δv)/ω sin ω(t−τ)); the sharing oracle is the identity of the
//! solve two grids were sampled from.

use crate::common::oscillator;
use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::{Reference, ReferenceSolver};
use springlab::scenario::Scenario;

const K: f64 = 4.0;
const U0: f64 = 0.1;

fn adaptive(scene: &Scenario, grids: &[TimeGrid], horizon: f64) -> Reference {
    let sys = scene.build();
    Reference::compute_with(
        &sys,
        &scene.initial_state(),
        grids,
        horizon,
        ReferenceSolver::Adaptive,
    )
    .unwrap()
}

/// The largest distance of the reference's moving particle from `exact(t)` (its x coordinate,
/// the spring's axis) and the largest ratio of that distance to the stated uncertainty.
fn worst(r: &Reference, g: usize, exact: impl Fn(f64) -> f64) -> (f64, f64) {
    let grid = r.grids[g];
    let (mut err, mut ratio) = (0.0_f64, 0.0_f64);
    for n in grid.sample_steps() {
        let x = r.positions(g, n).unwrap()[1];
        let e = (x.x - exact(grid.time(n)))
            .abs()
            .max(x.y.abs())
            .max(x.z.abs());
        err = err.max(e);
        ratio = ratio.max(e / r.uncertainty_at(g, n));
    }
    (err, ratio)
}

#[test]
fn dense_samples_meet_the_closed_form_between_solver_steps() {
    // A grid step (0.0123 s) unrelated to the solver's steps: nearly every sample falls
    // inside a step.
    let scene = oscillator(K, 0.0, U0, 0.0);
    let grid = TimeGrid::new(0.0123, 400, 400);
    let r = adaptive(&scene, &[grid], grid.time(grid.steps));
    let w = K.sqrt();
    let (err, ratio) = worst(&r, 0, |t| 1.0 + U0 * (w * t).cos());
    eprintln!(
        "oscillator: worst error {err:e} m, worst error / stated uncertainty {ratio:.3}, uncertainty {:e} m",
        r.info.uncertainty
    );
    assert!(
        ratio <= 1.0,
        "an error past the stated uncertainty: {ratio}"
    );
    // Not absurdly loose: the errors and the stated uncertainty are within a hundred times
    // the looser companion's tolerance (1e-10 at a length scale of 1.1 m).
    assert!(err < 1e-10, "error {err:e}");
    assert!(
        r.info.uncertainty < 1e-8,
        "uncertainty {:e}",
        r.info.uncertainty
    );
}

#[test]
fn no_sample_interpolates_across_an_impulse() {
    // Impulse Δv = 0.3 m/s at τ = 0.5 s. The sample at τ is the state just before it (as
    // the runner samples it); the sample 1 µs later is on the far side.
    let tau = 0.5;
    let dv = 0.3;
    let toml = format!(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[{x},0.0,0.0]\nmass=1.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness={K}\nrest_length=1.0\n\
         [[impulse]]\ntime={tau}\nparticle=1\ndelta_v=[{dv},0.0,0.0]\n",
        x = 1.0 + U0
    );
    let scene = Scenario::from_toml_str(&toml, "kicked.toml").unwrap();
    let at = TimeGrid {
        dt: tau,
        steps: 2,
        stride: 1,
    };
    let after = TimeGrid {
        dt: tau + 1e-6,
        steps: 1,
        stride: 1,
    };
    let r = adaptive(&scene, &[at, after], 1.0);
    let w = K.sqrt();
    let (u_tau, v_tau) = (U0 * (w * tau).cos(), -U0 * w * (w * tau).sin());
    let exact = |t: f64| {
        if t <= tau {
            1.0 + U0 * (w * t).cos()
        } else {
            let s = t - tau;
            1.0 + u_tau * (w * s).cos() + (v_tau + dv) / w * (w * s).sin()
        }
    };
    let (err_at, ratio_at) = worst(&r, 0, exact);
    let (err_after, ratio_after) = worst(&r, 1, exact);
    eprintln!(
        "impulse: at τ {err_at:e} m ({ratio_at:.3}), just after {err_after:e} m ({ratio_after:.3})"
    );
    assert!(ratio_at <= 1.0 && err_at < 1e-10, "at τ: {err_at:e}");
    assert!(
        ratio_after <= 1.0 && err_after < 1e-10,
        "after τ: {err_after:e}"
    );
}

#[test]
fn one_solve_serves_every_grid_of_a_scene_and_horizon() {
    // A scene no other test builds (its stiffness), so the first request solves it.
    let scene = oscillator(3.7, 0.0, U0, 0.0);
    let coarse = TimeGrid::new(0.1, 20, 20);
    let fine = TimeGrid::new(0.0037, 500, 500);
    let a = adaptive(&scene, &[coarse], 2.0);
    let b = adaptive(&scene, &[fine], 2.0);
    let id = a.solve_id().expect("an adaptive reference keeps its solve");
    assert_eq!(b.solve_id(), Some(id), "the second grid solved again");
    assert_eq!(a.info.solver_evals, b.info.solver_evals);
    // The same time on both grids is the same bits (t = 0.37 s: coarse has no such step, so
    // compare the fine grid with a reference of both grids at once).
    let both = adaptive(&scene, &[coarse, fine], 2.0);
    assert_eq!(both.solve_id(), Some(id));
    for n in fine.sample_steps() {
        assert_eq!(both.positions(1, n), b.positions(0, n));
    }
    // Its twin: another horizon is another solve.
    let c = adaptive(&scene, &[coarse], 2.5);
    assert!(c.solve_id().is_some_and(|other| other != id));
}
