//! One truth: a report of two scenes holds the very documents the commands write, and every
//! `"command"` in it re-creates its document. Oracle: the commands themselves: re-running each
//! printed command line must give the same numbers bit for bit (wall times aside), and the
//! report's stability limits must be the `stability` command's.

use serde_json::Value;
use springlab::measure::command::split_words;
use std::path::{Path, PathBuf};
use std::process::Command;

fn springlab(args: &[String], cwd: &Path) {
    let out = Command::new(env!("CARGO_BIN_EXE_springlab"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "springlab {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `a` and `b` agree on every value except measured times (wall times and their timing
/// statistics) and the command line itself.
fn same(a: &Value, b: &Value, path: &str) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: Vec<&String> = x.keys().collect();
            assert_eq!(keys, y.keys().collect::<Vec<_>>(), "{path}: keys differ");
            for (k, v) in x {
                if k == "command" || k.contains("wall") || k == "timing" {
                    continue;
                }
                same(v, &y[k], &format!("{path}.{k}"));
            }
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{path}: lengths differ");
            for (i, (u, v)) in x.iter().zip(y).enumerate() {
                same(u, v, &format!("{path}[{i}]"));
            }
        }
        _ => assert_eq!(a, b, "{path}"),
    }
}

/// An advice document with what follows from the wall-time ranking set aside: the pick and
/// the order of the alternatives (advise ranks by measured time, so a near-tie may rank the
/// other way on a re-run); every candidate's own numbers stay, sorted by name.
fn without_ranking(mut v: Value) -> Value {
    let o = v.as_object_mut().unwrap();
    for k in [
        "integrator",
        "dt",
        "predicted_error",
        "verified_error",
        "cost_per_second",
        "cost_per_second_reason",
        "picked_by",
    ] {
        o.remove(k);
    }
    if let Some(Value::Array(alts)) = o.get_mut("alternatives") {
        alts.sort_by(|a, b| a["integrator"].as_str().cmp(&b["integrator"].as_str()));
    }
    if let Some(Value::Array(frs)) = o.get_mut("frame_rates") {
        for f in frs {
            let f = f.as_object_mut().unwrap();
            f.remove("best");
            f.remove("picked_by");
        }
    }
    v
}

/// CSV files agree on every column except wall times.
fn same_csv(a: &str, b: &str, what: &str) {
    let (ha, hb) = (a.lines().next().unwrap(), b.lines().next().unwrap());
    assert_eq!(ha, hb, "{what}: headers differ");
    let skip: Vec<usize> = ha
        .split(',')
        .enumerate()
        .filter(|(_, h)| h.contains("wall"))
        .map(|(i, _)| i)
        .collect();
    let strip = |t: &str| -> Vec<Vec<String>> {
        let mut r = csv::ReaderBuilder::new()
            .has_headers(true)
            .from_reader(t.as_bytes());
        r.records()
            .map(|rec| {
                rec.unwrap()
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| !skip.contains(i))
                    .map(|(_, v)| v.to_string())
                    .collect()
            })
            .collect()
    };
    assert_eq!(strip(a), strip(b), "{what}: rows differ");
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn every_command_in_a_report_recreates_its_document() {
    let tmp = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenes = tmp.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    for s in ["anchored_spring", "bounce"] {
        std::fs::copy(
            root.join(format!("scenarios/{s}.toml")),
            scenes.join(format!("{s}.toml")),
        )
        .unwrap();
    }
    let out = tmp.path().join("reports");
    springlab(
        &[
            "report".into(),
            "--quick".into(),
            "--scenarios".into(),
            scenes.display().to_string(),
            "--out".into(),
            out.display().to_string(),
        ],
        tmp.path(),
    );
    let mut rerun = 0;
    for scene in ["anchored_spring", "bounce"] {
        let dir = out.join(scene);
        let res: Value = serde_json::from_str(&read(&dir.join("results.json"))).unwrap();
        let docs = res["documents"].as_array().unwrap();
        assert!(docs.len() >= 5, "{scene}: {} documents", docs.len());
        for d in docs {
            let file = dir.join(d["file"].as_str().unwrap());
            let line = d["command"].as_str().unwrap();
            let mut words = split_words(line);
            assert_eq!(words[0], "springlab");
            // Re-run into a fresh folder: replace the value of --out.
            let k = words.iter().position(|w| w == "--out").expect("--out");
            let again: PathBuf = tmp.path().join(format!("again-{rerun}"));
            words[k + 1] = again.display().to_string();
            springlab(&words[1..], tmp.path());
            let name = file.file_name().unwrap();
            let fresh = again.join(name);
            let (a, b) = (read(&file), read(&fresh));
            if name.to_string_lossy().ends_with(".json") {
                let (a, b): (Value, Value) = (
                    serde_json::from_str(&a).unwrap(),
                    serde_json::from_str(&b).unwrap(),
                );
                assert_eq!(a["command"].as_str(), Some(line), "{}", file.display());
                let (a, b) = if name == "advice.json" {
                    (without_ranking(a), without_ranking(b))
                } else {
                    (a, b)
                };
                same(&a, &b, &file.display().to_string());
            } else {
                same_csv(&a, &b, &file.display().to_string());
            }
            rerun += 1;
        }
        // The page's stability limits are the stability command's.
        let st: Value = serde_json::from_str(&read(&dir.join("stability/stability.json"))).unwrap();
        for b in res["backends"].as_array().unwrap() {
            if let Some(i) = st["integrators"]
                .as_array()
                .unwrap()
                .iter()
                .find(|i| i["integrator"] == b["backend"])
            {
                assert_eq!(
                    b["stable_dt"], i["max_stable_dt"],
                    "{scene} {}",
                    b["backend"]
                );
            }
        }
    }
    assert!(rerun >= 10, "only {rerun} documents re-run");
    // The closed form's order reads "exact" in JSON and on the page.
    let res: Value =
        serde_json::from_str(&read(&out.join("anchored_spring/results.json"))).unwrap();
    let analytic = res["backends"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["backend"] == "analytic")
        .unwrap();
    assert_eq!(analytic["order"], "exact");
    let page = read(&out.join("anchored_spring/index.html"));
    assert!(page.contains("<td class=\"l\">analytic</td><td>exact</td>"));
    assert!(!page.contains("4294967295") && !read(&out.join("index.html")).contains("4294967295"));
}
