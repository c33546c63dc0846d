//! Outputs replaced together or not at all: files and folders are written whole under hidden
//! staging names beside their targets, then swapped in behind a journal, so a command killed at
//! any moment leaves every target complete (old or new) and the next command that locks the
//! folder ([`recover`]) finishes or undoes what the killed one left.
//!
//! The protocol, for targets `a`, `b`, … in one parent folder and a transaction id `ID`:
//! 1. stage: write `.a.new-ID`, `.b.new-ID`, … (files synced as they are written);
//! 2. journal: write `.springlab-commit-ID` atomically, listing `a`, `b`, …;
//! 3. swap, per target: rename `a` to `.a.old-ID` (when there is one), `.a.new-ID` to `a`;
//! 4. clean: remove the `.old-ID` entries, then the journal.
//!
//! Recovery rolls a journaled transaction forward (step 3 for every target whose staged entry
//! still exists, then step 4) and rolls anything else back: staged entries and temporary files
//! are removed, and an `.a.old-ID` whose `a` is missing is put back.

use super::atomic::write_atomic;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

const JOURNAL_PREFIX: &str = ".springlab-commit-";

/// Suffixes of the hidden names this module and [`super::AtomicFile`] use beside a target.
const STAGED: &str = ".new-";
const OLD: &str = ".old-";
const TMP: &str = ".tmp-";

/// A set of outputs in one folder that replace their earlier versions together.
/// Dropping it uncommitted removes what it staged and leaves every target as it was.
#[derive(Debug)]
pub struct Transaction {
    parent: PathBuf,
    id: String,
    names: Vec<String>,
    committed: bool,
}

fn werr(file: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |source| Error::Write {
        file: file.to_path_buf(),
        source,
    }
}

fn staged_name(name: &str, id: &str) -> String {
    format!(".{name}{STAGED}{id}")
}

fn old_name(name: &str, id: &str) -> String {
    format!(".{name}{OLD}{id}")
}

fn remove_any(p: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(p),
        Ok(_) => std::fs::remove_file(p),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// Makes the folder's entries (renames, new names) durable; best effort where a folder cannot
/// be opened for syncing.
fn sync_dir(dir: &Path) {
    if let Ok(f) = std::fs::File::open(dir) {
        let _ = f.sync_all();
    }
}

impl Transaction {
    /// Starts a transaction over targets in `parent` (created if missing).
    pub fn new(parent: impl AsRef<Path>) -> Result<Self> {
        static SEQ: AtomicU64 = AtomicU64::new(0);
        let parent = parent.as_ref().to_path_buf();
        std::fs::create_dir_all(&parent).map_err(werr(&parent))?;
        let id = format!(
            "{}-{}",
            std::process::id(),
            SEQ.fetch_add(1, Ordering::Relaxed)
        );
        Ok(Transaction {
            parent,
            id,
            names: Vec::new(),
            committed: false,
        })
    }

    fn add(&mut self, name: &str) -> Result<PathBuf> {
        if name.is_empty() || name.contains(['/', '\\']) || self.names.iter().any(|n| n == name) {
            return Err(Error::Write {
                file: self.parent.join(name),
                source: std::io::Error::other("not a single new name in the folder"),
            });
        }
        let staged = self.parent.join(staged_name(name, &self.id));
        remove_any(&staged).map_err(werr(&staged))?;
        super::interrupt::track(&staged);
        self.names.push(name.to_string());
        Ok(staged)
    }

    /// Stages the folder `parent/name`: returns the (empty, hidden) folder to write it into.
    /// On commit it replaces the earlier folder whole, so no file of an earlier version stays.
    pub fn stage_dir(&mut self, name: &str) -> Result<PathBuf> {
        let staged = self.add(name)?;
        std::fs::create_dir_all(&staged).map_err(werr(&staged))?;
        Ok(staged)
    }

    /// Stages the file `parent/name` with `bytes` (written and synced now).
    pub fn stage_file(&mut self, name: &str, bytes: &[u8]) -> Result<()> {
        let staged = self.add(name)?;
        write_atomic(&staged, bytes)?;
        Ok(())
    }

    /// Swaps every staged entry into place, behind the journal (see the module doc).
    pub fn commit(mut self) -> Result<()> {
        let journal = self.parent.join(format!("{JOURNAL_PREFIX}{}", self.id));
        let mut list = self.names.join("\n");
        list.push('\n');
        write_atomic(&journal, list.as_bytes())?;
        sync_dir(&self.parent);
        self.committed = true;
        // From the journal on, the transaction is finished, here or by the next command in
        // the folder: an interruption waits for the renames and leaves the staged names be.
        super::interrupt::publishing(|| {
            for n in &self.names {
                super::interrupt::untrack(&self.parent.join(staged_name(n, &self.id)));
            }
            roll_forward(&self.parent, &self.id, &self.names)?;
            remove_any(&journal).map_err(werr(&journal))
        })?;
        Ok(())
    }
}

impl Drop for Transaction {
    fn drop(&mut self) {
        if !self.committed {
            for n in &self.names {
                let staged = self.parent.join(staged_name(n, &self.id));
                let _ = remove_any(&staged);
                super::interrupt::untrack(&staged);
            }
        }
    }
}

/// Steps 3 and 4 of the protocol for one journaled transaction.
fn roll_forward(parent: &Path, id: &str, names: &[String]) -> Result<()> {
    for n in names {
        let staged = parent.join(staged_name(n, id));
        let target = parent.join(n);
        let old = parent.join(old_name(n, id));
        if std::fs::symlink_metadata(&staged).is_err() {
            continue;
        }
        if std::fs::symlink_metadata(&target).is_ok() {
            remove_any(&old).map_err(werr(&old))?;
            std::fs::rename(&target, &old).map_err(werr(&target))?;
        }
        std::fs::rename(&staged, &target).map_err(werr(&target))?;
    }
    sync_dir(parent);
    for n in names {
        let old = parent.join(old_name(n, id));
        remove_any(&old).map_err(werr(&old))?;
    }
    Ok(())
}

/// The path `p` will have once the transactions staging it commit: every component that is a
/// staged name (`.NAME.new-ID`) reads as its target `NAME`. Documents record the command that
/// re-creates them with this path, not the hidden one they were written under.
pub fn published_path(p: &Path) -> PathBuf {
    p.components()
        .map(|c| match c {
            std::path::Component::Normal(n) => match n.to_str().and_then(parse_hidden) {
                Some((target, STAGED)) => std::ffi::OsString::from(target),
                _ => n.to_os_string(),
            },
            other => other.as_os_str().to_os_string(),
        })
        .collect()
}

/// What [`recover`] did to a folder.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct Recovery {
    /// Interrupted commits finished (journals rolled forward).
    pub finished: usize,
    /// Earlier versions put back because an interrupted swap had moved them aside.
    pub restored: Vec<PathBuf>,
    /// Staged outputs, earlier versions and temporary files removed.
    pub removed: Vec<PathBuf>,
}

impl Recovery {
    /// True when the folder held nothing to recover.
    pub fn is_empty(&self) -> bool {
        self.finished == 0 && self.restored.is_empty() && self.removed.is_empty()
    }
}

/// The hidden name's target and kind, when `file` is one of ours (`.NAME.new-ID`,
/// `.NAME.old-ID` or `.NAME.tmp-ID`, where ID is digits and dashes).
fn parse_hidden(file: &str) -> Option<(&str, &'static str)> {
    let rest = file.strip_prefix('.')?;
    [STAGED, OLD, TMP].into_iter().find_map(|kind| {
        let at = rest.rfind(kind)?;
        let id = &rest[at + kind.len()..];
        let ok = !id.is_empty() && id.bytes().all(|b| b.is_ascii_digit() || b == b'-');
        (ok && at > 0).then_some((&rest[..at], kind))
    })
}

/// How deep [`recover`] looks below the locked folder: a report's scene folders and their
/// document folders.
const RECOVER_DEPTH: usize = 2;

/// Finishes or undoes what killed commands left in `dir` (see the module doc). Call it only
/// while holding the folder's exclusive lock, so no live writer's entries are touched.
pub fn recover(dir: &Path) -> Result<Recovery> {
    let mut rec = Recovery::default();
    recover_in(dir, RECOVER_DEPTH, &mut rec)?;
    Ok(rec)
}

fn entries(dir: &Path) -> Vec<(String, PathBuf, bool)> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<_> = rd
        .filter_map(|e| {
            let e = e.ok()?;
            let name = e.file_name().to_str()?.to_string();
            let is_dir = e.file_type().ok()?.is_dir();
            Some((name, e.path(), is_dir))
        })
        .collect();
    v.sort();
    v
}

fn recover_in(dir: &Path, depth: usize, rec: &mut Recovery) -> Result<()> {
    for (name, path, _) in entries(dir) {
        if let Some(id) = name.strip_prefix(JOURNAL_PREFIX) {
            if name.contains(TMP) {
                continue;
            }
            let text = std::fs::read_to_string(&path).map_err(|source| Error::Read {
                file: path.clone(),
                source,
            })?;
            let names: Vec<String> = text.lines().map(str::to_string).collect();
            roll_forward(dir, id, &names)?;
            remove_any(&path).map_err(werr(&path))?;
            rec.finished += 1;
        }
    }
    for (name, path, is_dir) in entries(dir) {
        match parse_hidden(&name) {
            Some((target, OLD)) => {
                let t = dir.join(target);
                if std::fs::symlink_metadata(&t).is_ok() {
                    remove_any(&path).map_err(werr(&path))?;
                    rec.removed.push(path);
                } else {
                    std::fs::rename(&path, &t).map_err(werr(&t))?;
                    rec.restored.push(t);
                }
            }
            Some(_) => {
                remove_any(&path).map_err(werr(&path))?;
                rec.removed.push(path);
            }
            None if is_dir && depth > 0 && !name.starts_with('.') => {
                recover_in(&path, depth - 1, rec)?;
            }
            None => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(p: &Path) -> String {
        std::fs::read_to_string(p).unwrap()
    }

    fn hidden(dir: &Path) -> Vec<String> {
        entries(dir)
            .into_iter()
            .map(|e| e.0)
            .filter(|n| n.starts_with('.'))
            .collect()
    }

    // Oracle: the definition of a whole rewrite. The committed folder holds exactly the files
    // written into it; an abandoned transaction leaves the earlier folder and file as they were
    // and no hidden entry behind.
    #[test]
    fn commit_replaces_whole_and_drop_keeps_the_old() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::create_dir_all(d.join("scene/sweep")).unwrap();
        std::fs::write(d.join("scene/sweep/old.csv"), "old").unwrap();
        std::fs::write(d.join("index.html"), "old").unwrap();
        {
            let mut t = Transaction::new(d).unwrap();
            let s = t.stage_dir("scene").unwrap();
            std::fs::write(s.join("page"), "abandoned").unwrap();
            t.stage_file("index.html", b"abandoned").unwrap();
        }
        assert_eq!(read(&d.join("index.html")), "old");
        assert!(d.join("scene/sweep/old.csv").exists());
        assert!(hidden(d).is_empty(), "{:?}", hidden(d));
        let mut t = Transaction::new(d).unwrap();
        let s = t.stage_dir("scene").unwrap();
        write_atomic(s.join("page"), b"new").unwrap();
        t.stage_file("index.html", b"new").unwrap();
        t.commit().unwrap();
        assert_eq!(read(&d.join("index.html")), "new");
        assert_eq!(read(&d.join("scene/page")), "new");
        assert!(!d.join("scene/sweep").exists());
        assert!(hidden(d).is_empty(), "{:?}", hidden(d));
    }

    // Oracle: the protocol of the module doc, interrupted after each of its steps by hand. A
    // kill before the journal leaves the old versions (recovery removes the staging); a kill
    // after it leaves a state recovery completes to the new versions. Either way every target
    // ends whole and no hidden entry remains.
    #[test]
    fn recovery_completes_or_undoes_every_interrupted_step() {
        for step in 0..=4 {
            let tmp = tempfile::tempdir().unwrap();
            let d = tmp.path();
            std::fs::create_dir_all(d.join("a")).unwrap();
            std::fs::write(d.join("a/f"), "old").unwrap();
            std::fs::write(d.join("b"), "old").unwrap();
            let id = "77-0";
            let names = ["a".to_string(), "b".to_string()];
            // Step 1: staged.
            std::fs::create_dir_all(d.join(staged_name("a", id))).unwrap();
            std::fs::write(d.join(staged_name("a", id)).join("f"), "new").unwrap();
            std::fs::write(d.join(staged_name("b", id)), "new").unwrap();
            std::fs::write(d.join(".b.tmp-77"), "half").unwrap();
            if step >= 2 {
                std::fs::write(d.join(format!("{JOURNAL_PREFIX}{id}")), "a\nb\n").unwrap();
            }
            if step >= 3 {
                // Half of step 3: `a` moved aside, not yet replaced.
                std::fs::rename(d.join("a"), d.join(old_name("a", id))).unwrap();
            }
            if step >= 4 {
                std::fs::rename(d.join(staged_name("a", id)), d.join("a")).unwrap();
                std::fs::rename(d.join("b"), d.join(old_name("b", id))).unwrap();
                std::fs::rename(d.join(staged_name("b", id)), d.join("b")).unwrap();
            }
            let rec = recover(d).unwrap();
            assert!(!rec.is_empty());
            let want = if step >= 2 { "new" } else { "old" };
            assert_eq!(read(&d.join("a/f")), want, "step {step}");
            assert_eq!(read(&d.join("b")), want, "step {step}");
            assert!(hidden(d).is_empty(), "step {step}: {:?}", hidden(d));
            assert!(recover(d).unwrap().is_empty(), "recovery is idempotent");
            let _ = names;
        }
    }

    // Oracle: the staging names of this module, read back by hand.
    #[test]
    fn published_path_names_the_target() {
        let p = Path::new("reports/.cloth.new-12-3/compare");
        assert_eq!(published_path(p), Path::new("reports/cloth/compare"));
        let q = Path::new("/abs/.x.old-1/y");
        assert_eq!(published_path(q), q);
    }

    // Oracle: an earlier version moved aside with no journal (a swap of an older writer) is
    // put back when its target is missing, and removed when the target is there; names that
    // merely look similar are left alone.
    #[test]
    fn recovery_restores_orphans_and_leaves_other_names() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::create_dir_all(d.join(".scene.old-12")).unwrap();
        std::fs::write(d.join(".scene.old-12/index.html"), "old").unwrap();
        std::fs::create_dir_all(d.join("kept")).unwrap();
        std::fs::create_dir_all(d.join(".kept.old-13")).unwrap();
        std::fs::create_dir_all(d.join("other/compare")).unwrap();
        std::fs::write(d.join("other/compare/.compare.csv.tmp-99"), "half").unwrap();
        std::fs::write(d.join(".notes.tmp-x"), "mine").unwrap();
        std::fs::write(d.join("a.old-1"), "mine").unwrap();
        let rec = recover(d).unwrap();
        assert_eq!(rec.restored, vec![d.join("scene")]);
        assert_eq!(read(&d.join("scene/index.html")), "old");
        assert!(!d.join(".kept.old-13").exists());
        assert!(!d.join("other/compare/.compare.csv.tmp-99").exists());
        assert!(d.join(".notes.tmp-x").exists() && d.join("a.old-1").exists());
    }
}
