//! One writer per output folder, and `run`'s projected-size warning, through the binary.
//!
//! Two `springlab run` started together into one `--out` overlap (each computes a 30×30 cloth
//! for seconds of simulated time): exactly one may write the folder, the other must fail at
//! once naming the folder, and the three files left must all be the winner's. The oracle of
//! "all the winner's" is the runs themselves: the two ask for different step counts, and each
//! file records its last step (trajectory.csv and energy.csv in their last row, summary.json
//! in `steps`), so a folder mixing the two runs shows two different last steps.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

/// The shipped cloth at 30×30 particles.
const SCENE: &str = "\
[world]\ngravity = [0.0, -9.81, 0.0]\n[[cloth]]\norigin = [0.0, 0.0, 0.0]\nsize = [1.0, 1.0]\n\
count = [30, 30]\nmass = 0.001\nstiffness = 200.0\ndamping = 0.002\nbend_stiffness = 20.0\n\
plane = \"xz\"\nfix = [\"top_left\", \"top_right\"]\n[run]\ndt = 0.001\nduration = 1.0\n";
const PARTICLES: usize = 900;
const BUSY: &str = "another springlab command is writing this folder";

fn scene(dir: &Path) -> PathBuf {
    let p = dir.join("cloth30.toml");
    std::fs::write(&p, SCENE).unwrap();
    p
}

fn start(scene: &Path, out: &Path, steps: u64, every: u64) -> Child {
    crate::support::bin()
        .arg("run")
        .arg(scene)
        .args(["-i", "symplectic_euler", "--steps", &steps.to_string()])
        .args(["--every", &every.to_string(), "--out"])
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn last_step(csv: &Path) -> u64 {
    let text = std::fs::read_to_string(csv).unwrap();
    let last = text.lines().last().unwrap();
    last.split(',').next().unwrap().parse().unwrap()
}

/// The steps recorded by each of the folder's three files, and trajectory.csv's data rows.
fn folder_steps(dir: &Path) -> ([u64; 3], usize) {
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    let rows = std::fs::read_to_string(dir.join("trajectory.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    (
        [
            last_step(&dir.join("trajectory.csv")),
            last_step(&dir.join("energy.csv")),
            summary["steps"].as_u64().unwrap(),
        ],
        rows,
    )
}

/// Rows of trajectory.csv for `steps` at `every`: frames 0, every, 2·every, … and the last.
fn rows(steps: u64, every: u64) -> usize {
    (steps / every + 1 + u64::from(steps % every != 0)) as usize * PARTICLES
}

const EVERY: u64 = 100;

#[test]
fn two_runs_into_one_folder_one_writes_and_the_other_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let t0 = std::time::Instant::now();
    for trial in 0..10 {
        let out = tmp.path().join(format!("same-{trial}"));
        let steps = [3000, 3001];
        let a = start(&scene, &out, steps[0], EVERY);
        let b = start(&scene, &out, steps[1], EVERY);
        let runs: Vec<Output> = [a, b]
            .into_iter()
            .map(|c| c.wait_with_output().unwrap())
            .collect();
        let ok: Vec<usize> = (0..2).filter(|&k| runs[k].status.success()).collect();
        assert_eq!(ok.len(), 1, "trial {trial}: exactly one run writes");
        let (won, lost) = (ok[0], 1 - ok[0]);
        let err = String::from_utf8_lossy(&runs[lost].stderr);
        assert!(
            err.contains(BUSY) && err.contains(&out.display().to_string()),
            "trial {trial}: the refused run names the folder and why: {err}"
        );
        let (recorded, traj_rows) = folder_steps(&out);
        assert_eq!(
            recorded, [steps[won]; 3],
            "trial {trial}: trajectory.csv, energy.csv and summary.json all from the winner"
        );
        assert_eq!(traj_rows, rows(steps[won], EVERY), "trial {trial}");
    }
    assert!(t0.elapsed().as_secs() < 60, "{:?}", t0.elapsed());
}

#[test]
fn two_runs_into_two_folders_both_write() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let steps = [3000, 3001];
    let outs = [tmp.path().join("a"), tmp.path().join("b")];
    let kids: Vec<Child> = (0..2)
        .map(|k| start(&scene, &outs[k], steps[k], EVERY))
        .collect();
    for (k, c) in kids.into_iter().enumerate() {
        let o = c.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let (recorded, traj_rows) = folder_steps(&outs[k]);
        assert_eq!(recorded, [steps[k]; 3]);
        assert_eq!(traj_rows, rows(steps[k], EVERY));
    }
}

/// A size printed by `run` (`146.74 MB`) in bytes.
fn bytes(s: &str) -> f64 {
    let mut it = s.split_whitespace();
    let v: f64 = it.next().unwrap().parse().unwrap();
    let unit = match it.next().unwrap() {
        "GB" => 1e9,
        "MB" => 1e6,
        "kB" => 1e3,
        "B" => 1.0,
        u => panic!("unit {u}"),
    };
    v * unit
}

/// The size `run` projects for `name` in its `projected output` line.
fn projected(line: &str, name: &str) -> f64 {
    let at = line.find(&format!("{name} ")).unwrap() + name.len() + 1;
    let rest = &line[at..];
    let end = rest.find([',', ')']).unwrap();
    bytes(&rest[..end])
}

/// Starts a run, reads its first line of stdout (the projection, printed after any warning)
/// and kills it: the warning is what is tested, not the gigabytes the run would write.
fn first_words(scene: &Path, out: &Path, steps: u64, every: u64) -> (String, String) {
    let mut c = start(scene, out, steps, every);
    let mut line = String::new();
    BufReader::new(c.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    c.kill().unwrap();
    let o = c.wait_with_output().unwrap();
    (line, String::from_utf8_lossy(&o.stderr).into_owned())
}

// Oracle for the warning's threshold and suggestion: the projections `run` prints for the
// suggested --every (at most 100 MB, no warning) and for one less (above, warned). Oracle for
// the projection itself: the files a small run writes.
#[test]
fn a_large_run_warns_and_its_suggested_every_does_not() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let out = tmp.path().join("big");
    // 10 s of the 30×30 cloth writes every step: over a gigabyte.
    let (line, err) = first_words(&scene, &out, 10_000, 1);
    assert!(line.starts_with("projected output: about "), "{line}");
    let warning = err
        .lines()
        .find(|l| l.starts_with("warning: "))
        .unwrap_or_else(|| panic!("no warning: {err}"));
    assert!(warning.contains("above 100.00 MB"), "{warning}");
    let k: u64 = warning
        .split("--every ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no --every N in: {warning}"));
    assert!(k > 1, "{warning}");
    let total = |l: &str| projected(l, "trajectory.csv") + projected(l, "energy.csv");
    assert!(total(&line) > 1e9, "{line}");
    let (at_k, err_k) = first_words(&scene, &out, 10_000, k);
    assert!(
        total(&at_k) <= 1.0001e8 && !err_k.contains("warning"),
        "{at_k} {err_k}"
    );
    let (below, err_below) = first_words(&scene, &out, 10_000, k - 1);
    assert!(
        total(&below) > 1e8 && err_below.contains("warning"),
        "{below}"
    );
}

#[test]
fn a_small_run_prints_its_projection_without_a_warning() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let out = tmp.path().join("small");
    let o = start(&scene, &out, 300, 3).wait_with_output().unwrap();
    assert!(o.status.success());
    let stdout = String::from_utf8_lossy(&o.stdout);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("warning"), "{err}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("projected output:"))
        .unwrap();
    // Trajectory rows are six numbers of order one; energy rows carry zeros and are looser.
    for (name, tol) in [("trajectory.csv", 0.1), ("energy.csv", 0.15)] {
        let actual = std::fs::metadata(out.join(name)).unwrap().len() as f64;
        let p = projected(line, name);
        assert!(
            (p / actual - 1.0).abs() < tol,
            "{name}: projected {p} B, wrote {actual} B"
        );
    }
}

/// A folder holding copies of two small shipped scenes.
fn two_small_scenes(dir: &Path) -> PathBuf {
    let s = dir.join("scenes");
    std::fs::create_dir_all(&s).unwrap();
    for f in ["anchored_spring.toml", "recoil_spring.toml"] {
        std::fs::copy(Path::new("scenarios").join(f), s.join(f)).unwrap();
    }
    s
}

fn report_cmd(scenes: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = crate::support::bin();
    c.args(["report", "--quick", "--scenarios"])
        .arg(scenes)
        .arg("--out")
        .arg(out)
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

// Oracle: the sharing rule of a report's shards (any number of `--shard I/N` processes may
// write one folder side by side, whenever they start): two shards spawned at the same instant
// both succeed, into a fresh folder and into an existing one; the twin near the same edge: a
// whole (unsharded) report writing the folder refuses a shard started beside it.
#[test]
fn shards_started_together_all_run_and_a_whole_report_still_excludes_them() {
    let tmp = tempfile::tempdir().unwrap();
    let scenes = two_small_scenes(tmp.path());
    for trial in 0..8 {
        // Fresh folders on even trials, the previous trial's folder on odd ones.
        let out = tmp.path().join(format!("out{}", trial / 2));
        let kids: Vec<Child> = (0..2)
            .map(|i| {
                report_cmd(&scenes, &out, &["--no-cache", "--shard", &format!("{i}/2")])
                    .spawn()
                    .unwrap()
            })
            .collect();
        for k in kids {
            let o = k.wait_with_output().unwrap();
            assert!(
                o.status.success(),
                "trial {trial}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
    }
    // The twin: a whole-folder writer (a long run) holds the folder alone past the shards'
    // wait; a shard started beside it is refused.
    let out = tmp.path().join("whole");
    let mut run = start(&scene(tmp.path()), &out, 100_000_000, 1000);
    let t0 = std::time::Instant::now();
    while !out.exists() && t0.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(5));
    }
    std::thread::sleep(Duration::from_millis(100));
    let shard = report_cmd(&scenes, &out, &["--shard", "0/2"])
        .output()
        .unwrap();
    run.kill().unwrap();
    run.wait().unwrap();
    let err = String::from_utf8_lossy(&shard.stderr);
    assert!(!shard.status.success() && err.contains(BUSY), "{err}");
}

/// `run` with the given extra arguments (no `--every` unless among them), and an optional
/// file-size limit (bytes) set in the child as `ulimit -f` would.
fn run_sized(scene: &Path, out: &Path, steps: u64, extra: &[&str], fsize: Option<u64>) -> Output {
    let mut c = crate::support::bin();
    c.arg("run")
        .arg(scene)
        .args(["-i", "symplectic_euler", "--steps", &steps.to_string()])
        .args(extra)
        .arg("--out")
        .arg(out);
    #[cfg(unix)]
    if let Some(bytes) = fsize {
        use std::os::unix::process::CommandExt;
        // SAFETY: only async-signal-safe setrlimit runs between fork and exec.
        unsafe {
            c.pre_exec(move || {
                let r = libc::rlimit {
                    rlim_cur: bytes,
                    rlim_max: bytes,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &r) == 0 {
                    Ok(())
                } else {
                    Err(std::io::Error::last_os_error())
                }
            });
        }
    }
    c.output().unwrap()
}

// Oracle: the projection `run` prints (checked against written files above): 10 000 frames of
// the 30×30 cloth are over a gigabyte, 300 frames about 40 MB. Past 100 MB without `--every`
// the run is refused before it writes anything; with `--every` written out it is the user's
// choice (the warning test above).
#[test]
fn a_large_run_without_every_is_refused_before_it_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let out = tmp.path().join("big");
    let o = run_sized(&scene, &out, 10_000, &[], None);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.starts_with("error: --every: this run would write about ") && err.contains("--every "),
        "{err}"
    );
    assert!(!out.join("trajectory.csv").exists());
}

// Oracle: the OS's file-size limit (RLIMIT_FSIZE, set in the child) against the projection:
// 300 frames of 900 particles are about 40 MB, above a 1 MB limit, so the run is refused
// naming the limit instead of dying of SIGXFSZ mid-file; its twin under a 1 GB limit writes.
#[cfg(unix)]
#[test]
fn a_run_past_the_file_size_limit_is_refused_and_its_twin_within_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let out = tmp.path().join("limited");
    let o = run_sized(&scene, &out, 300, &[], Some(1_000_000));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.starts_with("error: --every: ") && err.contains("file-size limit of 1.00 MB"),
        "{err}"
    );
    assert!(
        !out.exists()
            || std::fs::read_dir(&out).unwrap().all(|e| {
                let n = e.unwrap().file_name();
                !n.to_string_lossy().ends_with(".csv")
            })
    );
    let o = run_sized(&scene, &out, 300, &[], Some(1_000_000_000));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("trajectory.csv").is_file());
}
