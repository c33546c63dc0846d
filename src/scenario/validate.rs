//! Turning a parsed [`ScenarioFile`] into a [`Scenario`], rejecting every impossible value with
//! the field path that holds it.

use super::checker::Checker;
use super::file::{ScenarioFile, SpringLaw};
use super::finite::check_finite;
use super::generate;
use super::run_table::{validate_expect, validate_run};
use super::words::{ChainEnd, Corner, Plane};
use super::{initial_distance, Block, Particle, RunSettings, Scenario, SpringDef};
use crate::error::Result;
use crate::model::{DistanceConstraint, Impulse, Vec3};
use std::collections::HashSet;
use std::path::Path;

use super::checker::{MAX_NAME_BYTES, MAX_PARTICLES};

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
    let expect = validate_expect(&ck, &raw, &run)?;
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
    let end = scene
        .run
        .duration
        .or_else(|| Some(scene.run.dt? * scene.run.steps? as f64))
        .unwrap_or(1.0);
    super::time_scales::check_resolvable(&ck, &scene, end)?;
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
        ck.names(&format!("{f}.fix"), &c.fix, &ChainEnd::words())?;
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
        ck.names(&format!("{f}.fix"), &c.fix, &Corner::words())?;
        if let Some(p) = &c.plane {
            ck.names(
                &format!("{f}.plane"),
                std::slice::from_ref(p),
                &Plane::words(),
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
    let Some(end) = run.length() else {
        return Ok(());
    };
    for (k, im) in raw.impulse.iter().enumerate() {
        if let Some(why) = super::timing::impulse_after_run(im.time, end) {
            return Err(ck.err(format!("impulse[{k}].time"), why));
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
