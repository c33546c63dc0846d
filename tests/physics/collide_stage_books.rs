//! The contact stage's energy books against what it does (the
//! symplectic Euler "creation" of 17.6 J on chain_on_box).
//!
//! Oracles nobody tuned:
//! - bookkeeping: the stage's `created − dissipated` is, by definition, the change of the
//!   system's mechanical energy (kinetic + gravitational + elastic) across the stage, so it is
//!   checked against `System::energy` before and after, for every native method on the
//!   chain draped over the box (springs, friction, restitution);
//! - a particle resting on a plane (e = 0, impulse or projection) under gravity alone: velocity Verlet moves it from
//!   rest by exactly −½h²g with speed hg, so the stage's lift gains m·g·½h²g and its stop
//!   loses ½m(hg)²: nothing created. Symplectic Euler moves it by −h²g (drift with the kicked
//!   velocity): the lift gains m·h²g², the stop loses ½m(hg)², so the stage gives back exactly
//!   the ½m(hg)² the method lost that step — booked as created, never hidden;
//! - a particle on a 30° incline (held by μ = 0.6, or sliding with μ = 0.2): under constant
//!   gravity a step of explicit Euler gains exactly ½m h²|g|² whatever the state, symplectic
//!   Euler loses as much, velocity Verlet neither; the stage books, step by step, the energy
//!   change computed here by hand, so the run's balance is N times the method's own change.
//!   Explicit Euler's rise is its own, not the stage's: on the held particle at h = 1/30 s it
//!   is +6.04 J over 113 steps while the stage dissipates 6.67 J and the mechanical energy
//!   falls by 0.63 J;
//! - the Coulomb-damped oscillator (a block on a spring on a rough floor, any mechanics text):
//!   each half swing ends 2μmg/k closer to the spring's rest point. The friction travel rule
//!   must not pump energy into the spring: before the fix, re-timing symplectic Euler's drift
//!   made its spring-driven slides grow by a factor 1 + (hω)²/4 per step.

use springlab::method::MethodOptions;
use springlab::method::Registry;
use springlab::model::{State, System};
use springlab::scenario::Scenario;

fn mechanical(sys: &System, s: &State) -> f64 {
    sys.energy(&s.x, &s.v).mechanical()
}

/// Native methods that take obstacle scenes through the post-step stage.
fn natives(sys: &System) -> Vec<&'static str> {
    Registry::builtin()
        .iter()
        .filter(|m| !m.info.engine)
        .filter(|m| {
            let i = m.create(&MethodOptions::default());
            i.check(sys).is_ok() && !i.info.contacts
        })
        .map(|m| m.info.name)
        .collect()
}

/// Steps `name` on `sys` for `steps` steps of `h`, calling the contact stage by hand, and
/// returns the stage's (created, dissipated) totals after checking each step's books.
fn stage_books(sys: &System, s0: State, name: &str, h: f64, steps: usize) -> (f64, f64) {
    let stage = springlab::collide::of(sys).expect("obstacles");
    let mut stepper = Registry::builtin()
        .create(name, &MethodOptions::default())
        .unwrap();
    let mut s = s0;
    let (mut created, mut dissipated) = (0.0, 0.0);
    for k in 0..steps {
        let (x0, v0) = (s.x.clone(), s.v.clone());
        stepper.step(sys, &mut s, h).unwrap();
        let before = mechanical(sys, &s);
        let c = stage.apply(sys, &x0, &v0, &mut s, h);
        let change = mechanical(sys, &s) - before;
        let scale = before.abs().max(1.0);
        assert!(
            (c.created - c.dissipated - change).abs() <= 1e-11 * scale,
            "{name} step {k}: booked created {} − dissipated {} but the energy changed by {change}",
            c.created,
            c.dissipated
        );
        assert!(c.created >= 0.0 && c.dissipated >= 0.0);
        if c.changed {
            stepper.reset();
        }
        created += c.created;
        dissipated += c.dissipated;
    }
    (created, dissipated)
}

#[test]
fn the_stage_books_equal_its_energy_change_on_the_chain_over_the_box() {
    let path = format!("{}/scenarios/chain_on_box.toml", env!("CARGO_MANIFEST_DIR"));
    let scene = Scenario::from_file(std::path::Path::new(&path)).unwrap();
    let sys = scene.build();
    let names = natives(&sys);
    assert!(names.len() >= 5, "{names:?}");
    for name in names {
        let (c, d) = stage_books(&sys, scene.initial_state(), name, 1e-3, 1500);
        eprintln!("chain_on_box {name}: stage created {c:.3e} J, dissipated {d:.3e} J");
        assert!(
            d > 0.1,
            "{name}: the chain lands, friction and e = 0.2 must dissipate: {d}"
        );
    }
}

/// A particle (m = 0.1 kg, r = 0.05 m) resting on the plane y = 0, e = 0, friction `mu`, with
/// an optional spring (stiffness `k`) to a fixed anchor at the particle's height, stretched by
/// `stretch` along x.
fn on_floor(mu: f64, k: f64, stretch: f64, response: &str) -> Scenario {
    let spring = if k > 0.0 {
        format!(
            "[[particle]]\nposition = [{stretch}, 0.05, 0.0]\nmass = 1.0\nfixed = true\n\
             [[spring]]\nbetween = [0, 1]\nstiffness = {k}\nrest_length = 0.0\n"
        )
    } else {
        String::new()
    };
    Scenario::from_toml_str(
        &format!(
            "[world]\ngravity = [0.0, -9.81, 0.0]\n\
             [[particle]]\nposition = [0.0, 0.05, 0.0]\nmass = 0.1\nradius = 0.05\n\
             {spring}\
             [[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n\
             friction = {mu}\n[collision]\nresponse = \"{response}\"\n"
        ),
        "floor.toml",
    )
    .unwrap()
}

#[test]
fn resting_on_a_plane_creates_nothing_with_verlet_and_returns_symplectic_eulers_loss() {
    for response in ["impulse", "projection"] {
        let scene = on_floor(0.3, 0.0, 0.0, response);
        let sys = scene.build();
        let (h, m, g, steps) = (1e-3, 0.1, 9.81, 1000);
        let (c, _) = stage_books(&sys, scene.initial_state(), "velocity_verlet", h, steps);
        assert!(
            c <= 1e-15,
            "{response}: velocity_verlet at rest created {c} J"
        );
        let (c, _) = stage_books(&sys, scene.initial_state(), "symplectic_euler", h, steps);
        let lost = 0.5 * m * (h * g) * (h * g) * steps as f64;
        assert!(
            (c / lost - 1.0).abs() < 1e-9,
            "{response}: symplectic_euler at rest created {c} J, its own loss {lost} J"
        );
    }
}

#[test]
fn a_block_on_a_spring_on_a_rough_floor_loses_two_mu_m_g_over_k_per_half_swing() {
    // m = 0.1 kg, k = 10 N/m (ω = 10 rad/s), μ = 0.1, released 0.2 m from the anchor: the
    // turning points are 0.2, −0.1804, 0.1608, … (drop 2μmg/k = 0.01962 m per half swing).
    // dt = 0.01 s (hω = 0.1), where the old rule's pumping (×1.0025 per step, +8 % per half
    // swing) would have cancelled most of the drop.
    let (m, k, mu, g, a0, h) = (0.1, 10.0, 0.1, 9.81, 0.2, 0.01);
    let drop = 2.0 * mu * m * g / k;
    let scene = on_floor(mu, k, a0, "impulse");
    let sys = scene.build();
    // Explicit Euler grows on any undamped oscillator (×√(1 + (hω)²) per step): not a
    // question of the contact stage.
    let names: Vec<_> = natives(&sys)
        .into_iter()
        .filter(|n| *n != "explicit_euler")
        .collect();
    let mut bad = vec![];
    for name in names {
        let mut stepper = Registry::builtin()
            .create(name, &MethodOptions::default())
            .unwrap();
        let stage = springlab::collide::of(&sys).unwrap();
        let mut s = scene.initial_state();
        let mut turns = vec![];
        let mut last_v: f64 = 0.0;
        for _ in 0..300 {
            let (x0, v0) = (s.x.clone(), s.v.clone());
            stepper.step(&sys, &mut s, h).unwrap();
            if stage.apply(&sys, &x0, &v0, &mut s, h).changed {
                stepper.reset();
            }
            let v = s.v[0].x;
            if last_v != 0.0 && (v == 0.0 || v.signum() != last_v.signum()) {
                turns.push((s.x[0].x - a0).abs());
            }
            last_v = v;
        }
        // Half swings that start outside the static band μmg/k.
        let drops: Vec<f64> = turns
            .windows(2)
            .filter(|w| w[0] > 2.0 * drop)
            .map(|w| w[0] - w[1])
            .collect();
        eprintln!("{name}: turning points {turns:.4?}");
        // Methods that damp an oscillator by themselves (implicit Euler by 1/√(1 + (hω)²) per
        // step, BDF2, XPBD's implicit-Euler projection) lose more than friction takes: for
        // them only the bound that friction never pumps the swing (each drop at least 3/4 of
        // Coulomb's) applies.
        let damps = ["implicit_euler", "linear_implicit_euler", "bdf2", "xpbd"].contains(&name);
        let off = |d: &f64| {
            let r = d / drop - 1.0;
            r <= -0.25 || (!damps && r >= 0.25)
        };
        if drops.len() < 3 || drops.iter().any(off) {
            bad.push(format!(
                "{name}: drops {drops:.4?}, Coulomb damping {drop:.4} m"
            ));
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

/// A particle (m = 1 kg, r = 0.05 m) at rest on a 30° incline with friction `mu` and
/// restitution `e`.
fn on_incline(mu: f64, e: f64) -> Scenario {
    let th = 30f64.to_radians();
    let (nx, ny) = (-th.sin(), th.cos());
    Scenario::from_toml_str(
        &format!(
            "[world]\ngravity = [0.0, -9.81, 0.0]\n\
             [[particle]]\nposition = [{}, {}, 0.0]\nmass = 1.0\nradius = 0.05\n\
             [[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [{nx}, {ny}, 0.0]\n\
             friction = {mu}\nrestitution = {e}\n",
            0.05 * nx,
            0.05 * ny
        ),
        "incline.toml",
    )
    .unwrap()
}

/// Kinetic plus gravitational energy of a lone particle of mass `m` under `g`, by hand
/// (½m|v|² − m g·x), apart from the library's energy code.
fn by_hand(m: f64, g: springlab::model::Vec3, s: &State) -> f64 {
    0.5 * m * s.v[0].norm_squared() - m * g.dot(&s.x[0])
}

/// Runs `name` on the incline for `steps` steps of `h` through the runner and, beside it, by
/// hand with the stage called between steps. Per step, the stage's books must equal the
/// energy change by hand across it (one particle: a fall is dissipated, a rise created);
/// returns (the run's balance change, the mechanical change, dissipated, created) by hand,
/// after checking that the runner's account agrees with it.
fn incline_books(mu: f64, e: f64, name: &str, h: f64, steps: u64) -> (f64, f64, f64, f64) {
    let scene = on_incline(mu, e);
    let sys = scene.build();
    let (m, g) = (1.0, sys.gravity.unwrap());
    let stage = springlab::collide::of(&sys).unwrap();
    let mut stepper = Registry::builtin()
        .create(name, &MethodOptions::default())
        .unwrap();
    let mut s = scene.initial_state();
    let e0 = by_hand(m, g, &s);
    let (mut created, mut dissipated) = (0.0, 0.0);
    for k in 0..steps {
        let (x0, v0) = (s.x.clone(), s.v.clone());
        stepper.step(&sys, &mut s, h).unwrap();
        let before = by_hand(m, g, &s);
        let c = stage.apply(&sys, &x0, &v0, &mut s, h);
        let change = by_hand(m, g, &s) - before;
        let tol = 1e-12 * (1.0 + before.abs());
        assert!(
            (c.dissipated - (-change).max(0.0)).abs() <= tol
                && (c.created - change.max(0.0)).abs() <= tol,
            "{name} step {k}: booked dissipated {} created {}, energy changed by {change}",
            c.dissipated,
            c.created
        );
        if c.changed {
            stepper.reset();
        }
        created += c.created;
        dissipated += c.dissipated;
    }
    let mech = by_hand(m, g, &s) - e0;
    let mut stepper = Registry::builtin()
        .create(name, &MethodOptions::default())
        .unwrap();
    let out = springlab::run::run(
        &sys,
        &mut stepper,
        scene.initial_state(),
        // The whole run: the verdict's threshold is not the question here.
        &springlab::run::RunPlan {
            blowup_factor: 1e12,
            ..springlab::run::RunPlan::new(h, steps)
        },
        &mut springlab::run::NoObserver,
    )
    .unwrap();
    assert_eq!(out.steps_done, steps, "{name}: {:?}", out.status);
    let f = out.final_energy;
    let tol = 1e-9 * (1.0 + dissipated);
    assert!(
        (f.dissipated - dissipated).abs() <= tol && (f.created - created).abs() <= tol,
        "{name}: the runner booked dissipated {} created {}, the stage by hand {dissipated} {created}",
        f.dissipated,
        f.created
    );
    assert!((f.mechanical() - f.kinetic - f.gravity).abs() <= 1e-12);
    (mech + dissipated - created, mech, dissipated, created)
}

#[test]
fn explicit_euler_on_an_incline_books_what_the_stage_removes_and_keeps_its_own_gain() {
    // Oracle (closed form): under a constant force every step of explicit Euler (x += h v,
    // v += h g) changes ½m|v|² − m g·x by exactly +½ m h² |g|², whatever the state; symplectic
    // Euler (v += h g, x += h v) by −½ m h² |g|²; velocity Verlet by 0. The contact stage
    // books exactly what it changes (checked per step), so over N steps the balance
    // (mechanical change + dissipated − created) must be N times the method's own change:
    // a rise for explicit Euler however much the stage dissipates, and the twins near it, a
    // fall for symplectic Euler and nothing for velocity Verlet.
    let (h, steps, m, g) = (1.0 / 30.0, 113u64, 1.0, 9.81);
    let own = 0.5 * m * h * h * g * g;
    for (mu, e) in [(0.6, 0.0), (0.6, 0.5), (0.2, 0.0), (0.2, 0.5)] {
        for (name, sign) in [
            ("explicit_euler", 1.0),
            ("symplectic_euler", -1.0),
            ("velocity_verlet", 0.0),
        ] {
            let (balance, mech, d, c) = incline_books(mu, e, name, h, steps);
            let expected = sign * own * steps as f64;
            eprintln!(
                "μ {mu} e {e} {name}: mechanical {mech:+.4} J, dissipated {d:.4} J, created {c:.4} J, balance {balance:+.6} J (method's own {expected:+.6} J)"
            );
            assert!(
                (balance - expected).abs() <= 1e-9 * (1.0 + d + mech.abs()),
                "μ {mu} e {e} {name}: balance {balance} J, the method's own {expected} J"
            );
        }
    }
}
