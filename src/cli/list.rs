//! `springlab list`: the methods (with the options each reads) and the shipped scenarios, one
//! line each.

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

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    let files = springlab::report::scenario_files(&a.scenarios)?;
    println!("methods:");
    for m in springlab::method::Registry::builtin().iter() {
        let i = &m.info;
        let aliases = if i.aliases.is_empty() {
            String::new()
        } else {
            format!(" (alias {})", i.aliases.join(", "))
        };
        let options: String = i
            .options
            .iter()
            .map(|o| {
                format!(
                    " [--{} {}, default {}]",
                    o.flag,
                    super::method_args::value_name(&o.kind),
                    o.default_value()
                )
            })
            .collect();
        println!(
            "  {:<22} order {:<5} {}{aliases}{options}",
            i.name,
            i.order.to_string(),
            i.summary
        );
    }
    println!("scenarios ({}):", a.scenarios.display());
    for path in files {
        match Scenario::from_file(&path) {
            Ok(s) => {
                let first = s.description.lines().next().unwrap_or("");
                println!(
                    "  {:<22} {} particles, {} springs — {first}",
                    s.name,
                    s.particles.len(),
                    s.springs.len()
                );
            }
            Err(e) => println!("  {:<22} INVALID: {e}", path.display()),
        }
    }
    Ok(())
}
