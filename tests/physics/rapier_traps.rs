//! Regression tests for the Rapier 0.36 traps springlab works around, each with its oracle.
use crate::common;
use crate::rapier_support;
use rapier_support::*;
use springlab::rapier::internals::rapier3d_f64::prelude::*;
use springlab::rapier::internals::{build, particle_collider, spring_joint};
use springlab::rapier::Mode;
use springlab::scenario::Scenario;

/// Trap: generic-joint motors default to the acceleration-based model, which multiplies k and c
/// by the effective mass. Oracle: a 4 kg mass on k = 1 N/m oscillates with T = 2π·√(m/k) = 4π s
/// (acceleration-based would give 2π s).
#[test]
fn spring_motor_is_force_based() {
    let default = GenericJointBuilder::new(JointAxesMask::empty())
        .motor_position(JointAxis::LinX, 1.0, 1.0, 0.0)
        .build();
    assert_eq!(
        default.motor_model(JointAxis::LinX),
        Some(MotorModel::AccelerationBased)
    );
    let scene = Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
         [[particle]]\nposition=[1.2,0.0,0.0]\nmass=4.0\n\
         [[spring]]\nbetween=[0,1]\nstiffness=1.0\nrest_length=1.0\n",
        "heavy.toml",
    )
    .unwrap();
    assert_eq!(
        spring_joint(&scene.build(), 0).motor_model(JointAxis::LinX),
        Some(MotorModel::ForceBased)
    );
    let period = 2.0 * std::f64::consts::PI * 4.0_f64.sqrt();
    for name in METHODS {
        let h = 1e-2;
        let (rec, _) = record(&scene, name, h, 4, (2.6 * period / h) as u64);
        let t: Vec<f64> = rec.energy.iter().map(|e| e.0).collect();
        let u: Vec<f64> = rec.x.iter().map(|x| x[1].x - 1.0).collect();
        let c = upward_crossings(&t, &u);
        let measured = c[c.len() - 1] - c[c.len() - 2];
        assert!(
            (measured - period).abs() < 1e-3 * period,
            "{name}: T = {measured} vs {period}"
        );
    }
}

/// Trap: multibody joints get a default damping of 0.1 on free angular DOFs. Oracle: an
/// undamped pendulum conserves energy. With the default damping the 60° pendulum would lose
/// ≈ 0.1·⟨ω²⟩·2 s ≈ 1 J over 2 s (⟨ω²⟩ ≈ 5 rad²/s²); the measured first-order integration
/// fluctuation at h = 1 ms is 5e-3 J. We require 2e-3·|E| ≈ 0.01 J, 100× below the trap.
#[test]
fn multibody_default_damping_is_zeroed() {
    let scene = Scenario::from_file("scenarios/pendulum_rod.toml").unwrap();
    let sys = scene.build();
    let b = build(&sys, &scene.initial_state(), Mode::Multibody, 4, 1e-3);
    for mb in b.world.multibody_joints.multibodies() {
        assert!(
            mb.damping().iter().all(|&d| d == 0.0),
            "damping {:?}",
            mb.damping()
        );
    }
    let (rec, _) = record(&scene, "rapier_multibody", 1e-3, 4, 2000);
    let e0 = rec.energy[0].1;
    let worst = rec
        .energy
        .iter()
        .map(|e| (e.1 - e0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 2e-3 * e0.abs(), "energy drift {worst}");
}

/// Trap: bodies fall asleep once slow for ~2 s and freeze a stretched spring. Oracle: a weak
/// spring (ω = 0.1 rad/s, amplitude 0.1 m, speed ≤ 0.01 m/s: below Rapier's sleep threshold)
/// keeps oscillating as u(t) = 0.1·cos(ωt); after 6 s u = 0.1·cos(0.6) = 0.0825, while a
/// body frozen at sleep (t ≈ 2 s) would stay near 0.098.
#[test]
fn sleeping_never_freezes_a_spring() {
    let scene = common::oscillator(0.01, 0.0, 0.1, 0.0);
    for name in METHODS {
        let (rec, _) = record(&scene, name, 1.0 / 60.0, 4, 360);
        let u = rec.x.last().unwrap()[1].x - 1.0;
        let want = 0.1 * (0.1_f64 * 6.0).cos();
        assert!((u - want).abs() < 1e-4, "{name}: u(6 s) = {u}, want {want}");
    }
    let b = build(
        &scene.build(),
        &scene.initial_state(),
        Mode::Impulse,
        4,
        1.0 / 60.0,
    );
    for (_, rb) in b.world.bodies.iter() {
        assert!(
            rb.activation().normalized_linear_threshold < 0.0,
            "body can sleep"
        );
    }
}

/// Trap: multibody insertion places a child from its joint coordinates, moving it to match the
/// joint anchors. Oracle: the first step of a tiny duration must leave every particle where the
/// state put it (any mismatch would show as a jump of the anchor offset, ~0.1–1 m here).
#[test]
fn multibody_insertion_keeps_positions() {
    for file in [
        "scenarios/hanging_chain.toml",
        "scenarios/pendulum_rod.toml",
        "scenarios/two_body.toml",
    ] {
        let scene = Scenario::from_file(file).unwrap();
        let (rec, _) = record(&scene, "rapier_multibody", 1e-9, 1, 1);
        for (a, b) in rec.x[0].iter().zip(&rec.x[1]) {
            assert!((a - b).norm() < 1e-7, "{file}: {a} moved to {b}");
        }
    }
}

/// Trap: restitution combines by average by default, which would halve an obstacle's
/// restitution against a particle (restitution 0). Oracle: Rapier's default rule is Average;
/// ours is Max, so the obstacle's coefficient acts as given.
#[test]
fn restitution_rule_is_not_average() {
    assert_eq!(
        ColliderBuilder::ball(0.1)
            .build()
            .restitution_combine_rule(),
        CoefficientCombineRule::Average
    );
    let sys = common::oscillator(1.0, 0.0, 0.1, 0.0).build();
    let c = particle_collider(&sys, 1);
    assert_eq!(c.restitution_combine_rule(), CoefficientCombineRule::Max);
    assert_eq!(c.restitution(), 0.0);
    assert_eq!(c.collision_groups(), InteractionGroups::none());
}

/// Trap: Rapier's public API is glam-based and `PhysicsWorld` defaults to gravity −9.81 ŷ and
/// a 400 m/s speed cap. Oracle: a free particle without gravity moves at constant velocity,
/// exactly, even at 1000 m/s, and every Rapier import lives in src/rapier/.
#[test]
fn no_default_gravity_no_speed_cap_and_rapier_confined() {
    let scene = Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nvelocity=[1000.0,0.0,0.0]\nmass=1.0\n",
        "coast.toml",
    )
    .unwrap();
    for name in METHODS {
        let (rec, _) = record(&scene, name, 0.01, 4, 10);
        let x = rec.x.last().unwrap()[0];
        assert!(
            (x - springlab::model::Vec3::new(100.0, 0.0, 0.0)).norm() < 1e-9,
            "{name}: {x}"
        );
    }
    let mut stack = vec![std::path::PathBuf::from("src")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                if !p.ends_with("rapier") {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                assert!(
                    !text.contains("rapier3d_f64"),
                    "{} imports Rapier outside src/rapier/",
                    p.display()
                );
            }
        }
    }
}

/// Reproducibility: Rapier is built without its `parallel` feature, so a run is a pure
/// function of its input. Oracle: two runs of the same scene give the same bits.
#[test]
fn runs_are_bitwise_reproducible() {
    let scene = Scenario::from_file("scenarios/hanging_chain.toml").unwrap();
    for name in METHODS {
        let (a, _) = record(&scene, name, 1.0 / 240.0, 4, 40);
        let (b, _) = record(&scene, name, 1.0 / 240.0, 4, 40);
        assert_eq!(a.x, b.x, "{name}");
        assert_eq!(a.v, b.v, "{name}");
    }
}
