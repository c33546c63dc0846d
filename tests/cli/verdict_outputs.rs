//! What the verdict leaves in documents: `run` writes every step it computed, a run that is
//! not ok shows no accuracy number anywhere (empty CSV cells, `null` in JSON, "—" in printed
//! tables), and `check` refuses what `run` refuses and names the events mode.
//!
//! Oracles: explicit Euler worked by hand; the verdict's rules (`run::verdict`) for which runs
//! stop; the command contract of docs/commands.md and docs/energy-and-stability.md.

use crate::support::ok;
use std::path::Path;
use std::process::Output;

fn springlab(args: &[&str]) -> Output {
    crate::support::bin().args(args).output().unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// Two unit masses 5 m apart on a spring of k = 2 N/m and rest length 4 m.
const PAIR: &str = "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n\
    [[particle]]\nposition=[5.0,0.0,0.0]\nmass=1.0\n\
    [[spring]]\nbetween=[0,1]\nstiffness=2.0\nrest_length=4.0\n";

#[test]
fn run_writes_both_steps_of_the_worked_explicit_euler_exercise() {
    // By hand, h = 0.5: the spring pulls each mass with 2·(5 − 4) = 2 N.
    // Step 1: x unchanged (v₀ = 0), v = ±0.5·2 = ±1 m/s.
    // Step 2: x = 0 + 0.5·1 = 0.5 and 5 − 0.5 = 4.5; v = ±(1 + 0.5·2) = ±2 m/s (the force at
    // the old positions, still 5 m apart). The energy rises from 1 J to 4 J: a swing of three
    // scene energies, far below the cap; every step is written.
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "pair.toml", PAIR);
    let out = d.path().join("out");
    let text = ok(&[
        "run",
        &scene,
        "-i",
        "explicit_euler",
        "--dt",
        "0.5",
        "--steps",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(text.contains("status: ok"), "{text}");
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(
        rows,
        [
            "0,0,0,0,0,0,0,0,0",
            "0,0,1,5,0,0,0,0,0",
            "1,0.5,0,0,0,0,1,0,0",
            "1,0.5,1,5,0,0,-1,0,0",
            "2,1,0,0.5,0,0,2,0,0",
            "2,1,1,4.5,0,0,-2,0,0",
        ]
    );
}

/// A 10 g mass on k = 1e6 N/m (ω = 1e4 rad/s) at h = 0.01 s: hω = 100, a hundred times past
/// symplectic Euler's limit hω < 2 (ρ ≈ 1e4 per step).
const STIFF: &str = "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
    [[particle]]\nposition=[1.01,0.0,0.0]\nmass=0.01\n\
    [[spring]]\nbetween=[0,1]\nstiffness=1e6\nrest_length=1.0\n\
    [run]\ndt=0.01\nduration=1.0\n";

#[test]
fn a_run_past_the_cap_stops_there_and_shows_no_number() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "stiff.toml", STIFF);
    // `run` computes until the cap, writes the frame that passed it, and has no energy change
    // over a run it did not finish.
    let out = d.path().join("run");
    let text = ok(&[
        "run",
        &scene,
        "-i",
        "symplectic_euler",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(text.contains("past the cap"), "{text}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let done = summary["steps_done"].as_u64().unwrap();
    assert!((1..100).contains(&done), "{summary}");
    assert!(summary["energy_change"].is_null() && summary["energy_error"].is_null());
    let rows = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert_eq!(rows.lines().count() as u64, 1 + 2 * (done + 1));
    // `compare`: the unstable run's error and energy cells are empty, its metrics null, and
    // the printed table shows "—"; its twin, rk4 at a step inside its limit, has numbers.
    let cmp = d.path().join("cmp");
    let printed = ok(&[
        "compare",
        &scene,
        "--methods",
        "symplectic_euler,implicit_euler",
        "--duration",
        "0.1",
        "--out",
        cmp.to_str().unwrap(),
    ]);
    assert!(printed.contains('—'), "{printed}");
    let csv = std::fs::read_to_string(cmp.join("compare.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |row: &str, name: &str| {
        let i = header.iter().position(|h| *h == name).unwrap();
        row.split(',').nth(i).unwrap().to_string()
    };
    let row = |name: &str| {
        csv.lines()
            .find(|l| l.starts_with(&format!("{name},")))
            .unwrap()
            .to_string()
    };
    let bad = row("symplectic_euler");
    assert_eq!(col(&bad, "status"), "unstable");
    for c in ["error_final", "error_max", "energy_drift", "energy_balance"] {
        assert_eq!(col(&bad, c), "", "{c} of an unstable run: {bad}");
    }
    let good = row("implicit_euler");
    assert_eq!(col(&good, "status"), "ok");
    assert!(col(&good, "error_max").parse::<f64>().is_ok(), "{good}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cmp.join("summary.json")).unwrap()).unwrap();
    let entries = json["entries"].as_array().unwrap();
    let metrics = |name: &str| {
        entries
            .iter()
            .find(|e| e["method"] == name)
            .map(|e| e["result"]["metrics"].clone())
            .unwrap()
    };
    assert!(metrics("symplectic_euler").is_null());
    assert!(metrics("implicit_euler")["error_max"].is_f64());
}

#[test]
fn check_refuses_a_frame_kick_that_run_refuses_and_names_the_events_mode() {
    let d = tempfile::tempdir().unwrap();
    let base = "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n\
        [[impulse]]\ntime=TIME\nparticle=0\ndelta_v=[1.0,0.0,0.0]\n\
        [run]\ndt=0.1\nduration=0.9\nevents=\"frame\"\n";
    // A kick at 0.85 s moves to the frame boundary at 0.9 s, the end of the run: it would
    // never act, and both commands say so, naming the field.
    let late = write(d.path(), "late.toml", &base.replace("TIME", "0.85"));
    for cmd in ["check", "run"] {
        let out = springlab(&[cmd, &late, "-i", "rk4"][..if cmd == "check" { 2 } else { 4 }]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains("impulse[0].time"),
            "{cmd}: {err}"
        );
    }
    // Twin: the same kick at 0.75 s moves to 0.8 s and acts; check passes and names the mode.
    let fine = write(d.path(), "fine.toml", &base.replace("TIME", "0.75"));
    let text = ok(&["check", &fine]);
    assert!(text.contains("events = \"frame\""), "{text}");
}
