//! Scenes and flags that would run away (billions of steps, a reference that never ends) are
//! refused at once or stopped by the budget with a one-line reason naming `--budget` (or the
//! flag at fault); each has a twin, a nearby legitimate case that runs.

use crate::support::{bin, ok};
use std::path::{Path, PathBuf};

fn run(args: &[&str]) -> (bool, String, String) {
    let out = bin().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A shipped scene with `from` replaced by `to` (and `extra` appended), written to `dir`.
fn mutated(dir: &Path, shipped: &str, from: &str, to: &str, extra: &str) -> PathBuf {
    let text = std::fs::read_to_string(format!("scenarios/{shipped}.toml")).unwrap();
    assert!(text.contains(from), "{shipped} has no `{from}`");
    let path = dir.join(format!("{shipped}.toml"));
    std::fs::write(&path, format!("{}\n{extra}", text.replace(from, to))).unwrap();
    path
}

const FAST_PARTICLE_EXPECT: &str = "[expect]\nmethod = \"symplectic_euler\"\ndt = 0.001\nstable = true\nmax_position_error = 0.01\n";

// The fast particle at the step limit (1e10 steps of 1 ms) held to an [expect] table: its
// run alone is 1e10 steps, beyond any budget of minutes at nanoseconds per step, so every
// expectation fails at once naming the budget (it used to grow memory to 9 GB and abort). The
// twin: the shipped 50 steps pass.
#[test]
fn expect_at_the_step_limit_fails_at_once_naming_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    let long = mutated(
        dir.path(),
        "fast_particle_wall",
        "duration = 0.05",
        "steps = 10000000000",
        FAST_PARTICLE_EXPECT,
    );
    let (success, out, err) = run(&["expect", long.to_str().unwrap()]);
    assert!(!success);
    assert_eq!(out.matches("FAIL").count(), 2, "{out}");
    assert!(
        out.contains("left out") && out.contains("`--budget`"),
        "{out}"
    );
    assert!(err.contains("2 of 2 expectations failed"), "{err}");
    // The summary line comes first, on stdout, before the table.
    let summary = out.find("symplectic_euler at dt").expect("summary line");
    assert!(summary < out.find("expectation").unwrap(), "{out}");

    let twin = tempfile::tempdir().unwrap();
    let short = mutated(
        twin.path(),
        "fast_particle_wall",
        "duration = 0.05",
        "duration = 0.05",
        FAST_PARTICLE_EXPECT,
    );
    let out = ok(&["expect", short.to_str().unwrap()]);
    assert_eq!(out.matches(" pass").count(), 2, "{out}");
}

// The pendulum over 9 999 999 999 steps of 1 ms (1e7 s): its DOP853 reference swings about
// 5e6 times, at least a step per radian, so it is refused before any solve, naming the figure
// and --budget. The twin: 5000 steps run.
#[test]
fn compare_refuses_a_reference_past_the_budget_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let long = mutated(
        dir.path(),
        "pendulum_rod",
        "duration = 5.0",
        "steps = 9999999999",
        "",
    );
    let out = dir.path().join("out");
    let (success, _, err) = run(&[
        "compare",
        long.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!success);
    assert!(
        err.contains("--budget") && err.contains("the reference alone would take about"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");

    let twin = tempfile::tempdir().unwrap();
    let short = mutated(
        twin.path(),
        "pendulum_rod",
        "duration = 5.0",
        "steps = 5000",
        "",
    );
    let out = twin.path().join("out");
    ok(&[
        "compare",
        short.to_str().unwrap(),
        "--methods",
        "verlet_constraints",
        "--out",
        out.to_str().unwrap(),
    ]);
}

// The chain on the box with a sphere around its first particles: they start inside it, and the
// DOP853 reference's impulse contacts chatter in steps far shorter than the chain's motion
// needs. Its solve stops once it has spent what the budget leaves it, with an error naming
// --budget. The twin: the same sphere above the chain, out of its way, runs within the same
// budget.
#[test]
fn compare_stops_a_reference_that_passes_the_budget() {
    let sphere = |y: f64| {
        format!("[[obstacle]]\nshape = \"sphere\"\ncenter = [-0.5, {y}, 0.0]\nradius = 0.5\n")
    };
    let dir = tempfile::tempdir().unwrap();
    let inside = mutated(
        dir.path(),
        "chain_on_box",
        "duration = 1.5",
        "duration = 0.5",
        &sphere(1.0),
    );
    let out = dir.path().join("out");
    let args = |scene: &Path, out: &Path| -> Vec<String> {
        [
            "compare",
            scene.to_str().unwrap(),
            "--methods",
            "symplectic_euler",
            "--budget",
            "5",
            "--out",
            out.to_str().unwrap(),
        ]
        .map(String::from)
        .to_vec()
    };
    let a = args(&inside, &out);
    let (success, _, err) = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(!success);
    assert!(
        err.contains("--budget") && err.contains("the reference (DOP853) stopped after"),
        "{err}"
    );

    let twin = tempfile::tempdir().unwrap();
    let above = mutated(
        twin.path(),
        "chain_on_box",
        "duration = 1.5",
        "duration = 0.5",
        &sphere(2.0),
    );
    let out = twin.path().join("out");
    let a = args(&above, &out);
    ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
}

// A frame rate or step `run` refuses is refused at once by framerate and small-steps, naming
// the flag; budgets of substeps that pass the step limit are refused by small-steps as
// substeps are by run. The twins: the shipped rates and budgets run (small-steps; framerate's
// own tests run its defaults).
#[test]
fn framerate_and_small_steps_refuse_what_run_refuses() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    for (args, flag) in [
        (vec!["run", "--method", "rk4", "--hz", "1e-300"], "--hz"),
        (vec!["framerate", "--hz", "1e-300"], "--hz"),
        (vec!["small-steps", "--dt", "1.8e19"], "--dt"),
        (vec!["small-steps", "--dt", "1e-9"], "--budgets"),
        (
            vec!["small-steps", "--budgets", "1,100000000000"],
            "--budgets",
        ),
        (
            vec!["run", "--method", "rk4", "--substeps", "10000000000"],
            "--substeps",
        ),
        (vec!["compare", "--substeps", "10000000000"], "--substeps"),
    ] {
        let mut a = vec![args[0], "scenarios/two_body.toml"];
        a.extend(&args[1..]);
        a.extend(["--out", o]);
        let (success, _, err) = run(&a);
        assert!(!success, "{a:?}");
        assert!(err.starts_with(&format!("error: {flag}:")), "{a:?}: {err}");
    }
    ok(&[
        "small-steps",
        "scenarios/two_body.toml",
        "--budgets",
        "1,2",
        "--out",
        o,
    ]);
}

// small-steps with a budget its runs would pass is refused at once with the figures; the twin
// with the default budget runs the same comparison.
#[test]
fn small_steps_refuses_runs_past_its_budget() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let (success, _, err) = run(&[
        "small-steps",
        "scenarios/two_body.toml",
        "--budgets",
        "1,64",
        "--budget",
        "1e-6",
        "--out",
        o,
    ]);
    assert!(!success);
    assert!(
        err.starts_with("error: --budget: the comparison would take about"),
        "{err}"
    );
    ok(&[
        "small-steps",
        "scenarios/two_body.toml",
        "--budgets",
        "1,64",
        "--out",
        o,
    ]);
}
