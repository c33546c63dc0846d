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
    Command::new(env!("CARGO_BIN_EXE_springlab"))
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

    // The second run would take minutes: 10⁷ steps writing every step.
    let mut child = springlab()
        .args([
            "run",
            scene.to_str().unwrap(),
            "-i",
            "rk4",
            "--steps",
            "10000000",
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
