//! Every scene term through both Rapier engines, each against its closed form, so that no
//! engine silently drops one: gravity, drag, spring dampers and pinned particles.
//!
//! Each check has a twin: the same scene without the term (or, for the pin, with the anchor
//! free) fails the same check by far more than its tolerance, so a dropped term shows.
//!
//! Tolerances come from the engines' first-order schemes (src/rapier/scheme.rs): a frame of h
//! is N substeps of h_s = h/N, each applying the forces to the velocities, solving the joints
//! once (a spring as a backward-Euler step along its axis) and moving the positions with the
//! new velocities; drag is Rapier's implicit linear damping v ← v/(1 + h·c/m) once per frame
//! (on multibody links the same law held as a user force over the frame).

use crate::rapier_support::{record, Record, METHODS};
use springlab::model::Vec3;
use springlab::scenario::Scenario;

/// Frame step of every test: a game's 60 Hz.
const H: f64 = 1.0 / 60.0;

fn scene(toml: &str) -> Scenario {
    Scenario::from_toml_str(toml, "terms.toml").unwrap()
}

/// Two `mass` kg particles 1 m apart along x, joined by a spring at its rest length, both
/// moving with `v0` under `world`: the spring never stretches, so each moves as a lone
/// particle under the world's terms. Under rapier_multibody the pair is a multibody tree (a
/// root and a slider link), so the terms must reach links, not only free bodies.
fn pair(world: &str, mass: f64, v0: [f64; 3]) -> Scenario {
    let p = |x: f64| {
        format!(
            "[[particle]]\nposition = [{x:?}, 0.0, 0.0]\nvelocity = [{:?}, {:?}, {:?}]\nmass = {mass:?}\n",
            v0[0], v0[1], v0[2]
        )
    };
    scene(&format!(
        "[world]\n{world}\n{}{}[[spring]]\nbetween = [0, 1]\nstiffness = 10.0\nrest_length = 1.0\n",
        p(0.0),
        p(1.0)
    ))
}

/// A `m` = 1 kg bob hanging 1.5 m below an anchor (pinned unless `free_anchor`) on a spring
/// of k = 100 N/m, l0 = 1 m and damper `c`, under g = 9.81 m/s², released from rest.
fn hanging(c: f64, free_anchor: bool) -> Scenario {
    scene(&format!(
        "[world]\ngravity = [0.0, -9.81, 0.0]\n\
         [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = {}\n\
         [[particle]]\nposition = [0.0, -1.5, 0.0]\nmass = 1.0\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = 100.0\nrest_length = 1.0\ndamping = {c:?}\n",
        !free_anchor
    ))
}

/// The largest distance over every frame and particle between the run and `exact(p, t)`.
fn worst(rec: &Record, exact: impl Fn(usize, f64) -> Vec3) -> f64 {
    rec.x
        .iter()
        .zip(&rec.energy)
        .flat_map(|(xs, &(t, _))| {
            let exact = &exact;
            xs.iter()
                .enumerate()
                .map(move |(p, x)| (x - exact(p, t)).norm())
        })
        .fold(0.0, f64::max)
}

// Oracle: free fall, x(t) = x0 + v0 t + g t²/2, v(t) = v0 + g t. Symplectic Euler at h_s
// lands at x0 + v0 t + g h_s² M(M+1)/2 after M substeps: ahead of the parabola by exactly
// |g| t h_s/2, its first-order error, and on the exact velocity. Tolerances: that error (plus
// round-off), the velocity to round-off. Under rapier_multibody two first-order effects are
// allowed on top: the spring's helper pivot (1e-6 of the child's mass, gravity-free, riding on
// the root; src/rapier/multibody.rs) slows the root's fall by that fraction (1e-6·|g| t²/2,
// 1e-6·|g| t on the velocity);
// and a link's velocity is read back one substep's kick (|g| h_s) behind its position.
#[test]
fn gravity_follows_the_free_fall_parabola() {
    let (v0, g, n, frames) = (
        Vec3::new(1.0, 2.0, 0.0),
        Vec3::new(0.0, -9.81, 0.0),
        16,
        120,
    );
    let hs = H / n as f64;
    let x0 = |p: usize| Vec3::new(p as f64, 0.0, 0.0);
    let parabola = |p: usize, t: f64| x0(p) + v0 * t + g * (0.5 * t * t);
    let with = pair("gravity = [0.0, -9.81, 0.0]", 1.0, [1.0, 2.0, 0.0]);
    let without = pair("", 1.0, [1.0, 2.0, 0.0]);
    for name in METHODS {
        let (rec, out) = record(&with, name, H, n, frames);
        assert!(out.status.is_ok(), "{name}");
        let t = rec.energy.last().unwrap().0;
        let multibody = name == "rapier_multibody";
        let pivot = if multibody {
            1e-6 * g.norm() * t * t / 2.0
        } else {
            0.0
        };
        let tol = g.norm() * t * hs / 2.0 * (1.0 + 1e-9) + pivot + 1e-12;
        let v_tol = if multibody {
            g.norm() * hs * (1.0 + 1e-9) + 1e-6 * g.norm() * t
        } else {
            1e-12 * (v0 + g * t).norm()
        };
        let err = worst(&rec, parabola);
        let v_err = rec
            .v
            .last()
            .unwrap()
            .iter()
            .map(|v| (v - (v0 + g * t)).norm())
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: gravity: position {err:.4e} m (tolerance {tol:.4e}), velocity {v_err:.2e} m/s (tolerance {v_tol:.2e})"
        );
        assert!(err <= tol, "{name}: {err:e} > {tol:e}");
        assert!(v_err <= v_tol, "{name}: {v_err:e} > {v_tol:e}");
        // Twin: without gravity the same check is off by |g| t²/2.
        let (rec, _) = record(&without, name, H, n, frames);
        assert!(
            worst(&rec, parabola) > 100.0 * tol,
            "{name}: gravity-less twin"
        );
    }
}

// Oracle: linear drag on a lone particle, m dv/dt = −c v: v(t) = v0 e^{−d t}, x(t) = x0 +
// v0 (1 − e^{−d t})/d with d = c/m. Rapier's law v ← v/(1 + h d) per frame gives v0 (1 +
// h d)^{−t/h}, whose ratio to the exact decay is e^{t (h d − ln(1 + h d))/h} ≤ e^{t h d²/2}:
// the velocity tolerance. Within a frame the bodies move at most at the frame's starting
// speed, a relative error below h d on the distance travelled: the position tolerance.
#[test]
fn drag_decays_the_velocity_exponentially() {
    let (m, c, v0, n, frames) = (0.1, 0.05, 1.0, 4, 120);
    let d = c / m;
    let with = pair(&format!("drag = {c:?}"), m, [v0, 0.0, 0.0]);
    let without = pair("", m, [v0, 0.0, 0.0]);
    let travelled = |t: f64| v0 * (1.0 - (-d * t).exp()) / d;
    for name in METHODS {
        let check = |sc: &Scenario| {
            let (rec, out) = record(sc, name, H, n, frames);
            assert!(out.status.is_ok(), "{name}");
            let t = rec.energy.last().unwrap().0;
            let exact = v0 * (-d * t).exp();
            let v_rel = rec
                .v
                .last()
                .unwrap()
                .iter()
                .map(|v| (v.x / exact - 1.0).abs().max(v.yz().norm()))
                .fold(0.0, f64::max);
            let x_rel =
                worst(&rec, |p, t| Vec3::new(p as f64 + travelled(t), 0.0, 0.0)) / travelled(t);
            (v_rel, x_rel, t, rec.v.last().unwrap()[0].x)
        };
        let (v_rel, x_rel, t, v) = check(&with);
        let (v_tol, x_tol) = ((t * H * d * d / 2.0).exp() - 1.0, H * d);
        eprintln!(
            "{name}: drag: v(2 s) = {v:.6} m/s (exact {:.6}), velocity {v_rel:.2e} (tolerance {v_tol:.2e}), distance {x_rel:.2e} (tolerance {x_tol:.2e})",
            v0 * (-d * t).exp()
        );
        assert!(v_rel <= v_tol, "{name}: velocity {v_rel:e} > {v_tol:e}");
        assert!(x_rel <= x_tol, "{name}: distance {x_rel:e} > {x_tol:e}");
        // Twin: without drag the velocity stays v0, e^{d t} − 1 = 1.7 off.
        let (v_rel, _, _, _) = check(&without);
        assert!(v_rel > 100.0 * v_tol, "{name}: drag-less twin");
    }
}

// Oracle: the damped oscillator. About its static equilibrium y_eq = −(l0 + m g/k) the bob's
// offset is e(t) = e0 e^{−ζωt} (cos ω_d t + ζω/ω_d sin ω_d t), ω = √(k/m), ζ = c/(2mω),
// ω_d = ω√(1 − ζ²). Backward Euler at h_s on the eigenvalue λ = −ζω ± iω_d has the
// multiplier 1/(1 − h_s λ) = e^{h_s λ + h_s² λ²/2 + …}: its amplitude decays faster by
// h_s ω²(1 − 2ζ²)/2 per second and its phase lags by h_s ζ ω ω_d per second, so after t the
// offset is off by at most |e0|/√(1 − ζ²) e^{−ζωt} h_s t (ω²/2 + ζω²) to first order: the
// tolerance, with 25 % for the second-order terms.
#[test]
fn dampers_follow_the_damped_oscillator() {
    let (k, m, l0, g, c, n, frames) = (100.0_f64, 1.0_f64, 1.0, 9.81, 2.0, 64, 120);
    let hs = H / n as f64;
    let w = (k / m).sqrt();
    let z = c / (2.0 * m * w);
    let wd = w * (1.0 - z * z).sqrt();
    let y_eq = -(l0 + m * g / k);
    let e0 = -1.5 - y_eq;
    let offset = |t: f64| e0 * (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin());
    let bound = |t: f64| {
        e0.abs() / (1.0 - z * z).sqrt() * (-z * w * t).exp() * hs * t * (w * w / 2.0 + z * w * w)
    };
    for name in METHODS {
        let err = |sc: &Scenario| {
            let (rec, out) = record(sc, name, H, n, frames);
            assert!(out.status.is_ok(), "{name}");
            worst(&rec, |p, t| {
                if p == 0 {
                    Vec3::zeros()
                } else {
                    Vec3::new(0.0, y_eq + offset(t), 0.0)
                }
            })
        };
        let tol = 1.25
            * (0..=frames)
                .map(|i| bound(i as f64 * H))
                .fold(0.0, f64::max);
        let e = err(&hanging(c, false));
        eprintln!("{name}: damper: {e:.3e} m (tolerance {tol:.3e})");
        assert!(e <= tol, "{name}: {e:e} > {tol:e}");
        // Twin: without the damper the bob keeps swinging where the damped one has settled.
        assert!(
            err(&hanging(0.0, false)) > 10.0 * tol,
            "{name}: damper-less twin"
        );
    }
}

// Oracle: statics. A bob on a critically damped spring (c = 2√(k m)) below a pinned anchor
// settles at y_eq = −(l0 + m g/k): its offset (1 + ωt) e^{−ωt}|e0| is below 1e-15 m after
// 4 s, and a scheme's fixed point is the static equilibrium itself (no force left), so what
// remains is round-off: tolerance 1e-9 m. The pinned anchor stays where it was, to the bit.
#[test]
fn a_pinned_particle_holds_its_chain() {
    let (k, m, l0, g, n, frames) = (100.0_f64, 1.0_f64, 1.0, 9.81, 4, 240);
    let c = 2.0 * (k * m).sqrt();
    let y_eq = -(l0 + m * g / k);
    for name in METHODS {
        let settle = |sc: &Scenario| {
            let (rec, _) = record(sc, name, H, n, frames);
            let x = rec.x.last().unwrap().clone();
            (x[0], (x[1] - Vec3::new(0.0, y_eq, 0.0)).norm())
        };
        let (anchor, e) = settle(&hanging(c, false));
        eprintln!("{name}: pinned: settled {e:.2e} m from y_eq");
        assert_eq!(anchor, Vec3::zeros(), "{name}: the pin moved");
        assert!(e < 1e-9, "{name}: {e:e} m from the equilibrium");
        // Twin: with the anchor free the pair falls (about g t²/2 = 78 m in 4 s).
        let (_, e) = settle(&hanging(c, true));
        assert!(e > 1.0, "{name}: free-anchor twin {e}");
    }
}

// Oracle: the energy balance. What the drag takes from the motion is booked as dissipated, so
// kinetic + dissipated stays at the start's kinetic energy E0: to first order, since the
// books estimate the drag's work over each frame (Rapier's own damping by the trapezoidal
// rule on the read-back speeds, the held drag on multibody links by its force times the
// displacement) while the velocity changes within it; both estimates differ from the kinetic
// energy lost by at most h·d of that loss (h d = 1/120 here). Twin: with no drag nothing is
// booked at all, and the balance holds to round-off.
#[test]
fn the_drag_loss_is_booked_when_it_happens() {
    let (m, c, n, frames) = (0.1, 0.05, 4, 120);
    let d = c / m;
    for name in METHODS {
        let (_, out) = record(
            &pair(&format!("drag = {c:?}"), m, [1.0, 0.0, 0.0]),
            name,
            H,
            n,
            frames,
        );
        let (e0, e1) = (out.initial_energy, out.final_energy);
        let lost = e0.mechanical() - e1.mechanical();
        let drift = e1.total - e0.total;
        eprintln!(
            "{name}: drag books {:.5} J of {lost:.5} J lost, balance {drift:+.2e} J",
            e1.dissipated
        );
        assert!(
            lost > 0.5 * e0.mechanical(),
            "{name}: the drag took {lost} J"
        );
        assert!(drift.abs() <= H * d * lost, "{name}: balance {drift:e}");
        let (_, out) = record(&pair("", m, [1.0, 0.0, 0.0]), name, H, n, frames);
        assert_eq!(out.final_energy.dissipated, 0.0, "{name}: drag-less twin");
        let drift = out.final_energy.total - out.initial_energy.total;
        assert!(drift.abs() < 1e-12, "{name}: drag-less balance {drift:e}");
    }
}
