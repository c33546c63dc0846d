//! Honest verdicts: the runner's one verdict on examples users
//! measured, with oracles nobody tuned here.
//!
//! - The blown-up rope: symplectic Euler is stable on a chain only for h·ω_max < 2 (Hairer,
//!   Lubich & Wanner, GNI §I.1); ω_max < 2√(k/m) = 126.5 rad/s for k = 200 N/m, 50 g beads,
//!   so dt = 0.0164 s (hω ≈ 2.07) must blow up and dt = 0.008 s (hω ≈ 1.01) must not.
//! - The incline: an undamped, unforced particle never raises its energy balance; held by
//!   static friction (μ = 1 > tan 30°) it stays at rest, without friction it slides and
//!   trades potential for kinetic energy. Either way a correct verdict says ok.
//! - The map: on a linear oscillator the energy of a mode grows like ρ²ⁿ over n steps, so a
//!   cell whose one-step spectral radius exceeds 1.01 cannot stay bounded over the map's
//!   ≥ 1389 steps (1.01^2778 > 1e12) from a seed holding ~1e-8 of the energy. Exact on a
//!   linear scene; on the nonlinear hanging spring only for the modes that keep
//!   their stiffness (see the test).
//! - Short runs: an exact solution keeps its energy balance constant, so a balance that
//!   multiplies tenfold over each octave of a run's length is growing (ρ²ⁿ), while a bounded
//!   swing rises at most like sin² from its start (×4 an octave): symplectic Euler and
//!   velocity Verlet at 0.9 of hω = 2 (GNI §I.1) stay bounded over 40 steps and 20 000.

use springlab::measure::stability::{
    decide, stability_map, CellDecidedBy, MapConfig, GROWTH_SHOWN, MAP_MIN_STEPS, RHO_SHOWN,
};
use springlab::run::{run, NoObserver, RunPlan, Status};
use springlab::scenario::Scenario;

use crate::common;

const ROPE: &str = r#"
name = "rope30"
[world]
gravity = [0.0, -9.81, 0.0]
[[chain]]
start = [0.0, 0.0, 0.0]
end = [1.45, 0.0, 0.0]
count = 30
mass = 0.05
stiffness = 200.0
fix = ["first"]
[run]
dt = 0.0164
duration = 2.0
"#;

fn incline(friction: f64) -> Scenario {
    let toml = format!(
        r#"
name = "incline"
[world]
gravity = [0.0, -9.81, 0.0]
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
[[obstacle]]
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [-0.5, 0.8660254037844386, 0.0]
friction = {friction}
[run]
dt = 0.01
duration = 1.0
"#
    );
    Scenario::from_toml_str(&toml, "incline.toml").unwrap()
}

#[test]
fn the_blown_up_rope_is_not_ok_and_the_stable_rope_is() {
    let scene = Scenario::from_toml_str(ROPE, "rope30.toml").unwrap();
    let out = common::run_steps(&scene, "symplectic_euler", 0.0164, 122);
    match &out.status {
        Status::Unstable { step, time, reason } => {
            eprintln!("rope at dt = 0.0164 s: unstable at step {step}, t = {time} s: {reason}");
            assert!(reason.contains(" J"), "the reason is in joules: {reason}");
        }
        Status::Ok => panic!(
            "blown-up rope called ok: energy {} J -> {} J",
            out.initial_energy.total, out.final_energy.total
        ),
    }
    let fine = common::run_steps(&scene, "symplectic_euler", 0.008, 250);
    assert!(fine.status.is_ok(), "{:?}", fine.status);
}

#[test]
fn a_particle_on_an_incline_is_ok_for_every_method() {
    for friction in [1.0, 0.0] {
        let scene = incline(friction);
        let sys = scene.build();
        for name in [
            "explicit_euler",
            "symplectic_euler",
            "velocity_verlet",
            "rk4",
            "implicit_euler",
            "rapier_impulse",
        ] {
            let mut stepper = common::stepper(name);
            let out = run(
                &sys,
                &mut stepper,
                scene.initial_state(),
                &RunPlan::new(0.01, 100),
                &mut NoObserver,
            )
            .unwrap();
            assert!(
                out.status.is_ok(),
                "{name}, friction {friction}: {:?}",
                out.status
            );
        }
    }
}

/// Rows of the default map of `scene` whose spectral radius exceeds `rho_min`, with how
/// many of them were called stable (printed).
fn map_cells_above(scene: &Scenario, rho_min: f64) -> (usize, usize) {
    let rows = stability_map(scene, &MapConfig::default()).unwrap();
    let (mut above, mut stable) = (0, 0);
    for r in &rows {
        if r.spectral_radius.is_some_and(|rho| rho > rho_min) {
            above += 1;
            if r.stable {
                stable += 1;
                eprintln!(
                    "{} at k×{}, hω = {}: ρ = {:?} called stable",
                    r.method, r.stiffness_scale, r.h_omega, r.spectral_radius
                );
            }
        }
    }
    (above, stable)
}

const SPRING: &str = r#"
[world]
gravity = [0.0, -9.81, 0.0]
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true
[[particle]]
position = [0.0, -1.5, 0.0]
mass = 1.0
[[spring]]
between = [0, 1]
stiffness = 1e4
rest_length = 1.0
damping = 20.0
[run]
dt = 0.001
duration = 1.0
"#;

#[test]
fn no_map_cell_with_a_spectral_radius_above_1_01_is_stable() {
    assert_eq!(
        MAP_MIN_STEPS,
        (GROWTH_SHOWN.ln() / (2.0 * RHO_SHOWN.ln())).ceil() as u64
    );
    // The damped spring (1 kg, k = 1e4 N/m, c = 20 N·s/m) made exactly linear, where
    // the theory applies to the whole run: zero rest length (f = −k d in every direction) and
    // the damping as isotropic drag.
    let linear = SPRING
        .replace("rest_length = 1.0\ndamping = 20.0", "rest_length = 0.0")
        .replace("[world]\n", "[world]\ndrag = 20.0\n");
    assert!(linear.contains("drag = 20.0") && linear.contains("rest_length = 0.0"));
    let scene = Scenario::from_toml_str(&linear, "linear_damped_spring.toml").unwrap();
    let (above, stable) = map_cells_above(&scene, RHO_SHOWN);
    assert!(above > 50, "the map must reach unstable cells: {above}");
    assert_eq!(stable, 0, "cells with ρ > {RHO_SHOWN} called stable");
}

#[test]
fn the_stretched_hanging_spring_map_calls_no_growing_cell_stable() {
    // The scene as written: a 1 m spring hanging 0.5 m stretched. Linearised at that
    // stretched start, its transverse mode is stiff (ω² = T/(mL) ≈ 3300 /s² at k×1), but the
    // tension relaxes within about 1/(ζω) = 0.1 s and the mode with it, so cells whose only
    // ρ > 1 is that mode's (ρ ≤ 1.04) can stay bounded: the theory at t = 0 does not apply
    // there. The cells once called stable (ρ 1.13 to 1.75) grow on the axial mode,
    // which keeps its stiffness: none may read stable.
    let scene = Scenario::from_toml_str(SPRING, "damped_spring_stiff.toml").unwrap();
    let (above, stable) = map_cells_above(&scene, 1.05);
    assert!(above > 50, "the map must reach unstable cells: {above}");
    assert_eq!(stable, 0, "cells with ρ > 1.05 called stable");
}

/// A soft cloth of `n`×`n` particles of 0.1 g (1 m², k = 100 N/m, c = 0.01 N·s/m) pinned at
/// two corners, falling flat under gravity.
fn soft_cloth(n: usize) -> Scenario {
    let toml = format!(
        "name = \"soft_cloth\"\n[world]\ngravity = [0.0, -9.81, 0.0]\n[[cloth]]\n\
         origin = [0.0, 0.0, 0.0]\nsize = [1.0, 1.0]\ncount = [{n}, {n}]\nmass = 0.0001\n\
         stiffness = 100.0\ndamping = 0.01\nplane = \"xz\"\nfix = [\"top_left\", \"top_right\"]\n\
         [run]\ndt = 0.016666666666666666\nsteps = 40\n"
    );
    Scenario::from_toml_str(&toml, "soft_cloth.toml").unwrap()
}

#[test]
fn a_cloth_whose_balance_grows_over_forty_frames_is_unstable() {
    // Rapier's impulse joints at 60 Hz with its own 4 substeps on the soft cloth: the balance
    // (constant for the exact solution) rises from 0 to tens of scene scales within 40 frames,
    // tenfold and more over each octave of the run (measured: 1.2e-3, 3.3e-2, 1.3, 15.8 J at
    // frames 4, 7, 14, 27 on a scale of 1.4 J), springs stretched to strain 4. Too short for
    // the windows of rule 3 or 4, too low for the cap: only the run-length rule sees it.
    let scene = soft_cloth(32);
    let sys = scene.build();
    let out = |substeps| {
        let mut opts = springlab::method::MethodOptions::default();
        opts.substeps = substeps;
        let mut stepper = springlab::method::create("rapier_impulse", &opts).unwrap();
        run(
            &sys,
            &mut stepper,
            scene.initial_state(),
            &RunPlan::new(1.0 / 60.0, 40),
            &mut NoObserver,
        )
        .unwrap()
    };
    let coarse = out(4);
    match &coarse.status {
        Status::Unstable { reason, .. } => {
            assert!(reason.contains("over the whole run"), "{reason}")
        }
        Status::Ok => panic!(
            "growing cloth called ok: balance {} J",
            coarse.final_energy.total
        ),
    }
    // Twin: the same 40 frames at 16 substeps stay within the scene's energy scale: ok.
    let fine = out(16);
    assert!(fine.status.is_ok(), "{:?}", fine.status);
}

#[test]
fn bounded_swings_near_the_limit_read_ok_short_and_long() {
    // Oracle: hω < 2 for symplectic Euler and velocity Verlet (GNI §I.1). A spring pair of
    // 1 kg and 3 kg (ω² = k(1/m₁ + 1/m₂)), stretched by 0.1 m, at 0.9 of the limit: bounded,
    // over a run shorter than any window and over a long one; at 1.1 unstable within 40 steps.
    let scene = Scenario::from_toml_str(
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\n\
         [[particle]]\nposition = [1.1, 0.0, 0.0]\nmass = 3.0\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = 50.0\nrest_length = 1.0\n",
        "pair.toml",
    )
    .unwrap();
    let w = (50.0f64 * (1.0 + 1.0 / 3.0)).sqrt();
    for m in ["symplectic_euler", "velocity_verlet"] {
        for steps in [8, 40, 20_000] {
            let out = common::run_steps(&scene, m, 0.9 * 2.0 / w, steps);
            assert!(out.status.is_ok(), "{m}, {steps} steps: {:?}", out.status);
        }
        let out = common::run_steps(&scene, m, 1.1 * 2.0 / w, 40);
        assert!(!out.status.is_ok(), "{m} at 1.1 × its limit read ok");
    }
}

#[test]
fn no_map_cell_contradicts_its_spectral_radius_without_saying_so() {
    // Oracle: the spectral radius ρ of the one-step map. Where a cell's verdict differs from
    // ρ ≤ 1, or from its run's, it names the measure that decided and why.
    let scene = Scenario::from_toml_str(SPRING, "damped_spring_stiff.toml").unwrap();
    let cfg = MapConfig {
        common: springlab::measure::Common {
            methods: vec!["explicit_euler".into(), "rk4".into()],
            ..Default::default()
        },
        ..Default::default()
    };
    for r in stability_map(&scene, &cfg).unwrap() {
        let Some(rho) = r.spectral_radius else {
            continue;
        };
        if r.stable != r.run_stable {
            assert!(!r.note.is_empty(), "{r:?}");
        }
        // Away from round-off in the identified radius, a verdict against it is the run's.
        if (rho - 1.0).abs() > 1e-9 && r.stable != (rho < 1.0) {
            assert_eq!(r.decided_by, CellDecidedBy::Run, "{r:?}");
            assert!(!r.note.is_empty(), "{r:?}");
        }
    }
    // The decision itself: ρ = 1.0113 with a bounded run that still has ρ > 1 at its end is
    // unstable by the radius; ρ = 0.9976 with a run that grew is unstable by the run; a
    // radius that is gone at the run's end leaves the bounded run stable, saying so.
    let (stable, by, note) = decide(Some((false, 1.0113)), true, 2000, || 1.0113);
    assert!(!stable && by == CellDecidedBy::SpectralRadius && !note.is_empty());
    let (stable, by, note) = decide(Some((true, 0.9976)), false, 2000, || unreachable!());
    assert!(!stable && by == CellDecidedBy::Run && note.contains("grew"));
    let (stable, by, note) = decide(Some((false, 1.04)), true, 2000, || 0.999);
    assert!(stable && by == CellDecidedBy::Run && note.contains("moved away"));
    // Twin: agreement needs no note.
    assert_eq!(
        decide(Some((true, 0.99)), true, 2000, || unreachable!()),
        (true, CellDecidedBy::SpectralRadius, String::new())
    );
}
