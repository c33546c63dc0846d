//! The reference store between commands: a later command reads what an earlier one solved, to
//! the same bits; `--no-cache` neither reads nor writes it; an entry cut short, two commands at
//! once and a command killed mid-write never put a wrong or half entry in anyone's way.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// A scene whose reference is DOP853 with a predictability horizon (so it has an ensemble too).
const SCENE: &str = "scenarios/hanging_chain.toml";

/// `springlab compare SCENE` into `out` with the store in `store` (None: `--no-cache`).
fn compare(store: &Path, out: &Path, no_cache: bool) -> Command {
    let mut c = crate::support::bin();
    c.env_remove("SPRINGLAB_NO_CACHE")
        .env("SPRINGLAB_CACHE_DIR", store)
        .args([
            "compare",
            SCENE,
            "--methods",
            "symplectic_euler,rk4",
            "--out",
        ])
        .arg(out);
    if no_cache {
        c.arg("--no-cache");
    }
    c
}

fn run(mut c: Command) {
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The documents of a compare folder that must not depend on the store: the table, and the
/// summary with its own folder's name taken out of the recorded command.
fn documents(out: &Path) -> (String, String) {
    let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    let summary = std::fs::read_to_string(out.join("summary.json"))
        .unwrap()
        .replace(&out.display().to_string(), "OUT");
    (csv, summary)
}

/// The store's entries (name and length), temporary files left out.
fn entries(store: &Path) -> Vec<(PathBuf, u64)> {
    let mut v: Vec<(PathBuf, u64)> = std::fs::read_dir(store)
        .map(|d| {
            d.flatten()
                .filter(|e| e.file_name().to_string_lossy().ends_with(".bin"))
                .map(|e| (e.path(), e.metadata().unwrap().len()))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn age(path: &Path, when: SystemTime) {
    std::fs::File::options()
        .append(true)
        .open(path)
        .unwrap()
        .set_modified(when)
        .unwrap();
}

// Oracle: the documents of a command that solved its reference afresh (`--no-cache`, an empty
// store). A command reading the store must write exactly them, and must have read it (the
// entries it used are marked used: their modification time moves past one set far back).
#[test]
fn a_later_command_reads_the_stored_reference_to_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let (store, unused) = (dir.path().join("store"), dir.path().join("unused"));
    run(compare(&unused, &dir.path().join("fresh"), true));
    assert!(entries(&unused).is_empty(), "--no-cache wrote the store");
    let fresh = documents(&dir.path().join("fresh"));

    run(compare(&store, &dir.path().join("first"), false));
    let stored = entries(&store);
    let names: Vec<String> = stored
        .iter()
        .map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().any(|n| n.starts_with("reference-"))
            && names.iter().any(|n| n.starts_with("ensemble-")),
        "{names:?}"
    );
    assert_eq!(documents(&dir.path().join("first")), fresh);

    let long_ago = UNIX_EPOCH + Duration::from_secs(1_000_000);
    for (p, _) in &stored {
        age(p, long_ago);
    }
    run(compare(&store, &dir.path().join("second"), false));
    assert_eq!(documents(&dir.path().join("second")), fresh);
    for (p, _) in &stored {
        let m = std::fs::metadata(p).unwrap().modified().unwrap();
        assert!(m > long_ago, "{} was not read", p.display());
    }
    // The twin: --no-cache leaves the store as it was (nothing read, nothing written).
    for (p, _) in &stored {
        age(p, long_ago);
    }
    run(compare(&store, &dir.path().join("third"), true));
    assert_eq!(documents(&dir.path().join("third")), fresh);
    assert_eq!(entries(&store), stored);
    for (p, _) in &stored {
        assert_eq!(std::fs::metadata(p).unwrap().modified().unwrap(), long_ago);
    }
}

// Oracle: the documents of a command on an empty store. An entry cut to half its length (as
// a disk could leave a copied store) is not read: the command solves again, writes the same
// documents and puts the whole entry back.
#[test]
fn a_cut_entry_is_solved_again_and_rewritten_whole() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("store");
    run(compare(&store, &dir.path().join("first"), false));
    let whole = entries(&store);
    let fresh = documents(&dir.path().join("first"));
    for (p, len) in &whole {
        let bytes = std::fs::read(p).unwrap();
        std::fs::write(p, &bytes[..(*len / 2) as usize]).unwrap();
    }
    run(compare(&store, &dir.path().join("second"), false));
    assert_eq!(documents(&dir.path().join("second")), fresh);
    assert_eq!(entries(&store), whole);
}

// Oracle: the documents of one command alone. Two commands started together on one empty
// store, and commands killed with SIGKILL at spread moments of their work, never leave an
// entry a later command reads wrongly: every later command writes the same documents, and
// every entry left is whole (the same length as the one a clean run writes).
#[test]
fn commands_at_once_and_killed_commands_leave_only_whole_entries() {
    let dir = tempfile::tempdir().unwrap();
    let clean = dir.path().join("clean");
    run(compare(&clean, &dir.path().join("alone"), false));
    let fresh = documents(&dir.path().join("alone"));
    let whole = entries(&clean);
    let lengths: Vec<u64> = whole.iter().map(|e| e.1).collect();

    let store = dir.path().join("shared");
    let kids: Vec<_> = (0..2)
        .map(|k| {
            compare(&store, &dir.path().join(format!("both{k}")), false)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    for mut k in kids {
        assert!(k.wait().unwrap().success());
    }
    for k in 0..2 {
        assert_eq!(documents(&dir.path().join(format!("both{k}"))), fresh);
    }
    assert_eq!(
        entries(&store).iter().map(|e| e.1).collect::<Vec<_>>(),
        lengths
    );

    for (i, ms) in [0u64, 20, 60, 120].iter().enumerate() {
        let store = dir.path().join(format!("killed{i}"));
        let mut kid = compare(&store, &dir.path().join(format!("k{i}")), false)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(*ms));
        let _ = kid.kill();
        let _ = kid.wait();
        for (_, len) in entries(&store) {
            assert!(lengths.contains(&len), "an entry of {len} bytes");
        }
        let after = dir.path().join(format!("after{i}"));
        run(compare(&store, &after, false));
        assert_eq!(documents(&after), fresh);
        assert_eq!(
            entries(&store).iter().map(|e| e.1).collect::<Vec<_>>(),
            lengths
        );
    }
}
