//! Scenes no method can integrate, refused before anything runs: a gravity or drag so strong
//! that the motion's time scale is below what f64 time resolves over the run (at t = 1 s, two
//! neighbouring f64 times are 2.2e-16 s apart; a solver step must be many times that). Such a
//! scene would otherwise reach the reference and fail there as "step size underflow at t = 0",
//! naming nothing the user can change.

use super::checker::Checker;
use super::Scenario;
use crate::error::{significant, Result};
use crate::model::Vec3;

fn sig(v: f64) -> String {
    significant(v, 3)
}

/// The shortest time scale a run of length T can resolve: this many f64 spacings of max(T, 1).
const RESOLVABLE_SPACINGS: f64 = 1e3;

/// The scene's length scale for gravity's time scale: its extent, at least its largest radius,
/// at least a millimetre (a lone point particle still has a scale to fall across).
fn length_scale(scene: &Scenario) -> f64 {
    // The largest coordinate range: the largest component difference over all pairs, in one
    // pass (a cloth of 10⁵ particles has 10¹⁰ pairs).
    let ps = &scene.particles;
    let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
    let mut radius = 0.0_f64;
    for p in ps {
        lo = lo.inf(&p.position);
        hi = hi.sup(&p.position);
        radius = radius.max(p.radius);
    }
    (hi - lo).amax().max(radius).max(1e-3)
}

/// Refuses a scene whose gravity or drag acts faster than the run can resolve, naming the field,
/// its time scale and the shortest resolvable step.
pub(super) fn check_resolvable(ck: &Checker, scene: &Scenario, end: f64) -> Result<()> {
    let shortest = RESOLVABLE_SPACINGS * f64::EPSILON * end.max(1.0);
    let too_fast = |field: &str, what: String, tau: f64| {
        ck.err(
            field,
            format!(
                "{what} gives the motion a time scale of {} s, below the shortest step f64 time resolves over this {} s run ({} s): no method or reference can integrate it",
                sig(tau),
                sig(end),
                sig(shortest)
            ),
        )
    };
    if let Some(g) = scene.gravity {
        // The largest component: the norm of 1e300 would overflow.
        let (a, l) = (g.amax(), length_scale(scene));
        if a > 0.0 {
            let tau = (l / a).sqrt();
            if tau < shortest {
                let what = format!("|g| = {} m/s² across the scene's {} m", sig(a), sig(l));
                return Err(too_fast("world.gravity", what, tau));
            }
        }
    }
    if let Some(c) = scene.drag {
        let m = scene
            .particles
            .iter()
            .filter(|p| !p.fixed)
            .map(|p| p.mass)
            .fold(f64::INFINITY, f64::min);
        let tau = m / c;
        if m.is_finite() && tau < shortest {
            let what = format!(
                "drag {} N·s/m on the lightest free particle ({} kg)",
                sig(c),
                sig(m)
            );
            return Err(too_fast("world.drag", what, tau));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::scenario::Scenario;

    fn scene(world: &str) -> String {
        format!(
            "[world]\n{world}\n[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 0.05\n[[particle]]\nposition = [1.0, 0.0, 0.0]\nmass = 0.05\n[[spring]]\nbetween = [0, 1]\nstiffness = 10.0\n[run]\ndt = 0.001\nduration = 2.0\n"
        )
    }

    // Oracle: the f64 spacing at t = 2 s (4.4e-16 s) times the resolvable margin (1e3) gives
    // 4.4e-13 s. Gravity of 1e300 m/s² across 1 m has a time scale of 1e-150 s and drag of
    // 1e300 N·s/m on 0.05 kg one of 5e-302 s: both refused, naming their field. The twins near
    // the edge: |g| = 1e23 m/s² (3.2e-12 s) and drag 1e9 N·s/m (5e-11 s) are resolvable.
    #[test]
    fn unresolvable_gravity_and_drag_are_refused_naming_the_field() {
        for (world, field) in [
            ("gravity = [0.0, -1e300, 0.0]", "world.gravity"),
            ("drag = 1e300", "world.drag"),
        ] {
            let e = Scenario::from_toml_str(&scene(world), "s.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains(field) && e.contains("time scale"), "{e}");
            assert!(e.contains("s.toml"), "{e}");
        }
        for world in ["gravity = [0.0, -1e23, 0.0]", "drag = 1e9"] {
            Scenario::from_toml_str(&scene(world), "s.toml").expect(world);
        }
    }
}
