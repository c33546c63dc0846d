//! Measuring the speed–accuracy trade: references, metrics, convergence, stability, advice.
//!
//! The commands (compare, sweep, stability, advise, framerate, small steps, expect, the
//! study and its answers) are the modules here; what they share sits in four rooms, each
//! importing only the rooms before it: `base`, `truth`, `observe`, `kernel`. Every module
//! keeps its path `measure::<name>`.

mod base;
mod kernel;
mod observe;
mod truth;

pub mod advise;
pub mod answer;
pub mod compare;
pub mod engine_fare;
pub mod expect;
pub mod expect_answer;
pub mod framerate;
pub mod small_steps;
pub mod small_steps_budget;
pub mod stability;
pub mod study;
pub mod sweep;

pub use common::Common;
pub use metrics::{strain_max, Metrics, Quality, QualityObserver};

pub use base::{apexes, grid, observables, probe};
use base::{dop853, kept, modes};
pub use kernel::{case, command, common, tolerance};
pub(crate) use observe::metrics;
pub use observe::{contacts, decimated, metric_table};
use observe::{fit, trace};
pub use truth::{reference, statistics};

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// The rooms in import order.
    const ROOMS: [&str; 4] = ["base", "truth", "observe", "kernel"];

    /// The modules `crate::measure::…` names in `text` (its code before any test module, not
    /// its comments), a group `crate::measure::{a, b::C}` naming each of its members.
    fn imported(text: &str) -> Vec<String> {
        let code: Vec<&str> = text
            .lines()
            .take_while(|l| !l.trim_start().starts_with("#[cfg(test)]"))
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect();
        let code = code.join("\n");
        let ident = |s: &str| -> String {
            s.trim_start()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect()
        };
        let mut out = Vec::new();
        for (i, m) in code.match_indices("crate::measure::") {
            let rest = &code[i + m.len()..];
            match rest.strip_prefix('{') {
                Some(group) => {
                    let group = &group[..group.find('}').unwrap_or(group.len())];
                    out.extend(group.split(',').map(ident).filter(|s| !s.is_empty()));
                }
                None => out.push(ident(rest)),
            }
        }
        out
    }

    /// The room a module of `measure` lives in (`None`: a command, at the top).
    fn room_of(module: &str) -> Option<usize> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/measure");
        if module.is_empty() {
            return None;
        }
        ROOMS.iter().position(|r| {
            let dir = root.join(r);
            dir.join(format!("{module}.rs")).exists() || dir.join(module).is_dir()
        })
    }

    // Oracle: the rule this module's documentation states, read off the source files: a
    // module in a room names no command and no module of a later room. The twin: the commands
    // do import the rooms (compare names the kernel's case), so the check sees imports.
    #[test]
    fn each_room_imports_only_the_rooms_before_it() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/measure");
        let mut checked = 0;
        for (k, room) in ROOMS.iter().enumerate() {
            let mut files = vec![];
            let mut dirs = vec![root.join(room)];
            while let Some(d) = dirs.pop() {
                for e in std::fs::read_dir(&d).unwrap() {
                    let p = e.unwrap().path();
                    if p.is_dir() {
                        dirs.push(p);
                    } else if p.extension().is_some_and(|x| x == "rs") {
                        files.push(p);
                    }
                }
            }
            for f in files {
                let text = std::fs::read_to_string(&f).unwrap();
                for m in imported(&text) {
                    let to = room_of(&m);
                    assert!(
                        to.is_some_and(|r| r <= k),
                        "{} ({room}) imports measure::{m}, which is {}",
                        f.display(),
                        to.map_or("a command".to_string(), |r| format!("in {}", ROOMS[r]))
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 20, "only {checked} imports seen");
        let compare = std::fs::read_to_string(root.join("compare.rs")).unwrap();
        assert!(imported(&compare).iter().any(|m| room_of(m) == Some(3)));
        assert_eq!(
            imported("use crate::measure::{case::X, grid};"),
            ["case", "grid"],
            "a group names each member"
        );
    }
}
