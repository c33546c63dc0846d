//! What `run` may write before it starts: the projected size of its CSV outputs against the
//! room it has (the free space of the filesystem that will hold them, the process's file-size
//! limit) and against [`SIZE_WARNING_BYTES`], so a run that cannot finish its files, or one
//! far larger than asked for, is refused before it writes a byte.

use super::run_files::{every_within, human_bytes, projected_run_bytes, written_frames};
use super::SIZE_WARNING_BYTES;
use crate::error::{Error, Result};
use std::path::Path;

/// How the user asked for the outputs' size: `--every` written out, `--force` given.
#[derive(Debug, Clone, Copy, Default)]
pub struct SizeAsk {
    /// `--every` was given on the command line (the size is then the user's choice).
    pub every_given: bool,
    /// `--force`: write even past the free space or a file-size limit.
    pub force: bool,
}

/// The projection line `run` prints, and a warning when the outputs pass
/// [`SIZE_WARNING_BYTES`] with `--every` or `--force` given; an error naming `--every` when
/// they pass it without either, or pass the free space under `dir` or the process's
/// file-size limit without `--force`. Each refusal says the `--every` that fits both the room
/// and the 100 MB line.
pub fn size_guard(
    dir: &Path,
    particles: usize,
    steps: u64,
    every: u64,
    ask: SizeAsk,
) -> Result<(String, Option<String>)> {
    let (traj, energy) = projected_run_bytes(particles, steps, every);
    let total = traj + energy;
    let rows = written_frames(steps, every);
    let line = format!(
        "projected output: about {} ({rows} frames × {particles} particles: trajectory.csv {}, energy.csv {})",
        human_bytes(total),
        human_bytes(traj),
        human_bytes(energy)
    );
    // What the run would write against `room`, and the `--every` that fits both the room's
    // `limit` and the 100 MB line: every refusal and the warning say it the same way.
    let says = |verb: &str, room: &str, limit: u64| {
        let fit = match every_within(particles, steps, every, limit.min(SIZE_WARNING_BYTES)) {
            Some(k) => {
                let (t, e) = projected_run_bytes(particles, steps, k);
                format!("--every {k} brings it to about {}", human_bytes(t + e))
            }
            None => "even the first and last frames alone exceed it".into(),
        };
        format!(
            "this run {verb} write about {} of CSV, {room}; {fit}",
            human_bytes(total)
        )
    };
    let refuse = |room: &str, limit: u64, how: &str| {
        Error::option("--every", format!("{} ({how})", says("would", room, limit)))
    };
    if !ask.force {
        if let Some(free) = free_space(dir).filter(|&f| total > f) {
            let room = format!(
                "more than the {} free where {} is written",
                human_bytes(free),
                dir.display()
            );
            return Err(refuse(&room, free, "--force writes anyway"));
        }
        if let Some(limit) = file_size_limit().filter(|&l| traj.max(energy) > l) {
            let room = format!(
                "a file above this process's file-size limit of {} (ulimit -f)",
                human_bytes(limit)
            );
            return Err(refuse(&room, limit, "--force writes anyway"));
        }
    }
    if total <= SIZE_WARNING_BYTES {
        return Ok((line, None));
    }
    let above = format!("above {}", human_bytes(SIZE_WARNING_BYTES));
    if !(ask.every_given || ask.force) {
        let how = "--every 1 or --force writes every step";
        return Err(refuse(&above, SIZE_WARNING_BYTES, how));
    }
    Ok((line, Some(says("will", &above, SIZE_WARNING_BYTES))))
}

/// Bytes free to this process on the filesystem that will hold `dir` (its first existing
/// ancestor), when the OS says.
fn free_space(dir: &Path) -> Option<u64> {
    let existing = dir
        .ancestors()
        .find(|p| p.is_dir())
        .unwrap_or(Path::new("."));
    fs4::available_space(existing).ok()
}

/// The process's soft limit on the size of a file it writes (`ulimit -f`), when it has one.
#[cfg(unix)]
fn file_size_limit() -> Option<u64> {
    let mut r = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: `r` is a valid rlimit the call fills in.
    let ok = unsafe { libc::getrlimit(libc::RLIMIT_FSIZE, &mut r) } == 0;
    (ok && r.rlim_cur != libc::RLIM_INFINITY).then_some(r.rlim_cur)
}

/// Elsewhere a failed write says it.
#[cfg(not(unix))]
fn file_size_limit() -> Option<u64> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the projection's own arithmetic (`projected_run_bytes`): 1024 particles over
    // 1000 frames at every step is about 140 MB, above the 100 MB line; 10 particles over 100
    // frames is a few kB. A small run is quiet; the large one is refused without --every and
    // warned with it (its twin), each naming the --every that fits.
    #[test]
    fn a_large_run_is_refused_unless_asked_for_and_a_small_one_is_quiet() {
        let here = Path::new(".");
        let ask = SizeAsk::default();
        assert!(size_guard(here, 10, 100, 1, ask).unwrap().1.is_none());
        let refused = size_guard(here, 1024, 1000, 1, ask)
            .unwrap_err()
            .to_string();
        assert!(
            refused.starts_with("--every: ") && refused.contains("--every 2 "),
            "{refused}"
        );
        let asked = SizeAsk {
            every_given: true,
            force: false,
        };
        let w = size_guard(here, 1024, 1000, 1, asked)
            .unwrap()
            .1
            .expect("warned");
        assert!(
            w.contains("above 100.00 MB") && w.contains("--every 2 "),
            "{w}"
        );
    }
}
