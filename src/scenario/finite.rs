//! The scene's initial state in f64: no position, energy or force that overflows, and no
//! spring without a direction to act along; each error names the field at fault.

use super::checker::Checker;
use super::Scenario;
use crate::error::{num, Error, Result};
use crate::model::{State, System, Vec3};

/// The field a particle comes from: `particle[k]`, or the `chain[k]`/`cloth[k]` that made it.
fn particle_field(scene: &Scenario, p: usize) -> String {
    if p < scene.raw.particle.len() {
        return format!("particle[{p}]");
    }
    let mut seen = std::collections::HashMap::new();
    for b in &scene.blocks {
        let k = seen.entry(b.kind).or_insert(0usize);
        if (b.first..b.first + b.shape[0] * b.shape[1]).contains(&p) {
            return format!("{}[{k}]", b.kind);
        }
        *k += 1;
    }
    format!("particle[{p}]")
}

/// The field a spring of the scene comes from: `spring[k]`, or the block that made it.
fn spring_field(scene: &Scenario, s: usize) -> String {
    if s < scene.raw.spring.len() {
        format!("spring[{s}]")
    } else {
        particle_field(scene, scene.springs[s].i)
    }
}

/// A vector as the errors print it.
fn v3(v: &Vec3) -> String {
    format!("({}, {}, {})", num(v.x), num(v.y), num(v.z))
}

/// The field an error about particle `p`'s `what` names, and the prefix that says which
/// particle of a block it is (empty for a `particle[k]`).
fn at(scene: &Scenario, p: usize, what: &str) -> (String, String) {
    let f = particle_field(scene, p);
    if p < scene.raw.particle.len() {
        (format!("{f}.{what}"), String::new())
    } else {
        (f, format!("its particle {p}: "))
    }
}

/// Refuses a scene whose initial state f64 cannot hold: a position whose squared distance
/// from the origin overflows (every distance and energy would be infinite or NaN), an
/// infinite kinetic, gravitational or elastic energy, an infinite force, or a spring whose
/// two ends coincide while its rest length is not zero (it has no direction to act along).
/// The error names the field that holds the value at fault. `scene` comes without its
/// obstacles (contact forces are not part of the check).
pub(super) fn check_finite(ck: &Checker, scene: &Scenario) -> Result<()> {
    check_particles(ck, scene)?;
    check_spring_ends(ck, scene)?;
    let built = Built {
        ck,
        scene,
        sys: scene.build(),
        s0: scene.initial_state(),
    };
    built.check_energy()?;
    built.check_forces()
}

/// Each particle's position within f64's reach and its kinetic energy finite.
fn check_particles(ck: &Checker, scene: &Scenario) -> Result<()> {
    for (p, q) in scene.particles.iter().enumerate() {
        if !q.position.norm_squared().is_finite() {
            let (f, who) = at(scene, p, "position");
            return Err(ck.err(f, format!("{who}the position {} m is too far from the origin for f64: its squared length overflows, so distances and energies would be infinite or NaN (keep every coordinate below 1e154 m)", v3(&q.position))));
        }
        if !q.fixed && !(q.mass * q.velocity.norm_squared()).is_finite() {
            let (f, who) = at(scene, p, "velocity");
            return Err(ck.err(
                f,
                format!(
                    "{who}the kinetic energy of {} kg at {} m/s is not finite in f64",
                    num(q.mass),
                    v3(&q.velocity)
                ),
            ));
        }
    }
    Ok(())
}

/// No `[[spring]]` whose two ends coincide while its rest length is not zero.
fn check_spring_ends(ck: &Checker, scene: &Scenario) -> Result<()> {
    for (k, s) in scene
        .springs
        .iter()
        .enumerate()
        .take(scene.raw.spring.len())
    {
        let (a, b) = (scene.particles[s.i].position, scene.particles[s.j].position);
        let l0 = scene.rest_length(s);
        if a == b && l0 > 0.0 {
            return Err(ck.err(
                format!("spring[{k}].between"),
                format!("its two ends, particles {} and {}, coincide at {} m while its rest length is {} m: the spring has no direction to push along", s.i, s.j, v3(&a), num(l0)),
            ));
        }
    }
    Ok(())
}

/// The scene built, with its initial state: what the energy and force checks evaluate, and
/// what their errors name.
struct Built<'a> {
    ck: &'a Checker<'a>,
    scene: &'a Scenario,
    sys: System,
    s0: State,
}

impl Built<'_> {
    /// The length of spring `s` in the initial state.
    fn length(&self, s: usize) -> f64 {
        let sp = &self.sys.springs;
        (self.s0.x[sp.j[s] as usize] - self.s0.x[sp.i[s] as usize]).norm()
    }

    /// The error naming spring `s`'s stiffness for its `what` that is not finite.
    fn spring_err(&self, s: usize, what: &str) -> Error {
        let sp = &self.sys.springs;
        let l = self.length(s);
        let field = format!("{}.stiffness", spring_field(self.scene, s));
        self.ck.err(field, format!("the {what} of spring {s} (particles {} and {}), stiffness {} N/m at length {} m and rest length {} m, is not finite in f64", sp.i[s], sp.j[s], num(sp.k[s]), num(l), num(sp.l0[s])))
    }

    /// The initial gravitational and elastic energies finite; an infinite elastic energy
    /// is blamed on the spring or constraint that holds it.
    fn check_energy(&self) -> Result<()> {
        let (ck, sys, s0, sp) = (self.ck, &self.sys, &self.s0, &self.sys.springs);
        let e = sys.energy(&s0.x, &s0.v);
        if !e.gravity.is_finite() {
            return Err(ck.err(
                "world.gravity",
                format!(
                    "the initial gravitational energy Σ m g·x of the scene is {} J, not finite in f64",
                    num(e.gravity)
                ),
            ));
        }
        if e.elastic.is_finite() {
            return Ok(());
        }
        let spring_at_fault = (0..sp.len()).find(|&s| {
            let stretch = self.length(s) - sp.l0[s];
            !(0.5 * sp.k[s] * stretch * stretch).is_finite()
        });
        if let Some(s) = spring_at_fault {
            return Err(self.spring_err(s, "energy ½k(l - l0)²"));
        }
        if let Some(k) = sys
            .constraints
            .iter()
            .position(|c| !c.energy(&s0.x).is_finite())
        {
            return Err(ck.err(
                format!("constraint[{k}].compliance"),
                "the initial elastic energy ½·stretch²/compliance is not finite in f64",
            ));
        }
        Err(ck.err(
            "(scene)",
            format!(
                "the initial elastic energy of the scene is {} J, not finite in f64",
                num(e.elastic)
            ),
        ))
    }

    /// Every initial force finite; one that is not is blamed on a spring, gravity or the
    /// particle's position.
    fn check_forces(&self) -> Result<()> {
        let (ck, scene, sys, s0, sp) =
            (self.ck, self.scene, &self.sys, &self.s0, &self.sys.springs);
        let mut f = vec![Vec3::zeros(); sys.len()];
        sys.forces(&s0.x, &s0.v, &mut f);
        let Some(p) = f
            .iter()
            .position(|fi| !(fi.x.is_finite() && fi.y.is_finite() && fi.z.is_finite()))
        else {
            return Ok(());
        };
        // The elastic energy was finite, so a spring at fault is one whose force overflows.
        if let Some(s) =
            (0..sp.len()).find(|&s| !(sp.k[s] * (self.length(s) - sp.l0[s])).is_finite())
        {
            return Err(self.spring_err(s, "force k(l - l0)"));
        }
        let q = &scene.particles[p];
        if let Some(g) = scene.gravity.filter(|g| !(q.mass * g.norm()).is_finite()) {
            return Err(ck.err(
                "world.gravity",
                format!(
                    "the weight m g of {} kg under {} m/s² is not finite in f64",
                    num(q.mass),
                    v3(&g)
                ),
            ));
        }
        let (field, who) = at(scene, p, "position");
        Err(ck.err(
            field,
            format!(
                "{who}the initial force on particle {p} is {} N, not finite in f64",
                v3(&f[p])
            ),
        ))
    }
}
