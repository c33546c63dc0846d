//! The progress promise in a pipe: a long command prints a line at least every interval until
//! it ends, naming the stage it is in, however long a single stage without a count (a
//! reference solve, the timing runs) lasts.
//!
//! Oracle: the interval's definition (`SPRINGLAB_PROGRESS_INTERVAL`, the seconds between lines)
//! and the clock of this test: each stderr line is stamped as it arrives through the pipe, and
//! no gap (from the start to the first line, between lines, from the last line to the exit)
//! may exceed the interval plus a slack for a loaded machine.

use crate::support::bin;
use std::io::{BufRead, BufReader};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// Seconds between lines asked of the command.
const INTERVAL: f64 = 0.3;

/// What a gap may exceed the interval by: the ticker looks several times per interval, and a
/// machine shared with other jobs may hold a thread back for a while.
const SLACK: f64 = 0.7;

/// A cloth named `name` of `n`×`n` particles with the shipped cloth's particle mass and
/// springs (`bend`: its bend springs too), its two top corners pinned, run `duration` s at `dt`.
fn cloth(name: &str, n: usize, bend: bool, dt: f64, duration: f64) -> String {
    let bend = if bend { "bend_stiffness = 20.0\n" } else { "" };
    format!(
        "name = \"{name}\"\n[world]\ngravity = [0.0, -9.81, 0.0]\n[[cloth]]\n\
         origin = [0.0, 0.0, 0.0]\nsize = [1.0, 1.0]\ncount = [{n}, {n}]\nmass = 0.001\n\
         stiffness = 200.0\ndamping = 0.002\n{bend}plane = \"xz\"\n\
         fix = [\"top_left\", \"top_right\"]\n[run]\ndt = {dt}\nduration = {duration}\n"
    )
}

#[test]
fn a_long_command_in_a_pipe_prints_a_line_every_interval_until_it_ends() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("cloth8.toml");
    // An 8×8 cloth with bend springs: its 2 s take advice several seconds, many intervals.
    std::fs::write(&scene, cloth("cloth8", 8, true, 0.001, 2.0)).unwrap();
    let start = Instant::now();
    let mut child = bin()
        .arg("advise")
        .arg(&scene)
        .args([
            "--tolerance",
            "0.002",
            "--methods",
            "position_verlet,rk4,xpbd",
        ])
        .arg("--out")
        .arg(dir.path().join("out"))
        .env("SPRINGLAB_PROGRESS_INTERVAL", INTERVAL.to_string())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        BufReader::new(stderr)
            .lines()
            .map(|l| (start.elapsed(), l.unwrap()))
            .collect::<Vec<(Duration, String)>>()
    });
    let status = child.wait().unwrap();
    let end = start.elapsed();
    let lines = reader.join().unwrap();
    assert!(status.success(), "{lines:?}");
    let progress: Vec<&(Duration, String)> = lines
        .iter()
        .filter(|(_, l)| l.starts_with("progress: "))
        .collect();
    let stamps: Vec<f64> = std::iter::once(0.0)
        .chain(progress.iter().map(|(t, _)| t.as_secs_f64()))
        .chain(std::iter::once(end.as_secs_f64()))
        .collect();
    assert!(
        end.as_secs_f64() > 4.0 * INTERVAL,
        "the command must outlast a few intervals to test anything: {end:?}"
    );
    for w in stamps.windows(2) {
        assert!(
            w[1] - w[0] <= INTERVAL + SLACK,
            "silent from {:.2} s to {:.2} s (interval {INTERVAL} s): {lines:#?}",
            w[0],
            w[1]
        );
    }
    // Every line names the stage: the command's own, or one of advice's parts (its game view
    // is the frame-rate table, whose stages say so).
    for (_, l) in &progress {
        let stage = l.trim_start_matches("progress: ");
        assert!(
            stage.starts_with("advise cloth8: ")
                || stage.starts_with("advise: ")
                || stage.starts_with("framerate cloth8"),
            "{l}"
        );
        assert!(l.contains(" s elapsed"), "{l}");
    }
    // The stretches without a count (the reference, the timing runs) are named too.
    assert!(
        progress
            .iter()
            .any(|(_, l)| l.contains(": reference") || l.contains(": timing")),
        "{lines:#?}"
    );
}

/// The counts `k` of a run's `progress: LABEL: k/TOTAL done` lines, in order.
fn counts(lines: &[String], total: u64) -> Vec<u64> {
    let tail = format!("/{total} done");
    lines
        .iter()
        .filter_map(|l| {
            let l = l.strip_prefix("progress: ")?;
            let (head, _) = l.split_once(&tail)?;
            head.rsplit(' ').next()?.parse().ok()
        })
        .collect()
}

/// `springlab run` of `scene` with `method` for `steps` steps, its stderr's lines.
fn run_lines(
    scene: &std::path::Path,
    method: &str,
    steps: u64,
    out: &std::path::Path,
) -> Vec<String> {
    let o = bin()
        .arg("run")
        .arg(scene)
        .args([
            "--method",
            method,
            "--steps",
            &steps.to_string(),
            "--every",
            "1000000",
        ])
        .arg("--out")
        .arg(out)
        .env("SPRINGLAB_PROGRESS_INTERVAL", INTERVAL.to_string())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    err.lines().map(str::to_string).collect()
}

/// Oracle: the line's definition, "DONE/TOTAL done" counts the steps done when it is printed.
/// A run of slow steps (an implicit 100×100 cloth, tens of milliseconds each) shows its count
/// rising between lines, not 0 until its end; its twin of three million fast steps (one spring,
/// well under a microsecond each) does too, its bar updated every few hundred steps.
#[test]
fn a_run_s_lines_count_its_steps_whether_they_are_slow_or_fast() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("cloth100.toml");
    // A 100×100 cloth: one implicit Euler step from rest takes tens of milliseconds, so 30 of
    // them outlast several intervals with under a step a line.
    std::fs::write(&scene, cloth("cloth100", 100, false, 1.0 / 60.0, 0.5)).unwrap();
    let slow = run_lines(&scene, "implicit_euler", 30, &dir.path().join("slow"));
    let c = counts(&slow, 30);
    assert!(c.len() >= 2, "a few lines while it runs: {slow:#?}");
    assert!(c.windows(2).all(|w| w[0] <= w[1]), "{c:?}");
    assert!(
        c.iter().any(|&k| k > 0 && k < 30),
        "the count rises while the slow run runs: {slow:#?}"
    );
    // The shipped anchored spring: one particle on a spring to a fixed one.
    let spring =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/anchored_spring.toml");
    let n = 3_000_000;
    let fast = run_lines(&spring, "symplectic_euler", n, &dir.path().join("fast"));
    let c = counts(&fast, n);
    assert!(
        c.iter().any(|&k| k > 0 && k < n),
        "the count rises while the fast run runs: {fast:#?}"
    );
}
