//! `springlab check`: validate a scene and show what it will build, without running it.

use super::common::load;
use anyhow::Result;
use std::path::PathBuf;

/// Flags of `springlab check`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Print every particle and spring even for large scenes.
    #[arg(long)]
    pub all: bool,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    let scene = load(&a.scenario)?;
    let sys = scene.build();
    let limit = if a.all { usize::MAX } else { 20 };
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
    println!("springs: {}", sys.springs.len());
    for s in 0..sys.springs.len().min(limit) {
        let sp = &sys.springs;
        println!(
            "  [{s}] {}-{}: k = {} N/m, l0 = {} m, c = {} N·s/m",
            sp.i[s], sp.j[s], sp.k[s], sp.l0[s], sp.c[s]
        );
    }
    println!("constraints: {}", sys.constraints.len());
    for (k, c) in sys.constraints.iter().enumerate().take(limit) {
        println!("  [{k}] {}-{}: length = {} m", c.i, c.j, c.length);
    }
    println!("impulses: {}", sys.impulses.len());
    println!("active terms: {}", sys.active_terms().join(", "));
    let applicable: Vec<&str> = springlab::method::Registry::builtin()
        .iter()
        .filter(|m| m.create(&Default::default()).check(&sys).is_ok())
        .map(|m| m.info.name)
        .collect();
    println!("integrators that apply: {}", applicable.join(", "));
    Ok(())
}
