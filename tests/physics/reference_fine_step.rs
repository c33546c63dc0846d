//! The fine-step reference (projection contacts): one hierarchy of fine steps per scene and
//! horizon, sampled by every grid between its steps.
//!
//! Oracles: the anchored spring's closed form u(t) = u₀ cos ωt (ω = √k for 1 kg) for a scene
//! whose projection plane the particle never reaches; free fall y₀ − g t²/2 for a ball before it
//! first meets its projection plane (at t = √(2(y₀ − r)/g)); the sharing oracle is the identity
//! of the hierarchy two grids were sampled from and the bits of each.

use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::finestep::FINE_AGREEMENT;
use springlab::measure::reference::Reference;
use springlab::scenario::Scenario;

const U0: f64 = 0.1;
const G: f64 = 9.81;

/// 1 kg on a spring of stiffness `k` from a fixed anchor, from rest at x = 1 + u₀, with a
/// projection plane at y = −1 it never touches.
fn plane_oscillator(k: f64) -> Scenario {
    let toml = format!(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[{x},0.0,0.0]\nmass=1.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness={k}\nrest_length=1.0\n\
         [[obstacle]]\nshape=\"plane\"\npoint=[0.0,-1.0,0.0]\nnormal=[0.0,1.0,0.0]\n\
         [collision]\nresponse=\"projection\"\n",
        x = 1.0 + U0
    );
    Scenario::from_toml_str(&toml, "plane_oscillator.toml").unwrap()
}

fn reference(scene: &Scenario, grids: &[TimeGrid], horizon: f64) -> Reference {
    Reference::compute(&scene.build(), &scene.initial_state(), grids, horizon).unwrap()
}

#[test]
fn samples_between_fine_steps_meet_the_closed_form_within_their_uncertainty() {
    // A grid step (12.3 ms) off the levels' lattice: nearly every sample is interpolated.
    let k: f64 = 400.0;
    let scene = plane_oscillator(k);
    let grid = TimeGrid::new(0.0123, 160, 160);
    let r = reference(&scene, &[grid], grid.time(grid.steps));
    assert_eq!(r.info.kind.name(), "fine_step");
    let w = k.sqrt();
    let (mut err, mut ratio) = (0.0_f64, 0.0_f64);
    for n in grid.sample_steps() {
        let t = grid.time(n);
        let x = r.positions(0, n).unwrap()[1];
        let e = (x.x - 1.0 - U0 * (w * t).cos())
            .abs()
            .max(x.y.abs())
            .max(x.z.abs());
        err = err.max(e);
        ratio = ratio.max(e / r.uncertainty_at(0, n));
    }
    eprintln!(
        "plane oscillator: worst error {err:e} m, worst error / stated uncertainty {ratio:.3}, uncertainty {:e} m ({})",
        r.info.uncertainty, r.info.description
    );
    assert!(
        ratio <= 1.0,
        "an error past the stated uncertainty: {ratio}"
    );
    // Not absurdly loose: refinement stopped when two levels agreed to FINE_AGREEMENT x the
    // motion scale at the coarser level's steps, so the stated uncertainty stays near that.
    assert!(
        r.info.uncertainty <= 2.0 * FINE_AGREEMENT * r.motion_scale(),
        "uncertainty {:e}",
        r.info.uncertainty
    );
}

#[test]
fn samples_before_the_first_contact_are_free_fall() {
    // A grid step (12.3 ms) off the levels' lattice: the samples in flight are interpolated.
    let (y0, radius) = (1.1, 0.1);
    let toml = format!(
        "[world]\ngravity=[0.0,-{G},0.0]\n\
         [[particle]]\nposition=[0.0,{y0},0.0]\nmass=1.0\nradius={radius}\n\
         [[obstacle]]\nshape=\"plane\"\npoint=[0.0,0.0,0.0]\nnormal=[0.0,1.0,0.0]\nrestitution=0.5\n\
         [collision]\nresponse=\"projection\"\n"
    );
    let scene = Scenario::from_toml_str(&toml, "ball.toml").unwrap();
    let grid = TimeGrid::new(0.0123, 100, 100);
    let r = reference(&scene, &[grid], grid.time(grid.steps));
    let contact = (2.0 * (y0 - radius) / G).sqrt();
    let mut compared = 0;
    for n in grid.sample_steps().filter(|&n| grid.time(n) < contact) {
        let t = grid.time(n);
        let y = r.positions(0, n).unwrap()[0].y;
        // rk4 and the cubic interpolant are both exact for free fall: what is left is
        // round-off, under one rounding of the height (~2.4e-16 m) per fine step for the
        // few thousand steps before the contact.
        let e = (y - (y0 - 0.5 * G * t * t)).abs();
        assert!(e < 1e-12, "t = {t}: off free fall by {e:e}");
        compared += 1;
    }
    assert!(compared > 30);
}

#[test]
fn one_hierarchy_serves_every_grid_of_a_scene_and_horizon() {
    // A scene no other test builds (its stiffness), so the first request makes it.
    let scene = plane_oscillator(37.0);
    let coarse = TimeGrid::new(0.1, 20, 20);
    let fine = TimeGrid::new(0.0037, 500, 500);
    let a = reference(&scene, &[coarse], 2.0);
    let b = reference(&scene, &[fine], 2.0);
    let id = a
        .solve_id()
        .expect("a fine-step reference keeps its hierarchy");
    assert_eq!(
        b.solve_id(),
        Some(id),
        "the second grid ran its levels again"
    );
    assert_eq!(a.info.solver_evals, b.info.solver_evals);
    // The same time on both grids is the same bits: the fine grid alone and with the coarse.
    let both = reference(&scene, &[coarse, fine], 2.0);
    assert_eq!(both.solve_id(), Some(id));
    for n in fine.sample_steps() {
        assert_eq!(both.positions(1, n), b.positions(0, n));
        assert_eq!(both.uncertainty_at(1, n), b.uncertainty_at(0, n));
    }
    // Its twin: another horizon is another hierarchy.
    let c = reference(&scene, &[coarse], 2.5);
    assert!(c.solve_id().is_some_and(|other| other != id));
}
