//! `springlab list`: the integrators and the shipped scenarios, one line each.

use anyhow::Result;
use springlab::scenario::Scenario;
use std::path::PathBuf;

/// Flags of `springlab list`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Directory of scenarios to list.
    #[arg(long, default_value = "scenarios")]
    pub scenarios: PathBuf,
}

/// One line per integrator: what it is.
pub const DESCRIPTIONS: &[(&str, &str)] = &[
    (
        "explicit_euler",
        "forward Euler, order 1; unstable on undamped oscillators at every step",
    ),
    (
        "symplectic_euler",
        "semi-implicit Euler (alias semi_implicit_euler), order 1, symplectic; stable for hω < 2",
    ),
    (
        "implicit_euler",
        "backward Euler, Newton + block-Jacobi CG; order 1, stable at any step, damps",
    ),
    ("rk2", "explicit midpoint Runge-Kutta, order 2"),
    (
        "rk4",
        "classic Runge-Kutta, order 4; stable for hω < 2√2 on oscillators",
    ),
    (
        "velocity_verlet",
        "kick-drift-kick Störmer-Verlet, order 2, symplectic; stable for hω < 2",
    ),
    (
        "position_verlet",
        "two-step Störmer form, order 2, symplectic; stable for hω < 2",
    ),
    (
        "verlet_constraints",
        "Verlet + Jakobsen/XPBD projection of rigid constraints (games' ropes and cloth)",
    ),
    (
        "analytic",
        "exact closed form for independent damped springs on fixed anchors",
    ),
    (
        "rapier_impulse",
        "Rapier 0.36 (f64): a body per particle, springs as force-based joint motors",
    ),
    (
        "rapier_multibody",
        "Rapier 0.36 (f64): multibody trees, loop-closing edges as impulse joints",
    ),
];

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    println!("integrators:");
    for name in springlab::integrate::known_names() {
        let desc = DESCRIPTIONS
            .iter()
            .find(|(n, _)| *n == name)
            .map_or("", |(_, d)| d);
        println!("  {name:<20} {desc}");
    }
    println!("scenarios ({}):", a.scenarios.display());
    for path in scenario_files(&a.scenarios)? {
        match Scenario::from_file(&path) {
            Ok(s) => {
                let first = s.description.lines().next().unwrap_or("");
                println!(
                    "  {:<20} {} particles, {} springs — {first}",
                    s.name,
                    s.particles.len(),
                    s.springs.len()
                );
            }
            Err(e) => println!("  {:<20} INVALID: {e}", path.display()),
        }
    }
    Ok(())
}

/// The `*.toml` files of a directory, sorted by name.
pub fn scenario_files(dir: &PathBuf) -> Result<Vec<PathBuf>> {
    let rd = std::fs::read_dir(dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot list scenarios: {e}", dir.display()))?;
    let mut files: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    Ok(files)
}
