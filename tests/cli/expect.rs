//! `springlab expect`: scenes held to their `[expect]` tables, with oracles that do not depend
//! on the methods' accuracy: limits far above or below what the scene itself implies.

use crate::support::{bin, ok};
use std::path::{Path, PathBuf};

/// A 1 kg mass on a 100 N/m spring (ω = 10 rad/s) started 10 % stretched, then `expect`.
/// The strain oscillates between −0.1 and 0.1; the energy is 0.5 J.
fn spring_scene(dir: &Path, name: &str, duration: f64, expect: &str) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(
        &path,
        format!(
            r#"
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true

[[particle]]
position = [1.1, 0.0, 0.0]
mass = 1.0

[[spring]]
between = [0, 1]
stiffness = 100.0
rest_length = 1.0

[run]
dt = 0.01
duration = {duration}

{expect}
"#
        ),
    )
    .unwrap();
    path
}

/// Limits far above what a 600 Hz velocity Verlet run measures: the strain is 0.1 at most,
/// the amplitude 0.1 m bounds any sensible position error, the energy (0.5 J) drifts far less
/// than 1 J/s.
const PASSING: &str = r#"[expect]
method = "velocity_verlet"
hz = 600
stable = true
max_position_error = 0.1
max_strain = 1.0
max_energy_drift_rate = 1.0
"#;

/// The same run with max_strain = 0.05: the spring starts 10 % stretched, so the strain is at
/// least 0.1 at t = 0 whatever the method does. The other three still pass.
const STRAIN_TOO_TIGHT: &str = r#"[expect]
method = "velocity_verlet"
hz = 600
stable = true
max_position_error = 0.1
max_strain = 0.05
max_energy_drift_rate = 1.0
"#;

/// Explicit Euler at dt = 0.5 s, ω dt = 5, far beyond its limit 2/ω: each step multiplies the
/// amplitude by about √(1 + 25) ≈ 5, so over 10 s (20 steps) the run blows up. Both the
/// stability and the (generous) strain limit fail: an unstable run has no number.
const UNSTABLE: &str = r#"[expect]
method = "explicit_euler"
hz = 2
stable = true
max_strain = 1.0
"#;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = bin().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn expect_passes_fails_and_writes_junit() {
    let dir = tempfile::tempdir().unwrap();
    let pass = spring_scene(dir.path(), "pass", 2.0, PASSING);
    let tight = spring_scene(dir.path(), "tight", 2.0, STRAIN_TOO_TIGHT);
    let unstable = spring_scene(dir.path(), "unstable", 10.0, UNSTABLE);
    let (p, t, u) = (
        pass.to_str().unwrap(),
        tight.to_str().unwrap(),
        unstable.to_str().unwrap(),
    );

    // All four expectations hold: exit 0, four pass lines.
    let out = ok(&["expect", p]);
    assert_eq!(out.matches(" pass").count(), 4, "{out}");
    assert!(!out.contains("FAIL"), "{out}");

    // The tight strain limit fails alone; the exit is non-zero and the summary names it.
    let (success, out, err) = run(&["expect", t]);
    assert!(!success);
    assert_eq!(out.matches("FAIL").count(), 1, "{out}");
    assert!(err.contains("1 of 4 expectations failed"), "{err}");
    assert!(err.contains("max_strain"), "{err}");

    // The unstable run fails `stable` and shows no number for the strain.
    let (success, out, _) = run(&["expect", u]);
    assert!(!success);
    assert_eq!(out.matches("FAIL").count(), 2, "{out}");
    assert!(out.contains("—, run unstable at t ="), "{out}");

    // JUnit: one testcase per expectation (4 + 4 + 2), one failure per failing one (0 + 1 + 2),
    // classname the scene as given.
    let xml_path = dir.path().join("expect.xml");
    let (success, _, _) = run(&["expect", p, t, u, "--junit", xml_path.to_str().unwrap()]);
    assert!(!success);
    let xml = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let suite = doc.root_element();
    assert_eq!(suite.tag_name().name(), "testsuite");
    assert_eq!(suite.attribute("name"), Some("springlab expect"));
    assert_eq!(suite.attribute("tests"), Some("10"));
    assert_eq!(suite.attribute("failures"), Some("3"));
    let cases: Vec<_> = suite
        .children()
        .filter(|n| n.has_tag_name("testcase"))
        .collect();
    assert_eq!(cases.len(), 10);
    let failing = |scene: &str| {
        cases
            .iter()
            .filter(|c| c.attribute("classname") == Some(scene))
            .filter(|c| c.children().any(|f| f.has_tag_name("failure")))
            .count()
    };
    let count = |scene: &str| {
        cases
            .iter()
            .filter(|c| c.attribute("classname") == Some(scene))
            .count()
    };
    assert_eq!((count(p), failing(p)), (4, 0));
    assert_eq!((count(t), failing(t)), (4, 1));
    assert_eq!((count(u), failing(u)), (2, 2));
    let strain = cases
        .iter()
        .find(|c| c.attribute("classname") == Some(t) && c.attribute("name") == Some("max_strain"))
        .expect("the tight strain testcase");
    let msg = strain
        .children()
        .find(|f| f.has_tag_name("failure"))
        .and_then(|f| f.attribute("message"))
        .unwrap();
    assert!(msg.contains("> limit 0.05"), "{msg}");
    // Names carry no limit: a change of limit keeps every testcase's name (its history).
    let names = |scene: &str| -> Vec<String> {
        cases
            .iter()
            .filter(|c| c.attribute("classname") == Some(scene))
            .filter_map(|c| c.attribute("name").map(String::from))
            .collect()
    };
    assert_eq!(names(p), names(t));
    assert_eq!(
        names(p),
        [
            "stable",
            "max_position_error",
            "max_strain",
            "max_energy_drift_rate"
        ]
    );
}

#[test]
fn expect_without_table_is_skipped_unless_nothing_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    let plain = spring_scene(dir.path(), "plain", 1.0, "");
    let pass = spring_scene(dir.path(), "pass", 2.0, PASSING);
    // Next to a scene that passes, a scene without [expect] is listed as skipped: exit 0.
    let out = ok(&["expect", plain.to_str().unwrap(), pass.to_str().unwrap()]);
    assert!(out.contains("plain.toml"), "{out}");
    assert!(out.contains("no [expect] table"), "{out}");
    assert!(out.contains("skipped"), "{out}");
    // Alone, nothing is checked: an error, exit non-zero.
    let (success, _, err) = run(&["expect", plain.to_str().unwrap()]);
    assert!(!success);
    assert!(err.contains("has an [expect] table"), "{err}");
}

#[test]
fn expect_table_errors_name_the_field_and_file() {
    let dir = tempfile::tempdir().unwrap();
    let typo = spring_scene(
        dir.path(),
        "typo",
        1.0,
        "[expect]\nmethod = \"rk4\"\nhz = 60\nmax_strian = 0.1\n",
    );
    let (success, _, err) = run(&["check", typo.to_str().unwrap()]);
    assert!(!success);
    assert!(err.contains("expect.max_strian"), "{err}");
    assert!(err.contains("typo.toml"), "{err}");

    let both = spring_scene(
        dir.path(),
        "both",
        1.0,
        "[expect]\nmethod = \"rk4\"\nhz = 60\ndt = 0.01\n",
    );
    let (success, _, err) = run(&["check", both.to_str().unwrap()]);
    assert!(!success);
    assert!(err.contains("both.toml") && err.contains("expect"), "{err}");
    assert!(err.contains("exactly one of `hz` and `dt`"), "{err}");

    let unknown = spring_scene(
        dir.path(),
        "unknown",
        1.0,
        "[expect]\nmethod = \"no_such_method\"\nhz = 60\n",
    );
    let (success, _, err) = run(&["check", unknown.to_str().unwrap()]);
    assert!(!success);
    assert!(err.contains("expect.method"), "{err}");
}

/// A frame longer than the run, or one so short its frames pass the step limit, is the
/// table's own field at fault (not a flag `expect` does not have). Oracle: the run's length
/// (1 s here) and the step limit of 1e10; the twin is a frame exactly the run's length.
#[test]
fn an_expect_frame_the_run_cannot_hold_names_its_field_and_the_twin_at_the_edge_loads() {
    let dir = tempfile::tempdir().unwrap();
    for (name, table, field) in [
        ("slow", "hz = 0.9", "expect.hz"),
        ("long", "dt = 1.5", "expect.dt"),
        ("fast", "hz = 1e300", "expect.hz"),
        ("many", "hz = 1e9\nsubsteps = 20", "expect.substeps"),
    ] {
        let path = spring_scene(
            dir.path(),
            name,
            1.0,
            &format!("[expect]\nmethod = \"rk4\"\n{table}\nstable = true\n"),
        );
        for cmd in ["check", "expect"] {
            let (success, out, err) = run(&[cmd, path.to_str().unwrap()]);
            assert!(!success, "{cmd} {name}: {out}");
            let said = format!("{out}{err}");
            assert!(
                said.contains(&format!("{name}.toml: {field}: ")),
                "{cmd} {name}: {said}"
            );
            assert!(!said.contains("--dt"), "{cmd} {name}: {said}");
        }
    }
    let edge = spring_scene(
        dir.path(),
        "edge",
        1.0,
        "[expect]\nmethod = \"rk4\"\nhz = 1\nstable = true\n",
    );
    let (success, out, err) = run(&["check", edge.to_str().unwrap()]);
    assert!(success, "{out}{err}");
}

#[test]
fn check_shows_the_expectations() {
    let dir = tempfile::tempdir().unwrap();
    let pass = spring_scene(dir.path(), "pass", 2.0, PASSING);
    let out = ok(&["check", pass.to_str().unwrap()]);
    assert!(out.contains("expect: velocity_verlet"), "{out}");
    assert!(out.contains("max_strain ≤ 1"), "{out}");
    assert!(out.contains("max_position_error ≤ 0.1 m"), "{out}");
}

// `advise --write-expect` appends the verified answer; `expect` then holds the scene to it (a
// pass by construction: the same run, re-made). The twin: a second `--write-expect` refuses,
// leaving the file byte for byte as it was.
#[test]
fn advise_writes_the_answer_that_expect_then_holds() {
    let dir = tempfile::tempdir().unwrap();
    let scene = spring_scene(dir.path(), "advised", 1.0, "");
    let p = scene.to_str().unwrap();
    let out = ok(&[
        "advise",
        p,
        "--methods",
        "velocity_verlet",
        "--points",
        "3",
        "--no-frame-rates",
        "--write-expect",
        "--out",
        dir.path().join("adv").to_str().unwrap(),
    ]);
    assert!(out.contains("appended an [expect] table"), "{out}");
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("[expect]") && text.contains("method = \"velocity_verlet\""));
    assert!(
        text.contains("# The answer verified by: springlab advise"),
        "{text}"
    );
    let junit = dir.path().join("junit.xml");
    let out = ok(&["expect", p, "--junit", junit.to_str().unwrap()]);
    assert!(!out.contains("FAIL"), "{out}");
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(
        xml.contains("failures=\"0\"") && xml.contains("max_strain"),
        "{xml}"
    );

    let (done, _, err) = run(&["advise", p, "--write-expect", "--points", "3"]);
    assert!(!done, "a second --write-expect must refuse");
    assert!(err.contains("already has an [expect] table"), "{err}");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
}

// A scene with a frame rate gets the game-rate answer: `--write-expect` writes the method, the
// rate and the substeps per frame of the frame view's best at that rate (`--hz`, else the
// scene's [run] hz), and `expect` holds the scene to it. The twin without a rate writes the
// free step (a `dt`, one substep), as `advise_writes_the_answer_that_expect_then_holds` checks.
#[test]
fn advise_writes_the_game_rate_answer_when_the_scene_has_a_rate() {
    let dir = tempfile::tempdir().unwrap();
    for (name, extra, flags) in [("asked", "", vec!["--hz", "30"]), ("own", "", vec![])] {
        let scene = spring_scene(dir.path(), name, 1.0, extra);
        if name == "own" {
            let text = std::fs::read_to_string(&scene)
                .unwrap()
                .replace("duration = 1\n", "duration = 1\nhz = 30\n");
            assert!(text.contains("hz = 30"), "{text}");
            std::fs::write(&scene, text).unwrap();
        }
        let p = scene.to_str().unwrap();
        let out_dir = dir.path().join(format!("adv-{name}"));
        let mut args = vec![
            "advise",
            p,
            "--methods",
            "velocity_verlet",
            "--points",
            "3",
            "--no-frame-rates",
            "--write-expect",
            "--out",
            out_dir.to_str().unwrap(),
        ];
        args.extend(flags);
        ok(&args);
        let text = std::fs::read_to_string(&scene).unwrap();
        let table = &text[text.find("[expect]").expect("a table")..];
        assert!(table.contains("hz = 30"), "{table}");
        assert!(
            table.contains("substeps = ") && !table.contains("dt = "),
            "{table}"
        );
        let out = ok(&["expect", p]);
        assert!(!out.contains("FAIL"), "{out}");
        assert!(out.contains("(30.0 Hz)"), "{out}");
    }
}
