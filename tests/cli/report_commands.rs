//! One truth: a report of two scenes holds the very documents the commands write, and every
//! `"command"` in it re-creates its document. Oracle: the commands themselves: re-running each
//! printed command line must give the same document, advice's ranking included (wall times are
//! apart, in each folder's timing.json), and the report's stability limits must be the
//! `stability` command's.

use serde_json::Value;
use springlab::measure::command::split_words;
use std::path::{Path, PathBuf};

fn springlab(args: &[String], cwd: &Path) {
    let out = crate::support::bin()
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

/// `a` and `b` agree on every value except the command line itself (which names its folder);
/// no wall time (a number under a `wall` key) is left in either.
fn same(a: &Value, b: &Value, path: &str) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: Vec<&String> = x.keys().collect();
            assert_eq!(keys, y.keys().collect::<Vec<_>>(), "{path}: keys differ");
            for (k, v) in x {
                assert!(
                    !(k.contains("wall") && v.is_number()) && k != "timing",
                    "{path}.{k}: a wall time"
                );
                if k == "command" {
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

/// A CSV document re-created byte for byte (its wall times are in the folder's timing.json).
fn same_csv(a: &str, b: &str, what: &str) {
    assert_eq!(a, b, "{what}: differs");
    assert!(
        !a.lines().next().unwrap().contains("wall"),
        "{what}: a wall time in a document"
    );
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
                same(&a, &b, &file.display().to_string());
            } else {
                same_csv(&a, &b, &file.display().to_string());
            }
            rerun += 1;
        }
        // The page's stability limits are the stability command's.
        let st: Value = serde_json::from_str(&read(&dir.join("stability/stability.json"))).unwrap();
        for b in res["methods"].as_array().unwrap() {
            if let Some(i) = st["methods"]
                .as_array()
                .unwrap()
                .iter()
                .find(|i| i["method"] == b["method"])
            {
                assert_eq!(
                    b["stable_dt"], i["max_stable_dt"],
                    "{scene} {}",
                    b["method"]
                );
            }
        }
    }
    assert!(rerun >= 10, "only {rerun} documents re-run");
    // The closed form's order reads "exact" in JSON and on the page.
    let res: Value =
        serde_json::from_str(&read(&out.join("anchored_spring/results.json"))).unwrap();
    let analytic = res["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["method"] == "analytic")
        .unwrap();
    assert_eq!(analytic["order"], "exact");
    let page = read(&out.join("anchored_spring/index.html"));
    assert!(page.contains("<td class=\"l\">analytic</td><td>exact</td>"));
    assert!(!page.contains("4294967295") && !read(&out.join("index.html")).contains("4294967295"));
}

/// A command run with values away from their defaults records them: re-running the recorded
/// line gives the same document. Oracle: the commands themselves, with `--blowup-factor 50`
/// (the default is 1000), a flag every measuring command reads, and `--linear-solver
/// block_ic0_cg`, a choice option the implicit methods read.
#[test]
fn a_non_default_run_records_the_command_that_recreates_it() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/anchored_spring.toml");
    let scene = scene.display().to_string();
    for (cmd, doc, extra) in [
        ("compare", "summary.json", vec!["--duration", "1"]),
        ("sweep", "summary.json", vec!["--duration", "1"]),
        ("stability", "stability.json", vec![]),
        (
            "advise",
            "advice.json",
            vec!["--tolerance", "1e-3", "--horizon", "1"],
        ),
        (
            "framerate",
            "framerate.json",
            vec!["--duration", "1", "--hz", "60"],
        ),
    ] {
        let first = tmp.path().join(format!("{cmd}-first"));
        let mut args: Vec<String> = vec![cmd.into(), scene.clone()];
        args.extend(extra.iter().map(|s| s.to_string()));
        args.extend(
            [
                "--blowup-factor",
                "50",
                "--linear-solver",
                "block_ic0_cg",
                "--out",
            ]
            .map(String::from),
        );
        args.push(first.display().to_string());
        springlab(&args, tmp.path());
        let a: Value = serde_json::from_str(&read(&first.join(doc))).unwrap();
        let line = a["command"].as_str().unwrap();
        assert!(line.contains("--blowup-factor 50"), "{cmd}: {line}");
        assert!(
            line.contains("--linear-solver block_ic0_cg"),
            "{cmd}: {line}"
        );
        let mut words = split_words(line);
        let k = words.iter().position(|w| w == "--out").expect("--out");
        let again = tmp.path().join(format!("{cmd}-again"));
        words[k + 1] = again.display().to_string();
        springlab(&words[1..], tmp.path());
        let b: Value = serde_json::from_str(&read(&again.join(doc))).unwrap();
        same(&a, &b, cmd);
    }
}
