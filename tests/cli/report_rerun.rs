//! Re-running the report leaves every file whose numbers did not change byte-identical: the
//! measured wall times live in each scene's `timing.json`, nothing else moves. Oracle: the
//! files themselves, byte for byte; the twin changes one scene (its length) and sees exactly
//! that scene's files change while the other scene's stay as they were. An unchanged scene is
//! not studied again at all (its folder is kept, timing included) unless `--no-cache` asks.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Runs a quick report with `extra` flags; its stderr.
fn report_with(scenes: &Path, out: &Path, extra: &[&str]) -> String {
    let o = crate::support::bin()
        .args(["report", "--quick", "--scenarios"])
        .arg(scenes)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    err
}

fn report(scenes: &Path, out: &Path) {
    report_with(scenes, out, &[]);
}

/// True when the report's stderr says it kept `scene`'s folder without studying it.
fn kept(stderr: &str, scene: &str) -> bool {
    stderr.contains(&format!("report: {scene} kept:"))
}

/// Every file under `dir` by its path from `dir`.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_path_buf();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// The files that differ between two snapshots (or exist in one only).
fn changed(a: &BTreeMap<PathBuf, Vec<u8>>, b: &BTreeMap<PathBuf, Vec<u8>>) -> Vec<PathBuf> {
    a.keys()
        .chain(b.keys())
        .filter(|k| a.get(*k) != b.get(*k))
        .cloned()
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect()
}

/// A folder under `tmp` holding copies of two shipped scenes, the anchored and the recoil
/// spring.
fn two_scenes(tmp: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenes = tmp.join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    for s in ["anchored_spring", "recoil_spring"] {
        std::fs::copy(
            root.join(format!("scenarios/{s}.toml")),
            scenes.join(format!("{s}.toml")),
        )
        .unwrap();
    }
    scenes
}

fn is_timing(p: &Path) -> bool {
    p.file_name().is_some_and(|n| n == "timing.json")
}

#[test]
fn a_rerun_changes_only_the_timing_files_and_a_changed_scene_only_its_own() {
    let tmp = tempfile::tempdir().unwrap();
    let scenes = two_scenes(tmp.path());
    let out = tmp.path().join("reports");
    report(&scenes, &out);
    let first = files(&out);
    assert!(first.keys().any(|k| is_timing(k)), "no timing.json written");
    // The wall times are kept, not dropped: read back, compare's CSV has them on every line.
    let back =
        springlab::output::read_document(out.join("anchored_spring/compare/compare.csv")).unwrap();
    let mut rdr = csv::Reader::from_reader(back.as_bytes());
    let col = rdr
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "wall_seconds")
        .expect("wall_seconds read back");
    for r in rdr.records() {
        let t: f64 = r.unwrap()[col].parse().expect("a wall time on every line");
        assert!(t > 0.0);
    }
    // Unchanged: every scene kept, not one byte written differently, timing included.
    let err = report_with(&scenes, &out, &[]);
    assert!(
        kept(&err, "anchored_spring") && kept(&err, "recoil_spring"),
        "{err}"
    );
    assert_eq!(changed(&first, &files(&out)), Vec::<PathBuf>::new());
    // Studied again: the same documents, only the measured wall times move.
    let err = report_with(&scenes, &out, &["--no-cache"]);
    assert!(
        !kept(&err, "anchored_spring") && !kept(&err, "recoil_spring"),
        "{err}"
    );
    let second = files(&out);
    let moved = changed(&first, &second);
    assert!(
        moved.iter().all(|p| is_timing(p)),
        "a re-run changed more than the timing files: {moved:?}"
    );
    // Each scene has one timing document; the report's overview has its own.
    for s in ["anchored_spring", "recoil_spring"] {
        let timing: Vec<_> = second
            .keys()
            .filter(|k| k.starts_with(s) && is_timing(k))
            .collect();
        assert_eq!(timing.len(), 1, "{s}: {timing:?}");
    }
    // The twin: a longer anchored spring changes its own numbers, and only its own files.
    let path = scenes.join("anchored_spring.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("duration = 10.0", "duration = 12.0")).unwrap();
    let err = report_with(&scenes, &out, &[]);
    assert!(
        !kept(&err, "anchored_spring") && kept(&err, "recoil_spring"),
        "{err}"
    );
    let third = files(&out);
    let moved = changed(&second, &third);
    assert!(moved
        .iter()
        .any(|p| p.starts_with("anchored_spring") && !is_timing(p)));
    assert!(
        moved
            .iter()
            .filter(|p| p.starts_with("recoil_spring"))
            .all(|p| is_timing(p)),
        "the unchanged scene changed: {moved:?}"
    );
    // A changed flag is a changed input: every scene is studied again.
    let err = report_with(&scenes, &out, &["--energy-terms"]);
    assert!(
        !kept(&err, "anchored_spring") && !kept(&err, "recoil_spring"),
        "{err}"
    );
}

/// Sharded, then merged: every file but the timing documents is the unsharded report's, byte
/// for byte, once each report's folder is named alike (the shards' records aside).
#[test]
fn shards_merged_give_the_unsharded_report() {
    let tmp = tempfile::tempdir().unwrap();
    let scenes = two_scenes(tmp.path());
    let whole = tmp.path().join("whole");
    report(&scenes, &whole);
    let sharded = tmp.path().join("sharded");
    let run = |extra: &[&str]| {
        let o = crate::support::bin()
            .args(["report", "--quick", "--scenarios"])
            .arg(&scenes)
            .arg("--out")
            .arg(&sharded)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(&["--shard", "0/2"]);
    run(&["--shard", "1/2"]);
    run(&["--merge"]);
    // The commands name their folder: each report's own path reads as OUT.
    let named = |dir: &Path| -> BTreeMap<PathBuf, Vec<u8>> {
        let from = dir.display().to_string();
        files(dir)
            .into_iter()
            .map(|(k, v)| {
                (
                    k,
                    String::from_utf8_lossy(&v)
                        .replace(&from, "OUT")
                        .into_bytes(),
                )
            })
            .collect()
    };
    let (a, b) = (named(&whole), named(&sharded));
    assert!(a.keys().any(|k| k.ends_with("results.json")));
    let differ: Vec<_> = changed(&a, &b)
        .into_iter()
        .filter(|p| !is_timing(p) && !p.starts_with("shards"))
        .collect();
    assert!(differ.is_empty(), "merged differs from whole: {differ:?}");
}

/// The overview an earlier report wrote is still read, so a scene that fails in the next
/// report keeps its row. Oracle: `tests/data/earlier_summary.json`, one scene cut from a
/// report written before rows named their method `method` (`backends`/`backend`,
/// `stability_method`, `seconds`, answers' `integrator`): every value reads as written there.
#[test]
fn an_earlier_overview_is_read_with_its_own_words() {
    let dir = tempfile::tempdir().unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/earlier_summary.json");
    std::fs::copy(&fixture, dir.path().join("summary.json")).unwrap();
    let sum = springlab::report::overview::previous_summary(dir.path()).expect("readable");
    let scene = &sum.scenes[0];
    assert_eq!(scene.scene, "anchored_spring");
    let row = &scene.methods[0];
    assert_eq!(row.method, "explicit_euler");
    assert_eq!(row.stability_decided_by.as_deref(), Some("spectral_radius"));
    assert_eq!(scene.seconds.compare, 0.210808237);
    let answer = scene.answer.as_ref().expect("an answer");
    assert_eq!(answer.free_step.method.as_deref(), Some("position_verlet"));
    assert_eq!(answer.game_rate.method.as_deref(), Some("symplectic_euler"));
    // Twin: a row that names no method at all is not a row; the overview is unreadable.
    let text = std::fs::read_to_string(&fixture).unwrap();
    let broken = text.replacen("\"backend\":", "\"nothing\":", 1);
    assert_ne!(broken, text);
    std::fs::write(dir.path().join("summary.json"), broken).unwrap();
    assert!(springlab::report::overview::previous_summary(dir.path()).is_none());
}
