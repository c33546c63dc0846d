//! Turning a parsed [`ScenarioFile`] into a [`Scenario`], rejecting every impossible value with
//! the field path that holds it.

use super::file::{ScenarioFile, SpringLaw, Triple};
use super::generate;
use super::{initial_distance, Block, Expect, Particle, RunSettings, Scenario, SpringDef};
use crate::error::{num, Error, Result};
use crate::model::{DistanceConstraint, Impulse, Vec3};
use std::collections::HashSet;
use std::path::Path;

/// Most particles one scene may hold (a 3162×3162 cloth).
pub const MAX_PARTICLES: usize = 10_000_000;
/// Longest scene name in bytes: it becomes a directory name, which holds at most 255.
pub const MAX_NAME_BYTES: usize = 255;
/// Most steps one run may take.
pub const MAX_STEPS: u64 = 10_000_000_000;

struct Checker<'a> {
    file: &'a Path,
}

impl Checker<'_> {
    fn err(&self, field: impl Into<String>, msg: impl Into<String>) -> Error {
        Error::invalid(self.file, field, msg)
    }
    fn finite(&self, field: &str, x: f64) -> Result<f64> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be a finite number, got {}", num(x))))
        }
    }
    fn positive(&self, field: &str, x: f64) -> Result<f64> {
        self.finite(field, x)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be > 0, got {}", num(x))))
        }
    }
    fn non_negative(&self, field: &str, x: f64) -> Result<f64> {
        self.finite(field, x)?;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be >= 0, got {}", num(x))))
        }
    }
    fn triple(&self, field: &str, t: Triple) -> Result<Vec3> {
        for (k, c) in t.iter().enumerate() {
            self.finite(&format!("{field}[{k}]"), *c)?;
        }
        Ok(Vec3::from(t))
    }
    fn index(&self, field: &str, i: i64, n: usize) -> Result<usize> {
        if i < 0 || i as u64 >= n as u64 {
            Err(self.err(
                field,
                format!(
                    "particle index {i} does not exist (the scene has {n} particles, 0..{})",
                    n.saturating_sub(1)
                ),
            ))
        } else {
            Ok(i as usize)
        }
    }
    fn pair(&self, field: &str, b: [i64; 2], n: usize) -> Result<(usize, usize)> {
        let i = self.index(&format!("{field}.between[0]"), b[0], n)?;
        let j = self.index(&format!("{field}.between[1]"), b[1], n)?;
        if i == j {
            return Err(self.err(
                format!("{field}.between[1]"),
                format!("joins particle {i} to itself"),
            ));
        }
        Ok((i, j))
    }
    fn count(&self, field: &str, c: i64, min: i64) -> Result<usize> {
        if c < min || c as u64 > MAX_PARTICLES as u64 {
            Err(self.err(
                field,
                format!("must be between {min} and {MAX_PARTICLES}, got {c}"),
            ))
        } else {
            Ok(c as usize)
        }
    }
    fn names(&self, field: &str, given: &[String], allowed: &[&str]) -> Result<()> {
        for (k, g) in given.iter().enumerate() {
            if !allowed.contains(&g.as_str()) {
                return Err(self.err(
                    format!("{field}[{k}]"),
                    format!(
                        "unknown value '{g}'; expected one of: {}",
                        allowed.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Validates a parsed file and resolves defaults; `file` labels errors and gives the default name.
pub fn validate(raw: ScenarioFile, file: &Path) -> Result<Scenario> {
    let ck = Checker { file };
    let mut particles = validate_particles(&ck, &raw)?;
    let mut generated = Vec::new();
    let blocks = validate_blocks(&ck, &raw, &mut particles, &mut generated)?;
    if particles.is_empty() {
        return Err(ck.err(
            "particle",
            "the scene has no particles: add [[particle]], [[chain]] or [[cloth]]",
        ));
    }
    // Explicit springs come before generated ones in the final list, so indices in errors match the file.
    let mut springs = validate_springs(&ck, &raw, &particles)?;
    springs.extend(generated.into_iter().map(|mut s| {
        s.rest_length = Some(initial_distance(&particles, s.i, s.j));
        s
    }));
    let constraints = validate_constraints(&ck, &raw, &particles)?;
    let impulses = validate_impulses(&ck, &raw, &particles)?;
    let gravity = match raw.world.gravity {
        Some(g) => Some(ck.triple("world.gravity", g)?),
        None => None,
    };
    let drag = match raw.world.drag {
        Some(d) => Some(ck.non_negative("world.drag", d)?).filter(|&d| d > 0.0),
        None => None,
    };
    let run = validate_run(&ck, &raw)?;
    impulses_within_run(&ck, &raw, &run)?;
    let collision = super::obstacle_validate::validate_collision(&raw, file)?;
    let name = validate_name(&ck, &raw, file)?;
    let expect = validate_expect(&ck, &raw)?;
    let mut scene = Scenario {
        name,
        description: raw.description.clone().unwrap_or_default(),
        source: file.to_path_buf(),
        particles,
        springs,
        constraints,
        impulses,
        gravity,
        drag,
        run,
        blocks,
        collision,
        expect,
        raw,
    };
    // Checked without the obstacles: their shapes are built by the commands that run the
    // scene, and their own values were checked above.
    let collision = scene.collision.take();
    check_finite(&ck, &scene)?;
    scene.collision = collision;
    Ok(scene)
}

/// The `[[particle]]` tables: finite positions and velocities, positive masses (a fixed
/// particle may weigh nothing), non-negative radii.
fn validate_particles(ck: &Checker, raw: &ScenarioFile) -> Result<Vec<Particle>> {
    let mut particles = Vec::new();
    for (k, p) in raw.particle.iter().enumerate() {
        let f = format!("particle[{k}]");
        let position = ck.triple(&format!("{f}.position"), p.position)?;
        let velocity = ck.triple(&format!("{f}.velocity"), p.velocity)?;
        let mass = if p.fixed {
            ck.non_negative(&format!("{f}.mass"), p.mass)?
        } else {
            ck.positive(&format!("{f}.mass"), p.mass)?
        };
        let radius = ck.non_negative(&format!("{f}.radius"), p.radius)?;
        particles.push(Particle {
            position,
            velocity,
            mass,
            fixed: p.fixed,
            radius,
        });
    }
    Ok(particles)
}

/// The `[[chain]]` and `[[cloth]]` generators: their values checked, their particles appended
/// to `particles` and their springs to `springs` (rest lengths set later), within
/// [`MAX_PARTICLES`].
fn validate_blocks(
    ck: &Checker,
    raw: &ScenarioFile,
    particles: &mut Vec<Particle>,
    springs: &mut Vec<SpringDef>,
) -> Result<Vec<Block>> {
    let mut blocks = Vec::new();
    for (k, c) in raw.chain.iter().enumerate() {
        let f = format!("chain[{k}]");
        ck.triple(&format!("{f}.start"), c.start)?;
        ck.triple(&format!("{f}.end"), c.end)?;
        let n = ck.count(&format!("{f}.count"), c.count, 2)?;
        ck.positive(&format!("{f}.mass"), c.mass)?;
        ck.non_negative(&format!("{f}.stiffness"), c.stiffness)?;
        ck.non_negative(&format!("{f}.damping"), c.damping)?;
        ck.names(&format!("{f}.fix"), &c.fix, &["first", "last"])?;
        if Vec3::from(c.start) == Vec3::from(c.end) {
            return Err(ck.err(
                format!("{f}.end"),
                "equals start: the chain's springs would have zero rest length",
            ));
        }
        if particles.len() + n > MAX_PARTICLES {
            return Err(ck.err(
                format!("{f}.count"),
                format!("the scene would exceed {MAX_PARTICLES} particles"),
            ));
        }
        blocks.push(generate::chain(c, particles, springs));
    }
    for (k, c) in raw.cloth.iter().enumerate() {
        let f = format!("cloth[{k}]");
        ck.triple(&format!("{f}.origin"), c.origin)?;
        ck.positive(&format!("{f}.size[0]"), c.size[0])?;
        ck.positive(&format!("{f}.size[1]"), c.size[1])?;
        let nx = ck.count(&format!("{f}.count[0]"), c.count[0], 2)?;
        let ny = ck.count(&format!("{f}.count[1]"), c.count[1], 2)?;
        if (nx as u64) * (ny as u64) + particles.len() as u64 > MAX_PARTICLES as u64 {
            return Err(ck.err(
                format!("{f}.count"),
                format!("{nx}×{ny} would exceed {MAX_PARTICLES} particles"),
            ));
        }
        ck.positive(&format!("{f}.mass"), c.mass)?;
        ck.non_negative(&format!("{f}.stiffness"), c.stiffness)?;
        ck.non_negative(&format!("{f}.damping"), c.damping)?;
        ck.non_negative(&format!("{f}.bend_stiffness"), c.bend_stiffness)?;
        ck.names(
            &format!("{f}.fix"),
            &c.fix,
            &["top_left", "top_right", "bottom_left", "bottom_right"],
        )?;
        if let Some(p) = &c.plane {
            ck.names(
                &format!("{f}.plane"),
                std::slice::from_ref(p),
                &["xy", "xz"],
            )
            .map_err(|_| {
                ck.err(
                    format!("{f}.plane"),
                    format!("unknown value '{p}'; expected xy or xz"),
                )
            })?;
        }
        blocks.push(generate::cloth(c, particles, springs));
    }
    Ok(blocks)
}

/// The `[[spring]]` tables: two distinct particles joined once, non-negative stiffness and
/// damping, the rest length as given or the initial distance (never 0 under the strain law).
fn validate_springs(
    ck: &Checker,
    raw: &ScenarioFile,
    particles: &[Particle],
) -> Result<Vec<SpringDef>> {
    let n = particles.len();
    let mut springs = Vec::new();
    let mut seen = HashSet::new();
    for (k, s) in raw.spring.iter().enumerate() {
        let f = format!("spring[{k}]");
        let (i, j) = ck.pair(&f, s.between, n)?;
        let stiffness = ck.non_negative(&format!("{f}.stiffness"), s.stiffness)?;
        let damping = ck.non_negative(&format!("{f}.damping"), s.damping)?;
        let rest = match s.rest_length {
            Some(l) => ck.non_negative(&format!("{f}.rest_length"), l)?,
            None => initial_distance(particles, i, j),
        };
        if s.law == SpringLaw::Strain && rest <= 0.0 {
            let why = if s.rest_length.is_some() {
                "is 0"
            } else {
                "defaults to the initial distance, which is 0"
            };
            return Err(ck.err(
                format!("{f}.rest_length"),
                format!("{why}: the strain law divides by the rest length"),
            ));
        }
        if !seen.insert((i.min(j), i.max(j))) {
            return Err(ck.err(format!("{f}.between"), format!("duplicate spring: particles {i} and {j} are already joined by an earlier spring")));
        }
        springs.push(SpringDef {
            i,
            j,
            stiffness,
            rest_length: Some(rest),
            damping,
            law: s.law,
        });
    }
    Ok(springs)
}

/// The `[[constraint]]` tables: a positive length (as given or the initial distance), not both
/// ends fixed, non-negative compliance.
fn validate_constraints(
    ck: &Checker,
    raw: &ScenarioFile,
    particles: &[Particle],
) -> Result<Vec<DistanceConstraint>> {
    let mut constraints = Vec::new();
    for (k, c) in raw.constraint.iter().enumerate() {
        let f = format!("constraint[{k}]");
        let (i, j) = ck.pair(&f, c.between, particles.len())?;
        let length = match c.length {
            Some(l) => ck.positive(&format!("{f}.length"), l)?,
            None => {
                let d = initial_distance(particles, i, j);
                if d <= 0.0 {
                    return Err(ck.err(
                        format!("{f}.length"),
                        "defaults to the initial distance, which is 0",
                    ));
                }
                d
            }
        };
        if particles[i].fixed && particles[j].fixed {
            return Err(ck.err(
                format!("{f}.between"),
                "both particles are fixed: the constraint can do nothing",
            ));
        }
        let compliance = ck.non_negative(&format!("{f}.compliance"), c.compliance)?;
        constraints.push(DistanceConstraint {
            i,
            j,
            length,
            compliance,
        });
    }
    Ok(constraints)
}

/// The `[[impulse]]` tables, sorted by time: a non-negative time, a free particle, a finite
/// velocity change.
fn validate_impulses(
    ck: &Checker,
    raw: &ScenarioFile,
    particles: &[Particle],
) -> Result<Vec<Impulse>> {
    let mut impulses = Vec::new();
    for (k, im) in raw.impulse.iter().enumerate() {
        let f = format!("impulse[{k}]");
        let time = ck.non_negative(&format!("{f}.time"), im.time)?;
        let particle = ck.index(&format!("{f}.particle"), im.particle, particles.len())?;
        if particles[particle].fixed {
            return Err(ck.err(
                format!("{f}.particle"),
                format!("particle {particle} is fixed and cannot be kicked"),
            ));
        }
        let delta_v = ck.triple(&format!("{f}.delta_v"), im.delta_v)?;
        impulses.push(Impulse {
            time,
            particle,
            delta_v,
        });
    }
    impulses.sort_by(|a, b| a.time.total_cmp(&b.time));
    Ok(impulses)
}

/// The file's own run length: no impulse may fall at or after it (it would never act).
fn impulses_within_run(ck: &Checker, raw: &ScenarioFile, run: &RunSettings) -> Result<()> {
    let end = run
        .duration
        .or_else(|| run.steps.zip(run.dt).map(|(n, dt)| n as f64 * dt));
    let Some(end) = end else {
        return Ok(());
    };
    for (k, im) in raw.impulse.iter().enumerate() {
        if im.time >= end * (1.0 - 1e-9) {
            return Err(ck.err(
                format!("impulse[{k}].time"),
                format!(
                    "{} s is at or after the end of the run at {end} s; impulses must act within [0, {end}) s",
                    im.time
                ),
            ));
        }
    }
    Ok(())
}

/// The scene's name (as given, else the file's stem): it becomes a directory name, so it
/// must be one.
fn validate_name(ck: &Checker, raw: &ScenarioFile, file: &Path) -> Result<String> {
    let name = raw.name.clone().unwrap_or_else(|| {
        file.file_stem()
            .map_or("scenario".into(), |s| s.to_string_lossy().into_owned())
    });
    if name.is_empty() || name.contains(['/', '\\']) || name == "." || name == ".." {
        return Err(ck.err(
            "name",
            format!("'{name}' cannot be used as a directory name"),
        ));
    }
    if name.contains('\0') {
        return Err(ck.err(
            "name",
            format!("{name:?} holds a NUL byte, which cannot be in a directory name"),
        ));
    }
    if name.len() > MAX_NAME_BYTES {
        return Err(ck.err(
            "name",
            format!(
                "is {} bytes long; a directory name holds at most {MAX_NAME_BYTES}",
                name.len()
            ),
        ));
    }
    Ok(name)
}

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

/// Refuses a scene whose initial state f64 cannot hold: a position whose squared distance
/// from the origin overflows (every distance and energy would be infinite or NaN), an
/// infinite kinetic, gravitational or elastic energy, an infinite force, or a spring whose
/// two ends coincide while its rest length is not zero (it has no direction to act along).
/// The error names the field that holds the value at fault. `scene` comes without its
/// obstacles (contact forces are not part of the check).
/// Long because each check names its own field in its error; the checks share one pass over the scene.
fn check_finite(ck: &Checker, scene: &Scenario) -> Result<()> {
    let v3 = |v: &Vec3| format!("({}, {}, {})", num(v.x), num(v.y), num(v.z));
    let at = |p: usize, what: &str| {
        let f = particle_field(scene, p);
        if p < scene.raw.particle.len() {
            (format!("{f}.{what}"), String::new())
        } else {
            (f, format!("its particle {p}: "))
        }
    };
    for (p, q) in scene.particles.iter().enumerate() {
        if !q.position.norm_squared().is_finite() {
            let (f, who) = at(p, "position");
            return Err(ck.err(f, format!("{who}the position {} m is too far from the origin for f64: its squared length overflows, so distances and energies would be infinite or NaN (keep every coordinate below 1e154 m)", v3(&q.position))));
        }
        if !q.fixed && !(q.mass * q.velocity.norm_squared()).is_finite() {
            let (f, who) = at(p, "velocity");
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
    let sys = scene.build();
    let s0 = scene.initial_state();
    let sp = &sys.springs;
    let length = |s: usize| (s0.x[sp.j[s] as usize] - s0.x[sp.i[s] as usize]).norm();
    let spring_at_fault = || {
        (0..sp.len()).find(|&s| {
            let stretch = length(s) - sp.l0[s];
            !(0.5 * sp.k[s] * stretch * stretch).is_finite()
        })
    };
    let spring_err = |s: usize, what: &str| {
        let l = length(s);
        let field = format!("{}.stiffness", spring_field(scene, s));
        ck.err(field, format!("the {what} of spring {s} (particles {} and {}), stiffness {} N/m at length {} m and rest length {} m, is not finite in f64", sp.i[s], sp.j[s], num(sp.k[s]), num(l), num(sp.l0[s])))
    };
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
    if !e.elastic.is_finite() {
        if let Some(s) = spring_at_fault() {
            return Err(spring_err(s, "energy ½k(l - l0)²"));
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
        return Err(ck.err(
            "(scene)",
            format!(
                "the initial elastic energy of the scene is {} J, not finite in f64",
                num(e.elastic)
            ),
        ));
    }
    let mut f = vec![Vec3::zeros(); sys.len()];
    sys.forces(&s0.x, &s0.v, &mut f);
    if let Some(p) = f
        .iter()
        .position(|fi| !(fi.x.is_finite() && fi.y.is_finite() && fi.z.is_finite()))
    {
        // The elastic energy was finite, so a spring at fault is one whose force overflows.
        if let Some(s) = (0..sp.len()).find(|&s| !(sp.k[s] * (length(s) - sp.l0[s])).is_finite()) {
            return Err(spring_err(s, "force k(l - l0)"));
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
        let (field, who) = at(p, "position");
        return Err(ck.err(
            field,
            format!(
                "{who}the initial force on particle {p} is {} N, not finite in f64",
                v3(&f[p])
            ),
        ));
    }
    Ok(())
}

fn validate_run(ck: &Checker, raw: &ScenarioFile) -> Result<RunSettings> {
    let Some(r) = &raw.run else {
        return Ok(RunSettings {
            dt: None,
            steps: None,
            duration: None,
            integrators: Vec::new(),
            events: Default::default(),
            tolerance: None,
            hz: None,
        });
    };
    let dt = match r.dt {
        Some(dt) => Some(ck.positive("run.dt", dt)?),
        None => None,
    };
    let steps = match r.steps {
        Some(s) if s < 1 || s as u64 > MAX_STEPS => {
            return Err(ck.err(
                "run.steps",
                format!("must be between 1 and {MAX_STEPS}, got {s}"),
            ))
        }
        Some(s) => Some(s as u64),
        None => None,
    };
    let duration = match r.duration {
        Some(d) => Some(ck.positive("run.duration", d)?),
        None => None,
    };
    match (steps, duration) {
        (Some(_), Some(_)) => {
            return Err(ck.err(
                "run",
                "give exactly one of `steps` and `duration`, not both",
            ))
        }
        (None, None) => return Err(ck.err("run", "give exactly one of `steps` and `duration`")),
        _ => {}
    }
    if let (Some(dt), Some(d)) = (dt, duration) {
        if dt > d * (1.0 + 1e-12) {
            return Err(ck.err(
                "run.dt",
                format!("{} s is longer than run.duration = {} s: one step would end the run at {} s, after its duration; give a step ≤ the duration", num(dt), num(d), num(dt)),
            ));
        }
        if d / dt > MAX_STEPS as f64 {
            return Err(ck.err(
                "run.duration",
                format!("duration / dt = {:.3e} steps exceeds {MAX_STEPS}", d / dt),
            ));
        }
    }
    let integrators = r.integrators.clone().unwrap_or_default();
    for (k, name) in integrators.iter().enumerate() {
        if crate::method::Registry::builtin().find(name).is_none() {
            return Err(ck.err(
                format!("run.integrators[{k}]"),
                format!(
                    "unknown integrator '{name}'; known: {}",
                    crate::method::Registry::builtin().names().join(", ")
                ),
            ));
        }
    }
    let events = match &r.events {
        Some(e) => crate::model::Events::parse(e).map_err(|why| ck.err("run.events", why))?,
        None => Default::default(),
    };
    let tolerance = match r.tolerance {
        Some(t) => Some(ck.positive("run.tolerance", t)?),
        None => None,
    };
    let hz = match r.hz {
        Some(h) => Some(ck.positive("run.hz", h)?),
        None => None,
    };
    Ok(RunSettings {
        dt,
        steps,
        duration,
        integrators,
        events,
        tolerance,
        hz,
    })
}

/// Checks `[expect]`: a registered integrator, exactly one positive finite `hz` or `dt`,
/// `substeps` ≥ 1, and positive finite limits.
fn validate_expect(ck: &Checker, raw: &ScenarioFile) -> Result<Option<Expect>> {
    let Some(e) = &raw.expect else {
        return Ok(None);
    };
    let registry = crate::method::Registry::builtin();
    if registry.find(&e.integrator).is_none() {
        return Err(ck.err(
            "expect.integrator",
            format!(
                "unknown integrator '{}'; known: {}",
                e.integrator,
                registry.names().join(", ")
            ),
        ));
    }
    let frame_dt = match (e.hz, e.dt) {
        (Some(_), Some(_)) => {
            return Err(ck.err("expect", "give exactly one of `hz` and `dt`, not both"))
        }
        (None, None) => return Err(ck.err("expect", "give exactly one of `hz` and `dt`")),
        (Some(hz), None) => 1.0 / ck.positive("expect.hz", hz)?,
        (None, Some(dt)) => ck.positive("expect.dt", dt)?,
    };
    let substeps = match e.substeps {
        None => 1,
        Some(n) if (1..=MAX_STEPS as i64).contains(&n) => n as u64,
        Some(n) => {
            return Err(ck.err(
                "expect.substeps",
                format!("must be between 1 and {MAX_STEPS}, got {n}"),
            ))
        }
    };
    let limit = |field: &str, v: Option<f64>| -> Result<Option<f64>> {
        v.map(|x| ck.positive(&format!("expect.{field}"), x))
            .transpose()
    };
    Ok(Some(Expect {
        integrator: e.integrator.clone(),
        frame_dt,
        substeps,
        stable: e.stable,
        max_position_error: limit("max_position_error", e.max_position_error)?,
        max_strain: limit("max_strain", e.max_strain)?,
        max_energy_drift_rate: limit("max_energy_drift_rate", e.max_energy_drift_rate)?,
    }))
}
