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
    println!(
        "particles: {} ({} free, {} fixed)",
        scene.particles.len(),
        scene.free_count(),
        scene.particles.len() - scene.free_count()
    );
    for (i, p) in scene.particles.iter().enumerate().take(limit) {
        let x = p.position;
        println!(
            "  [{i}] x = ({}, {}, {}) m, m = {} kg{}",
            x.x,
            x.y,
            x.z,
            p.mass,
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
    println!("impulses: {}", sys.impulses.len());
    for (k, im) in sys.impulses.iter().enumerate().take(limit) {
        let d = im.delta_v;
        println!(
            "  [{k}] t = {} s: particle {}, Δv = ({}, {}, {}) m/s",
            im.time, im.particle, d.x, d.y, d.z
        );
    }
    left_out(sys.impulses.len(), limit);
    let obstacles = &scene.raw.obstacle;
    println!("obstacles: {}", obstacles.len());
    for (k, o) in obstacles.iter().enumerate().take(limit) {
        let v = |t: Option<[f64; 3]>| t.map(|t| format!("({}, {}, {})", t[0], t[1], t[2]));
        let geometry = [
            ("point", v(o.point)),
            ("normal", v(o.normal)),
            ("center", v(o.center)),
            ("radius", o.radius.map(|r| format!("{r} m"))),
            ("half_extents", v(o.half_extents)),
            ("rotation", v(o.rotation)),
            ("a", v(o.a)),
            ("b", v(o.b)),
            ("file", o.file.clone()),
            ("vertices", o.vertices.as_ref().map(|x| x.len().to_string())),
            (
                "triangles",
                o.triangles.as_ref().map(|x| x.len().to_string()),
            ),
        ]
        .into_iter()
        .filter_map(|(n, x)| x.map(|x| format!("{n} = {x}")))
        .collect::<Vec<_>>()
        .join(", ");
        println!("  [{k}] {}: {geometry}", o.shape);
    }
    left_out(obstacles.len(), limit);
    println!("active terms: {}", sys.active_terms().join(", "));
    let applicable: Vec<&str> = springlab::method::Registry::builtin()
        .iter()
        .filter(|m| m.create(&Default::default()).check(&sys).is_ok())
        .map(|m| m.info.name)
        .collect();
    println!("integrators that apply: {}", applicable.join(", "));
    Ok(())
}
