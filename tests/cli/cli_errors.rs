//! The command line's answers to bad values: one line naming the flag (and, for files, the
//! path), each OS error once, numbers in short form, and step limits refused at once by every
//! command. Each refusal has a twin: a valid value near the same edge that gets past the flag.
//!
//! Oracles: the error contract (`FLAG: what is wrong`, one line), `springlab::scenario::
//! MAX_STEPS` with the arithmetic duration / dt, and the OS (a path that is a file cannot be
//! a folder; a missing file is ENOENT, "os error 2").

use crate::support::bin;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

/// A spring scene of exactly 1 s: step counts are 1 / dt.
const ONE_SECOND: &str = "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
[[particle]]\nposition = [1.0, 0.0, 0.0]\nmass = 1.0\n\
[[spring]]\nbetween = [0, 1]\nstiffness = 4.0\nrest_length = 0.5\n\
[run]\ndt = 0.01\nduration = 1.0\n";

fn scene(dir: &Path) -> PathBuf {
    let p = dir.join("one_second.toml");
    std::fs::write(&p, ONE_SECOND).unwrap();
    p
}

fn spring_scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/damped_spring.toml")
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

/// The command failed with exactly one line on stderr, naming `flag`; returns that line.
fn one_line_error(out: &Output, flag: &str) -> String {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!out.status.success(), "accepted; stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "not one line: {err}");
    assert!(
        lines[0].starts_with(&format!("error: {flag}:")),
        "does not start with the flag {flag}: {err}"
    );
    lines[0].to_string()
}

/// The command failed, and not because of `flag` (its value got past validation).
fn fails_elsewhere(out: &Output, flag: &str, because: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected a later refusal: {err}");
    assert!(!err.contains(&format!("{flag}:")), "{flag} refused: {err}");
    assert!(err.contains(because), "missing '{because}' in: {err}");
}

fn succeeds(out: &Output) {
    assert!(
        out.status.success(),
        "refused: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

// Negative numbers reach the validators instead of clap's "unexpected argument".

#[test]
fn negative_values_are_refused_by_the_flags_own_check() {
    let sc = spring_scene();
    let sc = s(&sc);
    for (args, flag) in [
        (vec!["compare", sc, "--dt", "-1"], "--dt"),
        (vec!["compare", sc, "--duration", "-1"], "--duration"),
        (
            vec!["advise", sc, "--tolerance", "1e-3", "--dt-min", "-1"],
            "--dt-min",
        ),
        (vec!["advise", sc, "--tolerance", "-1"], "--tolerance"),
        (vec!["stability", sc, "--horizon", "-1"], "--horizon"),
        (vec!["sweep", sc, "--dt-min", "-1"], "--dt-min"),
        (vec!["framerate", sc, "--cost-cap", "-1"], "--cost-cap"),
    ] {
        let line = one_line_error(&run(&args), flag);
        assert!(line.contains("-1"), "value not quoted: {line}");
        assert!(!line.contains("unexpected argument"), "{line}");
    }
}

#[test]
fn a_negative_whole_number_is_refused_on_one_line_naming_the_flag() {
    let sc = spring_scene();
    for (args, flag) in [
        (vec!["sweep", s(&sc), "--points", "-1"], "--points"),
        (vec!["run", s(&sc), "-i", "rk4", "--steps", "-3"], "--steps"),
    ] {
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(!err.contains("unexpected argument"), "{err}");
        assert!(err.lines().next().unwrap().contains(flag), "{err}");
    }
}

#[test]
fn twin_positive_values_near_zero_get_past_the_same_flags() {
    let dir = tempfile::tempdir().unwrap();
    let sc = spring_scene();
    succeeds(&run(&[
        "compare",
        s(&sc),
        "--dt",
        "0.01",
        "--duration",
        "0.05",
        "--out",
        s(&dir.path().join("c")),
    ]));
    // --dt-min and --tolerance pass; the unknown method is refused after them.
    fails_elsewhere(
        &run(&[
            "advise",
            s(&sc),
            "--tolerance",
            "1e-9",
            "--dt-min",
            "1e-6",
            "--methods",
            "nosuch",
        ]),
        "--dt-min",
        "nosuch",
    );
    succeeds(&run(&[
        "stability",
        s(&sc),
        "--horizon",
        "1e-3",
        "--theory-only",
        "--out",
        s(&dir.path().join("s")),
    ]));
}

// --out naming a file is refused before any work, naming the flag and the path.

#[test]
fn out_naming_a_file_is_refused_at_once_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a_file");
    std::fs::write(&file, "not a folder").unwrap();
    let f = s(&file);
    let sc = spring_scene();
    let sc = s(&sc);
    let expected = format!("error: --out: {f} is a file, not a folder");
    for args in [
        vec!["run", sc, "-i", "rk4", "--out", f],
        vec!["compare", sc, "--out", f],
        vec!["sweep", sc, "--out", f],
        vec!["stability", sc, "--out", f],
        vec!["advise", sc, "--tolerance", "1e-3", "--out", f],
        vec!["framerate", sc, "--out", f],
        vec!["small-steps", sc, "--out", f],
        vec!["report", "--quick", "--out", f],
        vec!["merge", sc, "--out", f],
        vec!["bench-scaling", "--out", f],
        vec!["bench-ratios", "--out", f],
    ] {
        let t0 = Instant::now();
        let line = one_line_error(&run(&args), "--out");
        assert_eq!(line, expected, "{args:?}");
        // Validation, not computation: a quick report takes far longer than this.
        assert!(t0.elapsed() < Duration::from_secs(10), "{args:?} was slow");
    }
}

#[test]
fn out_below_a_file_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a_file");
    std::fs::write(&file, "").unwrap();
    let below = file.join("run");
    let sc = spring_scene();
    let line = one_line_error(
        &run(&["run", s(&sc), "-i", "rk4", "--out", s(&below)]),
        "--out",
    );
    assert!(
        line.ends_with(&format!(
            "{}: {} is a file, not a folder",
            s(&below),
            s(&file)
        )),
        "{line}"
    );
}

#[test]
fn twin_out_naming_a_new_or_existing_folder_is_used() {
    let dir = tempfile::tempdir().unwrap();
    let sc = spring_scene();
    let fresh = dir.path().join("new").join("run");
    for out in [&fresh, &fresh] {
        succeeds(&run(&[
            "run",
            s(&sc),
            "-i",
            "rk4",
            "--steps",
            "10",
            "--out",
            s(out),
        ]));
        assert!(out.join("summary.json").is_file());
    }
}

// OS errors once.

#[test]
fn an_os_error_appears_once() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    let out = run(&["check", s(&missing)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    assert!(err.contains("missing.toml"), "{err}");
    let blocked = dir.path().join("scene.toml");
    std::fs::write(&blocked, ONE_SECOND).unwrap();
    let merge = run(&["merge", s(dir.path()), "--out", s(&dir.path().join("m"))]);
    let err = String::from_utf8_lossy(&merge.stderr);
    assert!(!merge.status.success());
    assert_eq!(err.matches("os error").count(), 1, "{err}");
}

#[test]
fn twin_a_readable_scene_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    succeeds(&run(&["check", s(&scene(dir.path()))]));
}

// Numbers in short form; the step limit named and counted.

#[test]
fn a_tiny_frame_rate_is_refused_in_short_form() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scene(dir.path());
    let line = one_line_error(
        &run(&["run", s(&sc), "-i", "rk4", "--hz", "1e-300"]),
        "--hz",
    );
    assert!(line.len() < 200, "{} characters: {line}", line.len());
    // The step 1/HZ = 1e300 s, longer than the 1 s run.
    assert!(line.contains("1e300 s"), "{line}");
}

#[test]
fn twin_a_frame_rate_of_one_step_per_run_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scene(dir.path());
    succeeds(&run(&[
        "run",
        s(&sc),
        "-i",
        "rk4",
        "--hz",
        "1",
        "--out",
        s(&dir.path().join("o")),
    ]));
}

#[test]
fn a_subnormal_step_gives_its_real_step_count() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scene(dir.path());
    let line = one_line_error(
        &run(&["run", s(&sc), "-i", "rk4", "--dt", "1e-320"]),
        "--dt",
    );
    // 1 s / 1e-320 s = 1e320 steps (past u64 and f64 alike).
    assert!(line.contains("1e-320 s over 1 s is 1e320 steps"), "{line}");
    assert!(line.contains("above the limit of 10000000000"), "{line}");
    assert!(!line.contains("18446744073709551615"), "{line}");
}

#[test]
fn the_step_limit_edge_in_run() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scene(dir.path());
    // 1 s / 1e-10 s = 1e10 steps = MAX_STEPS: the step passes and --every is refused next.
    fails_elsewhere(
        &run(&["run", s(&sc), "-i", "rk4", "--dt", "1e-10", "--every", "0"]),
        "--dt",
        "--every",
    );
    assert_eq!(springlab::scenario::MAX_STEPS, 10_000_000_000);
    // 1 s / 9e-11 s = 1.1e10 steps: one past the limit.
    let line = one_line_error(
        &run(&["run", s(&sc), "-i", "rk4", "--dt", "9e-11", "--every", "0"]),
        "--dt",
    );
    assert!(line.contains("11111111111 steps"), "{line}");
}

#[test]
fn framerate_blames_the_duration_for_too_many_frames() {
    let sc = spring_scene();
    // 1e12 s at 30 Hz is 3e13 frames even at one substep.
    let line = one_line_error(
        &run(&["framerate", s(&sc), "--hz", "30", "--duration", "1e12"]),
        "--duration",
    );
    assert!(line.contains("3e13 steps"), "{line}");
    // Twin: 1e9 frames fit at one substep (≤ 1e10); only × 64 substeps do not.
    one_line_error(
        &run(&["framerate", s(&sc), "--hz", "1", "--duration", "1e9"]),
        "--max-substeps",
    );
}

#[test]
fn advise_refuses_a_horizon_past_the_step_limit_at_once() {
    let sc = spring_scene();
    let sc = s(&sc);
    let base = ["advise", sc, "--tolerance", "1e-3", "--dt-min", "1e-3"];
    let t0 = Instant::now();
    // 1.1e7 s / 1e-3 s = 1.1e10 steps > MAX_STEPS.
    let line = one_line_error(
        &run(&[&base[..], &["--horizon", "1.1e7", "--methods", "nosuch"]].concat()),
        "--horizon",
    );
    assert!(line.contains("11000000000 steps"), "{line}");
    let line = one_line_error(
        &run(&["advise", sc, "--tolerance", "1e-3", "--horizon", "1e12"]),
        "--horizon",
    );
    assert!(line.contains("above the limit"), "{line}");
    assert!(t0.elapsed() < Duration::from_secs(10));
    // Twin: 1e7 s / 1e-3 s = 1e10 steps, at the limit: refused later, for the method (in a
    // folder of its own, so no other test's advice holds its lock).
    let tmp = tempfile::tempdir().unwrap();
    let out = ["--out", s(tmp.path())];
    fails_elsewhere(
        &run(&[
            &base[..],
            &["--horizon", "1e7", "--methods", "nosuch"],
            &out[..],
        ]
        .concat()),
        "--horizon",
        "nosuch",
    );
}

#[test]
fn small_steps_refuses_a_duration_past_the_step_limit_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let sc = spring_scene();
    let t0 = Instant::now();
    // 1e12 s at the 1/60 s frame is 6e13 frames.
    let line = one_line_error(
        &run(&[
            "small-steps",
            s(&sc),
            "--duration",
            "1e12",
            "--out",
            s(dir.path()),
        ]),
        "--duration",
    );
    assert!(line.contains("6e13 steps"), "{line}");
    assert!(t0.elapsed() < Duration::from_secs(10));
    // A frame longer than the whole run is refused at once too, naming --dt.
    let t0 = Instant::now();
    let line = one_line_error(
        &run(&[
            "small-steps",
            s(&sc),
            "--dt",
            "1.8e19",
            "--out",
            s(dir.path()),
        ]),
        "--dt",
    );
    assert!(line.contains("longer than the duration"), "{line}");
    assert!(t0.elapsed() < Duration::from_secs(10));
    // Twin: a short run is measured.
    succeeds(&run(&[
        "small-steps",
        s(&sc),
        "--duration",
        "0.1",
        "--budgets",
        "1",
        "--out",
        s(dir.path()),
    ]));
}

#[test]
fn stability_refuses_a_horizon_past_the_step_limit() {
    let dir = tempfile::tempdir().unwrap();
    let sc = spring_scene();
    let line = one_line_error(
        &run(&[
            "stability",
            s(&sc),
            "--horizon",
            "1e12",
            "--out",
            s(dir.path()),
        ]),
        "--horizon",
    );
    assert!(line.contains("above the limit"), "{line}");
    // Twin: a horizon of a few seconds is analysed.
    succeeds(&run(&[
        "stability",
        s(&sc),
        "--horizon",
        "2",
        "--theory-only",
        "--out",
        s(dir.path()),
    ]));
}

#[test]
fn advise_needs_at_least_two_points() {
    let sc = spring_scene();
    let sc = s(&sc);
    for p in ["0", "1"] {
        let line = one_line_error(
            &run(&["advise", sc, "--tolerance", "1e-3", "--points", p]),
            "--points",
        );
        assert!(line.contains("at least 2"), "{line}");
    }
    // Twin: two points pass; the unknown method is refused after them (in a folder of its
    // own, so no other test's advice holds its lock).
    let tmp = tempfile::tempdir().unwrap();
    fails_elsewhere(
        &run(&[
            "advise",
            sc,
            "--tolerance",
            "1e-3",
            "--points",
            "2",
            "--methods",
            "nosuch",
            "--out",
            s(tmp.path()),
        ]),
        "--points",
        "nosuch",
    );
}

// Oracle: the rule that an error names the flag the user gave. A NaN or negative --dt-max is
// that flag's fault, not --dt-min's; a --dt-max so small that the default small end under it
// passes the step limit is --dt-max's too, printed in a few digits (not 300); an unknown
// method names --methods (or run's --method). The twins: the same commands with sound values
// get past those flags.
#[test]
fn the_flag_the_user_gave_is_the_one_blamed() {
    let tmp = tempfile::tempdir().unwrap();
    let sc = spring_scene();
    let out = tmp.path().join("o");
    let o = |extra: &[&str], cmd: &str| {
        let mut a = vec![cmd, s(&sc), "--out", s(&out)];
        a.extend_from_slice(extra);
        run(&a)
    };
    for bad in ["nan", "-1"] {
        one_line_error(&o(&["--dt-max", bad], "advise"), "--dt-max");
    }
    let line = one_line_error(&o(&["--dt-max", "1e-300"], "sweep"), "--dt-max");
    assert!(line.len() < 200, "{line}");
    one_line_error(&o(&["--methods", "no_such"], "compare"), "--methods");
    one_line_error(&o(&["--method", "no_such"], "run"), "--method");
    succeeds(&o(&["--dt-max", "0.01", "--methods", "rk4"], "advise"));
    succeeds(&o(&["--methods", "rk4"], "compare"));
}

/// `--scenarios` names a folder: a scene file or a missing path there is the flag's fault,
/// said on one line. Oracle: the OS (a file is not a folder; a missing path is ENOENT).
#[test]
fn scenarios_naming_a_file_or_nothing_is_refused_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let file = scene(dir.path());
    let missing = dir.path().join("missing");
    for cmd in ["report", "list"] {
        for (path, why) in [(&file, "is a file"), (&missing, "os error 2")] {
            let out = run(&[
                cmd,
                "--scenarios",
                s(path),
                "--out",
                s(&dir.path().join("o")),
            ][..if cmd == "list" { 3 } else { 5 }]);
            let line = one_line_error(&out, "--scenarios");
            assert!(line.contains(s(path)) && line.contains(why), "{line}");
        }
    }
}

/// Twin: the folder that holds the same file is listed.
#[test]
fn twin_scenarios_naming_the_folder_is_listed() {
    let dir = tempfile::tempdir().unwrap();
    scene(dir.path());
    let out = run(&["list", "--scenarios", s(dir.path())]);
    succeeds(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("one_second"));
}

/// A folder this process cannot write into: a read-only folder for a user, a read-only
/// filesystem for root (whom permissions do not stop): one from the mount table, else a
/// read-only tmpfs mounted for the test. `None` where neither exists.
#[cfg(unix)]
fn read_only_folder(dir: &Path) -> Option<PathBuf> {
    use std::os::unix::fs::PermissionsExt;
    if unsafe { libc::geteuid() } != 0 {
        let ro = dir.join("ro");
        std::fs::create_dir(&ro).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        return Some(ro);
    }
    let mounts = std::fs::read_to_string("/proc/mounts").unwrap_or_default();
    let listed = mounts.lines().find_map(|l| {
        let f: Vec<&str> = l.split_whitespace().collect();
        (f.len() > 3 && f[3].split(',').any(|o| o == "ro") && Path::new(f[1]).is_dir())
            .then(|| PathBuf::from(f[1]))
    });
    listed.or_else(|| {
        let ro = dir.join("rofs");
        std::fs::create_dir(&ro).unwrap();
        let mounted = std::process::Command::new("mount")
            .args(["-t", "tmpfs", "-o", "ro", "none"])
            .arg(&ro)
            .status()
            .is_ok_and(|s| s.success());
        mounted.then_some(ro)
    })
}

/// `--out` that cannot be written (a read-only folder, or a symbolic link to nothing, alone
/// or above it) is refused before any work, naming the flag and the path at fault. Oracle:
/// the OS (EROFS or EACCES for the folder; a link whose target is missing).
#[cfg(unix)]
#[test]
fn out_that_cannot_be_written_is_refused_at_once_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let sc = spring_scene();
    let dangling = dir.path().join("dangling");
    std::os::unix::fs::symlink(dir.path().join("nowhere"), &dangling).unwrap();
    let mut cases = vec![
        (dangling.clone(), "which does not exist"),
        (dangling.join("sub"), "which does not exist"),
    ];
    match read_only_folder(dir.path()) {
        Some(ro) => {
            cases.push((ro.clone(), "cannot write there"));
            cases.push((ro.join("sub"), "cannot write there"));
        }
        None => eprintln!("no read-only folder on this machine: only the links are tried"),
    }
    for (out, why) in &cases {
        for args in [
            vec!["compare", s(&sc), "--out", s(out)],
            vec!["report", "--quick", "--out", s(out)],
        ] {
            let line = one_line_error(&run(&args), "--out");
            assert!(line.contains(s(out)) && line.contains(why), "{line}");
        }
    }
    if let Some((ro, _)) = cases.get(2) {
        if ro.ends_with("rofs") {
            let _ = std::process::Command::new("umount").arg(ro).status();
        }
    }
}

/// Twin: a link to a folder that exists is followed and written through.
#[cfg(unix)]
#[test]
fn twin_out_through_a_link_to_a_folder_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("real");
    std::fs::create_dir(&real).unwrap();
    let link = dir.path().join("link");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let sc = spring_scene();
    let out = link.join("run");
    succeeds(&run(&[
        "run",
        s(&sc),
        "-i",
        "rk4",
        "--steps",
        "10",
        "--out",
        s(&out),
    ]));
    assert!(real.join("run/summary.json").is_file());
}

/// A method option the methods asked do not read would change nothing: it is refused on one
/// line naming the flag and the methods that read it, by every command that runs methods.
/// Oracle: the registry's option schema (`list` shows `--xpbd-substeps` read by xpbd only,
/// `--iterations` by verlet_constraints only).
#[test]
fn a_method_option_no_asked_method_reads_is_refused_naming_the_flag() {
    let sc = spring_scene();
    let sc = s(&sc);
    for (args, flag) in [
        (
            vec!["run", sc, "-i", "rk4", "--xpbd-substeps", "4"],
            "--xpbd-substeps",
        ),
        (
            vec![
                "compare",
                sc,
                "--methods",
                "rk4,symplectic_euler",
                "--iterations",
                "5",
            ],
            "--iterations",
        ),
        (
            vec!["sweep", sc, "--methods", "rk4", "--xpbd-iterations", "2"],
            "--xpbd-iterations",
        ),
        (
            vec!["framerate", sc, "--methods", "rk4", "--xpbd-substeps", "2"],
            "--xpbd-substeps",
        ),
    ] {
        let line = one_line_error(&run(&args), flag);
        assert!(line.contains("read only by"), "{line}");
    }
}

/// Twin: the same flags with a method that reads them run.
#[test]
fn twin_a_method_option_its_method_reads_is_used() {
    let dir = tempfile::tempdir().unwrap();
    let sc = spring_scene();
    let sc = s(&sc);
    let o = dir.path().join("o");
    succeeds(&run(&[
        "run",
        sc,
        "-i",
        "xpbd",
        "--xpbd-substeps",
        "4",
        "--steps",
        "10",
        "--out",
        s(&o),
    ]));
    succeeds(&run(&[
        "compare",
        sc,
        "--methods",
        "rk4,xpbd",
        "--xpbd-substeps",
        "2",
        "--duration",
        "0.1",
        "--out",
        s(&o),
    ]));
}
