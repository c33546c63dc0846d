//! `springlab check`: validate a scene and show what it will build, without running it.

use super::common::load;
use anyhow::Result;
use std::path::PathBuf;

/// Flags of `springlab check`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Print every particle, spring, constraint, impulse and obstacle even for large scenes
    /// (otherwise each list stops at 20 entries and says how many it left out).
    #[arg(long)]
    pub all: bool,
}

/// Entries a list shows without `--all`.
const SHORT_LIST: usize = 20;

/// The line closing a list of `total` entries of which `shown` were printed.
fn left_out(total: usize, shown: usize) {
    if total > shown {
        println!(
            "  … {} more not shown (--all lists every one)",
            total - shown
        );
    }
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    let scene = load(&a.scenario)?;
    // The scene's own [run] step and length, when it gives them, are held to what `run`
    // refuses without flags (a step longer than the run, too many steps, impulses that would
    // never act at that step and events mode).
    let has_length = scene.run.duration.is_some() || scene.run.steps.is_some();
    let own_run = if scene.run.dt.is_some() && has_length {
        Some(springlab::scenario::Timing::resolve(&scene, None, None)?)
    } else {
        None
    };
    let sys = scene.build();
    let limit = if a.all { usize::MAX } else { SHORT_LIST };
    println!(
        "scenario '{}' ({}): valid",
        scene.name,
        scene.source.display()
    );
    if !scene.description.is_empty() {
        println!("  {}", scene.description);
    }
    print_lists(&scene, &sys, limit);
    if let Some(t) = &own_run {
        println!("run: dt = {} s, {} steps ({} s)", t.dt, t.steps, t.duration);
    }
    println!(
        "answers: tolerance {}; at a free step and at {} Hz",
        match scene.run.tolerance {
            Some(t) => format!("{t} m ([run] tolerance)"),
            None => format!(
                "{} % of the motion scale (the reference measures it when a command runs)",
                springlab::measure::tolerance::RELATIVE_TOLERANCE * 100.0
            ),
        },
        scene.run.hz.unwrap_or(springlab::measure::answer::GAME_HZ)
    );
    print_collision(&scene, limit);
    println!("active terms: {}", sys.active_terms().join(", "));
    print_methods(&sys);
    print_expect(&scene);
    Ok(())
}

/// Lists the particles, springs, constraints and impulses, each list cut at `limit` entries.
fn print_lists(
    scene: &springlab::scenario::Scenario,
    sys: &springlab::model::System,
    limit: usize,
) {
    println!(
        "particles: {} ({} free, {} fixed)",
        scene.particles.len(),
        scene.free_count(),
        scene.particles.len() - scene.free_count()
    );
    for (i, p) in scene.particles.iter().enumerate().take(limit) {
        let x = p.position;
        println!(
            "  [{i}] x = ({}, {}, {}) m, m = {} kg, radius = {} m{}",
            x.x,
            x.y,
            x.z,
            p.mass,
            p.radius,
            if p.fixed { ", fixed" } else { "" }
        );
    }
    left_out(scene.particles.len(), limit);
    println!("springs: {}", sys.springs.len());
    for s in 0..sys.springs.len().min(limit) {
        let sp = &sys.springs;
        println!(
            "  [{s}] {}-{}: k = {} N/m, l0 = {} m, c = {} N·s/m",
            sp.i[s], sp.j[s], sp.k[s], sp.l0[s], sp.c[s]
        );
    }
    left_out(sys.springs.len(), limit);
    println!("constraints: {}", sys.constraints.len());
    for (k, c) in sys.constraints.iter().enumerate().take(limit) {
        println!("  [{k}] {}-{}: length = {} m", c.i, c.j, c.length);
    }
    left_out(sys.constraints.len(), limit);
    println!(
        "impulses: {} (events = \"{}\": {})",
        sys.impulses.len(),
        sys.events.label(),
        match sys.events {
            springlab::model::Events::Exact => "each acts at its own time",
            springlab::model::Events::Frame =>
                "each acts at the first frame boundary at or after its time",
        }
    );
    for (k, im) in sys.impulses.iter().enumerate().take(limit) {
        let d = im.delta_v;
        println!(
            "  [{k}] t = {} s: particle {}, Δv = ({}, {}, {}) m/s",
            im.time, im.particle, d.x, d.y, d.z
        );
    }
    left_out(sys.impulses.len(), limit);
}

/// Names the methods that apply to the scene and why each other one does not.
fn print_methods(sys: &springlab::model::System) {
    let mut applicable = Vec::new();
    let mut refused = Vec::new();
    for m in springlab::method::Registry::builtin().iter() {
        match m.create(&Default::default()).check(sys) {
            Ok(()) => applicable.push(m.info.name),
            Err(why) => refused.push((m.info.name, why)),
        }
    }
    println!(
        "methods that apply (native and Rapier): {}",
        applicable.join(", ")
    );
    for (name, why) in refused {
        println!("  not {name}: {why}");
    }
}

/// Shows the scene's [expect] table and the checks it holds the scene to, when it has one.
fn print_expect(scene: &springlab::scenario::Scenario) {
    use springlab::measure::expect::{describe, expectations};
    let Some(e) = &scene.expect else {
        return;
    };
    println!("expect: {} (`springlab expect` measures it)", describe(e));
    let list = expectations(e);
    if list.is_empty() {
        println!("  (no checks: the run only has to complete)");
    }
    for x in list {
        println!("  {x}");
    }
}

/// A vector as `(x, y, z)`.
fn v3(v: &springlab::model::Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

/// Lists the obstacles (shape, pose, restitution, friction) and the contact response.
fn print_collision(scene: &springlab::scenario::Scenario, limit: usize) {
    use springlab::collide::{mesh, PenaltyDamping, Response, ShapeDef};
    let Some(c) = &scene.collision else {
        println!("obstacles: 0");
        return;
    };
    println!("obstacles: {}", c.obstacles.len());
    for (k, o) in c.obstacles.iter().enumerate().take(limit) {
        let geometry = match &o.shape {
            ShapeDef::Plane { point, normal } => {
                format!("point = {}, normal = {}", v3(point), v3(normal))
            }
            ShapeDef::Sphere { center, radius } => {
                format!("center = {}, radius = {radius} m", v3(center))
            }
            ShapeDef::Box {
                center,
                half_extents,
                rotation,
            } => format!(
                "center = {}, half_extents = {}, rotation = {} (axis·angle, rad)",
                v3(center),
                v3(half_extents),
                v3(rotation)
            ),
            ShapeDef::Capsule { a, b, radius } => {
                format!("a = {}, b = {}, radius = {radius} m", v3(a), v3(b))
            }
            ShapeDef::Mesh {
                vertices,
                triangles,
            } => format!(
                "{} vertices, {} triangles, {}",
                vertices.len(),
                triangles.len(),
                if mesh::is_closed(vertices, triangles) {
                    "closed (solid inside)"
                } else {
                    "open (two-sided sheet)"
                }
            ),
        };
        println!(
            "  [{k}] {}: {geometry}; restitution = {}, friction = {}",
            o.shape.kind(),
            o.restitution,
            o.friction
        );
    }
    left_out(c.obstacles.len(), limit);
    let response = match c.response {
        Response::Penalty { stiffness, damping } => format!(
            "penalty, stiffness = {stiffness} N/m, {}",
            match damping {
                PenaltyDamping::Coefficient(d) => format!("damping = {d} N·s/m"),
                PenaltyDamping::Restitution(e) => format!("damping from restitution = {e}"),
                PenaltyDamping::PerObstacle => "damping from each obstacle's restitution".into(),
            }
        ),
        r => r.name().to_string(),
    };
    println!("contact response: {response}");
}
