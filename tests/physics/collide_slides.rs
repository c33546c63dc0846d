//! Friction as `contacts.json` reports it, for every method (the data of the collision
//! validation): slides in resting contact against the point-mass Coulomb law.
//!
//! Oracles (closed forms): on a 30° incline with μ = 0.2 a particle released at rest
//! accelerates at g(sin θ − μ cos θ) = 3.2059 m/s²; sliding at 5 m/s on a flat plane with
//! μ = 0.3 it stops after v0²/(2μg) = 4.2474 m; pushed up a 30° incline at v0 it decelerates
//! at g(sin θ + μ cos θ), stops after v0²/(2|a|) at v0/|a|, and slides back at
//! g(sin θ − μ cos θ) when tan θ > μ, else stays; a ball free to roll (a Rapier multibody body)
//! accelerates at 5/7·g·sin θ instead, the documented difference.

use springlab::measure::contacts::{ContactMetrics, ContactReport};
use springlab::method::MethodOptions;
use springlab::method::Registry;
use springlab::run::{run, RunPlan};
use springlab::scenario::Scenario;

const G: f64 = 9.81;

fn scene(deg: f64, mu: f64, v0: f64) -> Scenario {
    let th = deg.to_radians();
    let (nx, ny) = (-th.sin(), th.cos());
    let r = 0.05;
    Scenario::from_toml_str(
        &format!(
            "[world]\ngravity = [0.0, -{G}, 0.0]\n[[particle]]\nposition = [{}, {}, 0.0]\nvelocity = [{v0}, 0.0, 0.0]\nmass = 0.1\nradius = {r}\n\
             [[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [{nx}, {ny}, 0.0]\nfriction = {mu}\n",
            nx * r,
            ny * r
        ),
        "slide.toml",
    )
    .unwrap()
}

fn report(scene: &Scenario, name: &str, duration: f64) -> ContactReport {
    let sys = scene.build();
    let dt = 1e-3;
    let mut stepper = Registry::builtin()
        .create(name, &MethodOptions::default())
        .unwrap();
    let mut m = ContactMetrics::new(&sys, dt).unwrap();
    let out = run(
        &sys,
        &mut stepper,
        scene.initial_state(),
        &RunPlan::for_duration(dt, duration),
        &mut m,
    )
    .unwrap();
    assert!(out.status.is_ok(), "{name}: {:?}", out.status);
    m.report()
}

fn methods() -> Vec<&'static str> {
    let sys = scene(30.0, 0.2, 0.0).build();
    Registry::builtin()
        .iter()
        .filter(|m| m.create(&MethodOptions::default()).check(&sys).is_ok())
        .map(|m| m.info.name)
        .filter(|n| *n != "explicit_euler" && *n != "rapier_multibody")
        .collect()
}

#[test]
fn contacts_json_reports_the_incline_acceleration_for_every_method() {
    let th = 30f64.to_radians();
    let a = G * (th.sin() - 0.2 * th.cos());
    for name in methods() {
        let rep = report(&scene(30.0, 0.2, 0.0), name, 1.0);
        assert_eq!(rep.slides.len(), 1, "{name}: {:?}", rep.slides);
        let s = &rep.slides[0];
        eprintln!(
            "{name}: incline a = {:.5} m/s² (theory {a:.5}), over {:.3} s",
            s.acceleration,
            s.t_end - s.t_start
        );
        assert!((s.expected_acceleration - a).abs() < 1e-12);
        assert!((s.acceleration / a - 1.0).abs() < 0.01, "{name}: {s:?}");
    }
}

#[test]
fn contacts_json_reports_the_stopping_distance_for_every_method() {
    let (v0, mu) = (5.0, 0.3);
    let d = v0 * v0 / (2.0 * mu * G);
    for name in methods() {
        let rep = report(&scene(0.0, mu, v0), name, 2.0);
        let s = &rep.slides[0];
        eprintln!(
            "{name}: stopped after {:.5} m (theory {d:.5}) at {:.4} s (theory {:.4})",
            s.distance,
            s.t_end,
            v0 / (mu * G)
        );
        assert!(s.stopped, "{name}: {s:?}");
        assert!((s.expected_stop_distance.unwrap() / d - 1.0).abs() < 1e-12);
        assert!((s.distance / d - 1.0).abs() < 0.01, "{name}: {s:?}");
    }
}

/// The 30° incline with the particle pushed up the slope at `v0`.
fn pushed_up(mu: f64, v0: f64) -> Scenario {
    let th = 30f64.to_radians();
    let text = format!(
        "[world]\ngravity = [0.0, -{G}, 0.0]\n[[particle]]\nposition = [{}, {}, 0.0]\nvelocity = [{}, {}, 0.0]\nmass = 0.1\nradius = 0.05\n\
         [[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [{}, {}, 0.0]\nfriction = {mu}\n",
        -0.05 * th.sin(),
        0.05 * th.cos(),
        v0 * th.cos(),
        v0 * th.sin(),
        -th.sin(),
        th.cos()
    );
    Scenario::from_toml_str(&text, "pushed_up.toml").unwrap()
}

#[test]
fn up_an_incline_and_back_are_two_slides_each_with_its_own_law() {
    // μ = 0.2 < tan 30°: up at −g(sin θ + μ cos θ) = −6.6041, back at g(sin θ − μ cos θ) =
    // 3.2059. At v0 = 2 m/s the native responses stop the particle exactly at a sample; at
    // 3 m/s its motion reverses between two samples: both must split.
    let th = 30f64.to_radians();
    let mu = 0.2;
    let (up, back) = (
        -G * (th.sin() + mu * th.cos()),
        G * (th.sin() - mu * th.cos()),
    );
    let mut names = methods();
    names.push("explicit_euler");
    for v0 in [2.0, 3.0] {
        let t_stop = v0 / -up;
        for name in &names {
            let rep = report(&pushed_up(mu, v0), name, 1.5);
            assert_eq!(rep.slides.len(), 2, "{name} v0 {v0}: {:?}", rep.slides);
            let (a, b) = (&rep.slides[0], &rep.slides[1]);
            eprintln!(
                "{name} v0 {v0}: up a = {:.5} (theory {up:.5}) stop {:.5} m at {:.4} s, back a = {:.5} (theory {back:.5})",
                a.acceleration, a.distance, a.t_end, b.acceleration
            );
            assert!((a.expected_acceleration - up).abs() < 1e-12, "{a:?}");
            assert!((b.expected_acceleration - back).abs() < 1e-12, "{b:?}");
            assert!((a.acceleration / up - 1.0).abs() < 0.01, "{name}: {a:?}");
            assert!((b.acceleration / back - 1.0).abs() < 0.01, "{name}: {b:?}");
            assert!(a.stopped && !b.stopped, "{name}: {a:?} {b:?}");
            let d = v0 * v0 / (-2.0 * up);
            assert!((a.expected_stop_distance.unwrap() / d - 1.0).abs() < 1e-12);
            assert!((a.distance / d - 1.0).abs() < 0.01, "{name}: {a:?}");
            assert!((a.t_end - t_stop).abs() <= 2e-3, "{name}: {a:?}");
            assert!((b.t_start - t_stop).abs() <= 2e-3, "{name}: {b:?}");
        }
    }
}

#[test]
fn up_an_incline_that_holds_it_is_one_slide() {
    // The twin: μ = 0.6 just above tan 30° = 0.577, so static friction holds the particle
    // where it stops: one slide at −g(sin θ + μ cos θ), no slide back.
    let th = 30f64.to_radians();
    let mu = 0.6;
    let up = -G * (th.sin() + mu * th.cos());
    let mut names = methods();
    names.push("explicit_euler");
    for name in names {
        let rep = report(&pushed_up(mu, 3.0), name, 1.5);
        assert_eq!(rep.slides.len(), 1, "{name}: {:?}", rep.slides);
        let a = &rep.slides[0];
        eprintln!(
            "{name}: up a = {:.5} (theory {up:.5}), stopped {}",
            a.acceleration, a.stopped
        );
        assert!((a.acceleration / up - 1.0).abs() < 0.01, "{name}: {a:?}");
        assert!(a.stopped, "{name}: {a:?}");
    }
}

#[test]
fn difference_a_rapier_multibody_ball_rolls_down_the_incline() {
    // Multibody links must turn about their parents, so rapier_multibody keeps rotations:
    // a lone ball rolls without slipping (μ = 0.2 > 2/7·tan 30° = 0.165), a = 5/7·g·sin θ.
    let th = 30f64.to_radians();
    let rolling = 5.0 / 7.0 * G * th.sin();
    let rep = report(&scene(30.0, 0.2, 0.0), "rapier_multibody", 1.0);
    let s = &rep.slides[0];
    eprintln!(
        "rapier_multibody: incline a = {:.5} m/s² (rolling {rolling:.5}, sliding point {:.5})",
        s.acceleration, s.expected_acceleration
    );
    assert!((s.acceleration / rolling - 1.0).abs() < 0.01, "{s:?}");
}

#[test]
fn a_particle_held_by_a_spring_is_not_held_to_the_point_mass_law() {
    // Coulomb's point-mass law a = g·d − μ|g·n| holds only where gravity, the contact and
    // friction are the only forces. The same sliding particle tied to a fixed anchor by a
    // spring reports no slide at all, and says why; the lone one beside it still does.
    let base = scene(0.0, 0.3, 5.0);
    let mut text = String::from("[world]\ngravity = [0.0, -9.81, 0.0]\n");
    text += "[[particle]]\nposition = [0.0, 0.05, 0.0]\nvelocity = [5.0, 0.0, 0.0]\nmass = 0.1\nradius = 0.05\n";
    text += "[[particle]]\nposition = [0.0, 0.05, 1.0]\nvelocity = [5.0, 0.0, 0.0]\nmass = 0.1\nradius = 0.05\n";
    text += "[[particle]]\nposition = [-1.0, 0.05, 1.0]\nmass = 1.0\nfixed = true\n";
    text += "[[spring]]\nbetween = [1, 2]\nstiffness = 5.0\n";
    text += "[[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\nfriction = 0.3\n";
    let tied = Scenario::from_toml_str(&text, "tied.toml").unwrap();
    for name in ["symplectic_euler", "rk4", "rapier_impulse"] {
        let lone = report(&base, name, 2.0);
        assert!(
            !lone.slides.is_empty() && lone.slides_unmeasured.is_none(),
            "{name}"
        );
        let rep = report(&tied, name, 2.0);
        assert!(
            rep.slides.iter().all(|s| s.particle == 0),
            "{name}: {:?}",
            rep.slides
        );
        assert!(!rep.slides.is_empty(), "{name}: the lone particle's slide");
        assert!(rep.slides_unmeasured.is_none(), "{name}");
    }
    let path = format!("{}/scenarios/chain_on_box.toml", env!("CARGO_MANIFEST_DIR"));
    let chain = Scenario::from_file(std::path::Path::new(&path)).unwrap();
    let rep = report(&chain, "rk4", 1.5);
    assert!(rep.slides.is_empty(), "{:?}", rep.slides);
    assert_eq!(
        rep.slides_unmeasured,
        Some(springlab::measure::contacts::NO_LONE_PARTICLE)
    );
}
