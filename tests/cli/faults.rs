//! Faults injected into the binary: a report killed (SIGKILL) at many moments, one of them
//! while a scene folder is being written; a report onto a disk too small for it; the extreme
//! numbers a fuzzer tries, through `run`. Each asserts that nothing was lost or mixed and that
//! no document holds a non-finite number.
//!
//! Oracles: the report's own records. A scene folder is complete when its `results.json`
//! parses and every document it lists exists and parses (JSON) or holds only finite numbers
//! (CSV); the overview is whole when `summary.json` lists every scene of the previous report.
//! "Nothing left behind" is the absence of hidden entries (`.NAME.new-ID`, `.NAME.old-ID`,
//! `.NAME.tmp-ID`, journals) after the next command has started on the folder.

use crate::support::{bin, ok};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Two cheap shipped scenes, so a quick report takes seconds.
const SCENES: [&str; 2] = ["anchored_spring.toml", "two_body.toml"];

fn scenarios(dir: &Path) -> PathBuf {
    let s = dir.join("scenarios");
    std::fs::create_dir_all(&s).unwrap();
    for f in SCENES {
        std::fs::copy(Path::new("scenarios").join(f), s.join(f)).unwrap();
    }
    s
}

/// A report that studies and writes every scene again (`--no-cache`: an unchanged scene's
/// folder would otherwise be kept, and nothing written to be cut short).
fn report(scen: &Path, out: &Path) -> Command {
    let mut c = bin();
    c.args(["report", "--quick", "--no-cache", "--scenarios"])
        .arg(scen)
        .arg("--out")
        .arg(out);
    c
}

fn scene_names() -> Vec<String> {
    SCENES
        .iter()
        .map(|f| f.trim_end_matches(".toml").into())
        .collect()
}

/// Every CSV field that reads as a number is finite.
fn csv_finite(p: &Path) {
    let text = std::fs::read_to_string(p).unwrap();
    for (n, line) in text.lines().enumerate() {
        for cell in line.split(',') {
            let c = cell.trim().to_ascii_lowercase();
            assert!(
                !matches!(
                    c.as_str(),
                    "nan" | "inf" | "-inf" | "+inf" | "infinity" | "-infinity"
                ),
                "{}:{}: non-finite cell {cell:?}",
                p.display(),
                n + 1
            );
        }
    }
}

fn json(p: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The scene folder is whole: its results, page and every listed document.
fn complete(dir: &Path) {
    let res = json(&dir.join("results.json"));
    assert!(dir.join("index.html").is_file(), "{}", dir.display());
    let docs = res["documents"].as_array().unwrap();
    assert!(!docs.is_empty());
    for d in docs {
        let f = dir.join(d["file"].as_str().unwrap());
        match f.extension().and_then(|x| x.to_str()) {
            Some("json") => drop(json(&f)),
            Some("csv") => csv_finite(&f),
            _ => assert!(f.is_file(), "{}", f.display()),
        }
    }
}

/// Hidden entries anywhere below `dir`.
fn hidden(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if e.file_name().to_string_lossy().starts_with('.') {
            out.push(p);
        } else if p.is_dir() {
            out.extend(hidden(&p));
        }
    }
    out
}

/// The state a kill may leave: each scene whole, either in place or (mid-swap) moved aside
/// under its `.NAME.old-ID`, which the next start puts back.
fn recoverable(out: &Path, names: &[String]) {
    for n in names {
        let dir = out.join(n);
        if dir.is_dir() {
            complete(&dir);
            continue;
        }
        let aside: Vec<_> = std::fs::read_dir(out)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                p.file_name()
                    .is_some_and(|f| f.to_string_lossy().starts_with(&format!(".{n}.old-")))
            })
            .collect();
        assert_eq!(aside.len(), 1, "{n}: neither in place nor aside");
        complete(&aside[0]);
    }
}

/// After a later start: every scene whole in place, the overview lists them all, nothing
/// hidden remains.
fn whole(out: &Path, names: &[String]) {
    for n in names {
        complete(&out.join(n));
    }
    let sum = json(&out.join("summary.json"));
    let listed: Vec<_> = sum["scenes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["scene"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(listed, names);
    for f in ["index.html", "README.md"] {
        let t = std::fs::read_to_string(out.join(f)).unwrap();
        assert!(names.iter().all(|n| t.contains(n.as_str())), "{f}");
    }
    assert!(hidden(out).is_empty(), "{:?}", hidden(out));
}

/// A later start on the folder: `report --merge` takes the folder's lock (and so recovers it)
/// before it finds that there are no shards to merge.
fn later_start(out: &Path) {
    let o = bin()
        .args(["report", "--merge", "--out"])
        .arg(out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("no shard records"),
        "{err}"
    );
}

fn kill(mut c: Child) {
    c.kill().unwrap();
    c.wait().unwrap();
}

/// Starts a report and kills it as soon as `seen` holds for the folder (polled every
/// millisecond), or after `limit`; true when `seen` triggered the kill.
fn kill_when(scen: &Path, out: &Path, limit: Duration, seen: impl Fn(&Path) -> bool) -> bool {
    let c = report(scen, out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while t0.elapsed() < limit {
        if seen(out) {
            kill(c);
            return true;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    kill(c);
    false
}

fn staging(out: &Path) -> bool {
    std::fs::read_dir(out).is_ok_and(|rd| {
        rd.flatten().any(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with('.') && n.contains(".new-") && e.path().is_dir()
        })
    })
}

#[test]
fn a_report_killed_at_any_moment_loses_no_scene() {
    let tmp = tempfile::tempdir().unwrap();
    let scen = scenarios(tmp.path());
    let out = tmp.path().join("reports");
    let names = scene_names();
    let t0 = Instant::now();
    let st = report(&scen, &out).output().unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let full = t0.elapsed();
    whole(&out, &names);
    // While a scene folder is being written (its staging folder exists).
    let mut caught = 0;
    for _ in 0..5 {
        if kill_when(&scen, &out, full * 3, staging) {
            caught += 1;
            recoverable(&out, &names);
            later_start(&out);
            whole(&out, &names);
        }
    }
    assert!(caught > 0, "no kill landed while a scene was being written");
    // At moments spread over a whole report.
    for k in 1..=8 {
        let at = full.mul_f64(k as f64 / 8.0);
        kill_when(&scen, &out, at, |_| false);
        recoverable(&out, &names);
    }
    later_start(&out);
    whole(&out, &names);
    // A report finishes normally on the recovered folder.
    ok(&[
        "report",
        "--quick",
        "--scenarios",
        scen.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    whole(&out, &names);
}

/// Copies a folder tree.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let t = to.join(e.file_name());
        if e.path().is_dir() {
            copy_tree(&e.path(), &t);
        } else {
            std::fs::copy(e.path(), t).unwrap();
        }
    }
}

fn tree_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| {
            if e.path().is_dir() {
                tree_bytes(&e.path())
            } else {
                e.metadata().unwrap().len()
            }
        })
        .sum()
}

/// Every file's bytes below `dir`, by relative path.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.path().is_dir() {
            out.extend(
                snapshot(&e.path())
                    .into_iter()
                    .map(|(p, b)| (Path::new(&e.file_name()).join(p), b)),
            );
        } else {
            out.push((e.file_name().into(), std::fs::read(e.path()).unwrap()));
        }
    }
    out.sort();
    out
}

/// After a report that failed for want of space: every scene whole (the earlier folders,
/// untouched, for the scenes that failed), the overview still lists them all (the failed ones
/// marked), and nothing hidden is left.
fn survived_full_disk(out: &Path, before: &[(PathBuf, Vec<u8>)], names: &[String], stderr: &str) {
    assert!(!stderr.contains("panicked"), "{stderr}");
    let sum = json(&out.join("summary.json"));
    let listed: Vec<_> = sum["scenes"].as_array().unwrap().iter().collect();
    assert_eq!(listed.len(), names.len(), "the overview lost scenes");
    for s in &listed {
        let name = s["scene"].as_str().unwrap();
        complete(&out.join(name));
        if s.get("failed_this_time").is_some() {
            let prefix = Path::new(name);
            let old: Vec<_> = before
                .iter()
                .filter(|(p, _)| p.starts_with(prefix))
                .collect();
            let now: Vec<_> = snapshot(out)
                .into_iter()
                .filter(|(p, _)| p.starts_with(prefix))
                .collect();
            assert!(
                old.iter()
                    .map(|(p, b)| (p, b))
                    .eq(now.iter().map(|(p, b)| (p, b))),
                "{name}: a scene that failed must keep its earlier folder byte for byte"
            );
        }
    }
    assert!(hidden(out).is_empty(), "{:?}", hidden(out));
}

/// A tmpfs of `bytes` at `dir`, when this process may mount one.
fn tmpfs(dir: &Path, bytes: u64) -> bool {
    std::fs::create_dir_all(dir).unwrap();
    Command::new("mount")
        .args(["-t", "tmpfs", "-o", &format!("size={bytes}"), "tmpfs"])
        .arg(dir)
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

#[test]
fn a_report_onto_a_full_disk_keeps_every_earlier_scene_and_the_overview() {
    let tmp = tempfile::tempdir().unwrap();
    let scen = scenarios(tmp.path());
    let built = tmp.path().join("built");
    ok(&[
        "report",
        "--quick",
        "--scenarios",
        scen.to_str().unwrap(),
        "--out",
        built.to_str().unwrap(),
    ]);
    let names = scene_names();
    let size = tree_bytes(&built);
    // A disk with room for the report and a fifth more: a new report, which stages each scene
    // beside the earlier one, runs out of space.
    let disk = tmp.path().join("disk");
    let mounted = tmpfs(&disk, size + size / 5 + (64 << 10));
    let out = if mounted {
        disk.join("reports")
    } else {
        eprintln!("no tmpfs here (mount refused): the disk is filled by a file-size limit instead");
        tmp.path().join("reports")
    };
    copy_tree(&built, &out);
    let before = snapshot(&out);
    let mut cmd = if mounted {
        report(&scen, &out)
    } else {
        // A file-size limit (`ulimit -f`, in 512-byte blocks) far below the largest document:
        // writes beyond it fail as on a full disk (SIGXFSZ ignored, so they fail with EFBIG).
        let mut c = Command::new("sh");
        c.env("SPRINGLAB_NO_CACHE", "1")
            .arg("-c")
            .arg("trap '' XFSZ; ulimit -f 16; exec \"$0\" \"$@\"")
            .arg(env!("CARGO_BIN_EXE_springlab"))
            .args(["report", "--quick", "--no-cache", "--scenarios"])
            .arg(&scen)
            .arg("--out")
            .arg(&out);
        c
    };
    let o = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let checked = std::panic::catch_unwind(|| {
        assert!(!o.status.success(), "the report cannot have fitted: {err}");
        survived_full_disk(&out, &before, &names, &err);
    });
    if mounted {
        let _ = Command::new("umount").arg(&disk).status();
    }
    if let Err(e) = checked {
        std::panic::resume_unwind(e);
    }
}

/// The hostile numbers a fuzzer tries.
const EXTREMES: [&str; 10] = [
    "1e300",
    "-1e300",
    "1e308",
    "1.7976931348623157e308",
    "1e-300",
    "5e-324",
    "0.0",
    "-0.0",
    "1e154",
    "-1e-154",
];

/// The anchored spring with one field's value replaced.
fn anchored(field: &str, v: &str) -> String {
    let mut s = format!(
        "[world]\ngravity = [0.0, {g}, 0.0]\n[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
         [[particle]]\nposition = [{x}, 0.0, 0.0]\nvelocity = [0.0, {v0}, 0.0]\nmass = {m}\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = {k}\nrest_length = {l}\ndamping = {c}\n[run]\ndt = {dt}\nsteps = 40\n",
        g = if field == "g" { v } else { "-9.81" },
        x = if field == "x" { v } else { "1.5" },
        v0 = if field == "v" { v } else { "0.0" },
        m = if field == "m" { v } else { "1.0" },
        k = if field == "k" { v } else { "4.0" },
        l = if field == "l" { v } else { "1.0" },
        c = if field == "c" { v } else { "0.0" },
        dt = if field == "dt" { v } else { "0.01" },
    );
    s.insert_str(0, "name = \"extreme\"\n");
    s
}

#[test]
fn extreme_numbers_are_refused_or_give_finite_documents() {
    let tmp = tempfile::tempdir().unwrap();
    let mut refused = 0;
    let mut ran = 0;
    for field in ["g", "x", "v", "m", "k", "l", "c", "dt"] {
        for v in EXTREMES {
            let scene = tmp.path().join(format!("{field}{v}.toml"));
            std::fs::write(&scene, anchored(field, v)).unwrap();
            let out = tmp.path().join(format!("out-{field}{v}"));
            for method in ["symplectic_euler", "rk4", "implicit_euler"] {
                let o = bin()
                    .arg("run")
                    .arg(&scene)
                    .args(["-i", method, "--out"])
                    .arg(&out)
                    .output()
                    .unwrap();
                let err = String::from_utf8_lossy(&o.stderr);
                assert!(!err.contains("panicked"), "{field} = {v}, {method}: {err}");
                if !o.status.success() {
                    refused += 1;
                    assert!(
                        err.contains(scene.to_str().unwrap()) || err.contains("--"),
                        "{field} = {v}, {method}: the error names neither the file nor a flag: {err}"
                    );
                    continue;
                }
                ran += 1;
                for f in ["trajectory.csv", "energy.csv"] {
                    csv_finite(&out.join(f));
                }
                let s = std::fs::read_to_string(out.join("summary.json")).unwrap();
                assert!(!s.contains("NaN") && !s.contains("inf\""), "{s}");
                serde_json::from_str::<serde_json::Value>(&s).unwrap();
            }
        }
    }
    // Both outcomes occur, so neither branch's checks are vacuous.
    assert!(refused > 0 && ran > 0, "refused {refused}, ran {ran}");
}
