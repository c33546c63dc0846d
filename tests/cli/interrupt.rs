//! An interrupted run leaves earlier outputs intact: `springlab run` writes into an output
//! directory once (completes), then a second, long run into the same directory is killed
//! midway. The first run's files must be byte-identical and parse, and the final names must
//! never hold a half-written file (outputs go to hidden temporary names, renamed on success).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const SCENE: &str = "\
[world]\ngravity = [0.0, -9.81, 0.0]\n[[cloth]]\norigin = [0.0, 0.0, 0.0]\nsize = [1.0, 1.0]\n\
count = [16, 16]\nmass = 0.001\nstiffness = 200.0\ndamping = 0.002\nplane = \"xz\"\n\
fix = [\"top_left\", \"top_right\"]\n[run]\ndt = 0.001\nsteps = 50\n";

const FINAL: [&str; 3] = ["trajectory.csv", "energy.csv", "summary.json"];

fn springlab() -> Command {
    crate::support::bin()
}

fn read_all(dir: &Path) -> Vec<Vec<u8>> {
    FINAL
        .iter()
        .map(|f| std::fs::read(dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}")))
        .collect()
}

#[test]
fn killed_run_leaves_the_previous_outputs_intact() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("cloth.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = tmp.path().join("out");
    let st = springlab()
        .args([
            "run",
            scene.to_str().unwrap(),
            "-i",
            "symplectic_euler",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let before = read_all(&out);

    // The second run would take minutes: 10⁷ steps writing every step (`--force`: past the
    // free space, which it never reaches before it is killed).
    let mut child = springlab()
        .args([
            "run",
            scene.to_str().unwrap(),
            "-i",
            "rk4",
            "--steps",
            "10000000",
            "--force",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it once it has started writing its temporary files (or after 2 s at most).
    let t0 = Instant::now();
    loop {
        std::thread::sleep(Duration::from_millis(50));
        let writing = std::fs::read_dir(&out)
            .unwrap()
            .filter_map(|e| e.ok())
            .any(|e| {
                e.file_name().to_string_lossy().contains(".tmp-")
                    && e.metadata().map(|m| m.len() > 0).unwrap_or(false)
            });
        if writing || t0.elapsed() > Duration::from_secs(2) {
            break;
        }
    }
    std::thread::sleep(Duration::from_millis(200));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the second run ended before it was killed"
    );
    child.kill().unwrap();
    child.wait().unwrap();

    // The final names hold exactly the first run's outputs...
    assert_eq!(read_all(&out), before, "earlier outputs changed");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["method"], "symplectic_euler");
    assert_eq!(summary["steps_done"], 50);
    let mut rdr = csv::Reader::from_path(out.join("energy.csv")).unwrap();
    assert_eq!(
        rdr.records().collect::<Result<Vec<_>, _>>().unwrap().len(),
        51
    );
    let mut rdr = csv::Reader::from_path(out.join("trajectory.csv")).unwrap();
    assert_eq!(
        rdr.records().collect::<Result<Vec<_>, _>>().unwrap().len(),
        51 * 256
    );
    // ...and anything else in the directory is a hidden temporary of the killed run.
    for e in std::fs::read_dir(&out).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            FINAL.contains(&name.as_str())
                || name == springlab::output::TIMING_FILE
                || (name.starts_with('.') && name.contains(".tmp-")),
            "unexpected file {name}"
        );
    }
}

/// Every hidden name (a temporary file or staging folder) anywhere under `dir`.
fn hidden_under(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') {
                out.push(e.path().display().to_string());
            }
            if e.path().is_dir() {
                stack.push(e.path());
            }
        }
    }
    out
}

/// Sends `sig` to a running command after `after`; its exit code and stderr.
#[cfg(unix)]
fn signalled(args: &[&str], out: &Path, sig: i32, after: Duration) -> (Option<i32>, String) {
    let child = springlab()
        .args(args)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    // SAFETY: signalling a child this test started and has not yet reaped.
    unsafe {
        libc::kill(child.id() as i32, sig);
    }
    let o = child.wait_with_output().unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

// Oracle: the shell's convention for a command ended by a signal (exit 128 + signal: 130 for
// SIGINT, 143 for SIGTERM), and the rule that nothing unfinished stays behind: after Ctrl-C on
// run, compare, sweep and report, one line says what was kept and no hidden name is left.
// The twin: the same command left to finish exits 0 without that line.
#[cfg(unix)]
#[test]
fn ctrl_c_stops_a_command_with_one_line_and_no_temporary_left() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("cloth.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let s = scene.to_str().unwrap();
    let scenes = tmp.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    std::fs::copy(&scene, scenes.join("cloth.toml")).unwrap();
    let long_run = ["run", s, "-i", "rk4", "--steps", "10000000", "--force"];
    let cases: [(&[&str], i32, i32); 4] = [
        (&long_run, libc::SIGINT, 130),
        (&["compare", s, "--duration", "100"], libc::SIGINT, 130),
        (
            &["sweep", s, "--duration", "100", "--points", "12"],
            libc::SIGTERM,
            143,
        ),
        (
            &[
                "report",
                "--scenarios",
                scenes.to_str().unwrap(),
                "--no-cache",
            ],
            libc::SIGINT,
            130,
        ),
    ];
    for (k, (args, sig, code)) in cases.into_iter().enumerate() {
        let out = tmp.path().join(format!("out{k}"));
        let (got, err) = signalled(args, &out, sig, Duration::from_millis(1500));
        assert_eq!(got, Some(code), "{args:?}: {err}");
        let lines: Vec<_> = err.lines().filter(|l| l.contains("stopped by")).collect();
        assert_eq!(lines.len(), 1, "{args:?}: {err}");
        assert!(lines[0].contains("kept"), "{}", lines[0]);
        assert_eq!(hidden_under(&out), Vec::<String>::new(), "{args:?}");
    }
    // The twin: a short run ends by itself, with no such line.
    let o = springlab()
        .args(["run", s, "-i", "symplectic_euler", "--out"])
        .arg(tmp.path().join("short"))
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stderr).contains("stopped by"));
}

// Oracle: a write that fails (a file-size limit, as on a full disk) removes its own temporary
// file before the command exits with the error; the twin without the limit writes the files.
#[cfg(unix)]
#[test]
fn a_failed_write_leaves_no_temporary_file() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("cloth.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = tmp.path().join("out");
    let args = [
        "run",
        scene.to_str().unwrap(),
        "-i",
        "symplectic_euler",
        "--out",
    ];
    let o = Command::new("sh")
        .env("SPRINGLAB_NO_CACHE", "1")
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 16; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_springlab"))
        .args(args)
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success(), "the limit did not bite");
    assert_eq!(hidden_under(&out), Vec::<String>::new());
    let ok = springlab().args(args).arg(&out).output().unwrap();
    assert!(ok.status.success());
    assert!(out.join("trajectory.csv").is_file());
}
