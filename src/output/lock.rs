//! One writer per output folder: an advisory lock (`flock`) on the folder, taken before any
//! file of it is written and held until the last file is renamed into place.
//!
//! On Unix the lock is taken on the folder itself (an open handle on the directory), so it
//! leaves no file behind; elsewhere it is taken on a hidden `.springlab.lock` file in the
//! folder, which stays and is simply locked again by the next command. Either way the operating
//! system releases the lock when the holding process ends, however it ends, so a killed
//! command never leaves a stale lock.
//!
//! Whoever takes a folder's lock alone first finishes or undoes what a killed command left in
//! it ([`super::recover`]), so no hidden staging folder or temporary file outlives the next
//! start. A shared holder recovers only when no one else holds the folder; shared holders
//! started at the same instant wait out each other's brief recovery ([`SHARED_WAIT`]) instead
//! of reading it as a conflicting writer.
//!
//! A writer also holds a shared lock on every folder above its own (on Unix), so a writer of a
//! folder and a writer of a folder inside it exclude each other: `report --out OUT` is refused
//! while `compare --out OUT/scene/compare` runs, and the other way round. (Shards of one report
//! share their folder, so a shard does not exclude a writer inside it.)

use crate::error::{Error, Result};
use std::fs::File;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How long a shared holder retries while the folder is held alone: long enough for a peer
/// started at the same instant to recover the folder and share it, short enough that a
/// whole-folder writer is still refused promptly.
pub const SHARED_WAIT: Duration = Duration::from_secs(5);

/// The lock on an output folder; dropping it releases the folder.
#[derive(Debug)]
pub struct DirLock {
    dir: PathBuf,
    _handle: Option<File>,
    /// Shared locks on the folders above it.
    _above: Vec<File>,
}

impl DirLock {
    /// The locked folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

/// Creates `dir` if missing and takes its lock for this process alone. Fails at once with
/// [`Error::Busy`], naming the folder, when another command (or another lock of this process)
/// holds it. Where the file system offers no locks at all, warns and goes on unguarded.
pub fn lock_dir(dir: impl AsRef<Path>) -> Result<DirLock> {
    lock(dir.as_ref(), false)
}

/// Like [`lock_dir`], but a shared lock: any number of shared holders may write disjoint files
/// of the folder side by side (shards of one job), while an exclusive holder excludes them all.
pub fn lock_dir_shared(dir: impl AsRef<Path>) -> Result<DirLock> {
    lock(dir.as_ref(), true)
}

fn lock(dir: &Path, shared: bool) -> Result<DirLock> {
    let werr = |source| Error::Write {
        file: dir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(werr)?;
    let above = lock_above(dir)?;
    let handle = open_handle(dir).map_err(werr)?;
    let start = Instant::now();
    let got = loop {
        let got = match fs4::FileExt::try_lock(&handle) {
            Ok(()) => {
                say_recovered(dir, &super::recover(dir)?);
                // flock converts the held lock in place.
                if shared {
                    fs4::FileExt::try_lock_shared(&handle)
                } else {
                    Ok(())
                }
            }
            Err(fs4::TryLockError::WouldBlock) if shared => fs4::FileExt::try_lock_shared(&handle),
            Err(e) => Err(e),
        };
        // Held alone: by a peer shard recovering the folder (for milliseconds), or by a
        // whole-folder writer (for its run): wait out the first, refuse the second.
        match got {
            Err(fs4::TryLockError::WouldBlock) if shared && start.elapsed() < SHARED_WAIT => {
                std::thread::sleep(Duration::from_millis(2));
            }
            got => break got,
        }
    };
    match got {
        Ok(()) => Ok(DirLock {
            dir: dir.to_path_buf(),
            _handle: Some(handle),
            _above: above,
        }),
        Err(fs4::TryLockError::WouldBlock) => Err(Error::Busy {
            dir: dir.to_path_buf(),
        }),
        Err(fs4::TryLockError::Error(e)) => {
            eprintln!(
                "warning: {}: cannot lock the output folder ({e}); writing without the one-writer guard",
                dir.display()
            );
            Ok(DirLock {
                dir: dir.to_path_buf(),
                _handle: None,
                _above: above,
            })
        }
    }
}

/// Shared locks on every folder above `dir` (Unix; elsewhere none, as a lock there would
/// leave a file in each): refused with [`Error::BusyAbove`] when a command writes one of them.
/// A folder that cannot be opened (no permission) is passed over: no writer can hold it.
#[cfg(unix)]
fn lock_above(dir: &Path) -> Result<Vec<File>> {
    let Ok(full) = dir.canonicalize() else {
        return Ok(Vec::new());
    };
    let mut held = Vec::new();
    for up in full.ancestors().skip(1) {
        let Ok(h) = File::open(up) else { continue };
        match fs4::FileExt::try_lock_shared(&h) {
            Ok(()) => held.push(h),
            Err(fs4::TryLockError::WouldBlock) => {
                return Err(Error::BusyAbove {
                    dir: dir.to_path_buf(),
                    above: up.to_path_buf(),
                })
            }
            // A file system without locks: nothing to exclude there.
            Err(fs4::TryLockError::Error(_)) => {}
        }
    }
    Ok(held)
}

#[cfg(not(unix))]
fn lock_above(_dir: &Path) -> Result<Vec<File>> {
    Ok(Vec::new())
}

/// One line on stderr when recovery changed the folder, so the user knows why files moved.
fn say_recovered(dir: &Path, rec: &super::Recovery) {
    if !rec.is_empty() {
        eprintln!(
            "note: {}: finished {} interrupted commit(s), put back {} earlier output(s) and removed {} leftover(s) of a command that was killed",
            dir.display(),
            rec.finished,
            rec.restored.len(),
            rec.removed.len()
        );
    }
}

#[cfg(unix)]
fn open_handle(dir: &Path) -> std::io::Result<File> {
    File::open(dir)
}

#[cfg(not(unix))]
fn open_handle(dir: &Path) -> std::io::Result<File> {
    std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(dir.join(".springlab.lock"))
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the definition of one writer per folder. While a lock is held a second lock of
    // the same folder is refused with Busy naming the folder; a different folder locks freely;
    // once the first lock is dropped the folder locks again.
    #[test]
    fn a_held_folder_refuses_a_second_writer_until_released() {
        let tmp = tempfile::tempdir().unwrap();
        let a = tmp.path().join("a");
        let first = lock_dir(&a).unwrap();
        match lock_dir(&a) {
            Err(Error::Busy { dir }) => assert_eq!(dir, a),
            other => panic!("expected Busy, got {other:?}"),
        }
        let msg = lock_dir(&a).unwrap_err().to_string();
        assert!(msg.contains(&a.display().to_string()) && msg.contains("another springlab"));
        lock_dir(tmp.path().join("b")).expect("another folder is free");
        drop(first);
        lock_dir(&a).expect("released on drop");
    }

    // Oracle: shared locks coexist with each other and exclude an exclusive one, which in turn
    // excludes them (the flock semantics the shards of one report rely on).
    #[test]
    fn shared_locks_coexist_and_exclude_an_exclusive_one() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        let s1 = lock_dir_shared(d).unwrap();
        let _s2 = lock_dir_shared(d).expect("two shared holders");
        assert!(matches!(lock_dir(d), Err(Error::Busy { .. })));
        drop(s1);
        drop(_s2);
        let _x = lock_dir(d).unwrap();
        assert!(matches!(lock_dir_shared(d), Err(Error::Busy { .. })));
    }

    // Oracle: the rule that a writer of a folder and a writer of a folder inside it exclude
    // each other, both ways; the twin: sibling folders lock side by side.
    #[cfg(unix)]
    #[test]
    fn a_folder_and_a_folder_inside_it_exclude_each_other() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        let inner = out.join("scene").join("compare");
        let held = lock_dir(&inner).unwrap();
        match lock_dir(&out) {
            Err(Error::Busy { dir }) => assert_eq!(dir, out),
            other => panic!("the parent's writer was not refused: {other:?}"),
        }
        drop(held);
        let parent = lock_dir(&out).unwrap();
        match lock_dir(&inner) {
            Err(e @ Error::BusyAbove { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains("out/scene/compare") && msg.contains("writing"),
                    "{msg}"
                );
            }
            other => panic!("the nested writer was not refused: {other:?}"),
        }
        drop(parent);
        let _a = lock_dir(out.join("a")).unwrap();
        let _b = lock_dir(out.join("b")).expect("siblings are independent");
    }

    // Oracle: the sharing rule of shards: a folder held alone for a moment (a peer shard
    // recovering it before it shares) is shared once that moment ends; the twin: a folder
    // held alone past the wait (a whole-folder writer) refuses a shared holder. And shared
    // holders started at the same instant all get the folder.
    #[test]
    fn a_shared_holder_waits_out_a_brief_exclusive_hold() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path().join("out");
        let peer = lock_dir(&d).unwrap();
        let t = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(100));
            drop(peer);
        });
        lock_dir_shared(&d).expect("shared once the peer's brief hold ends");
        t.join().unwrap();
        let tmp = tempfile::tempdir().unwrap();
        let _alone = lock_dir(tmp.path()).unwrap();
        let t0 = Instant::now();
        assert!(matches!(
            lock_dir_shared(tmp.path()),
            Err(Error::Busy { .. })
        ));
        assert!(t0.elapsed() >= SHARED_WAIT);
        for _ in 0..20 {
            let tmp = tempfile::tempdir().unwrap();
            let d = tmp.path().join("out");
            let barrier = std::sync::Barrier::new(4);
            let got: Vec<bool> = std::thread::scope(|s| {
                let hs: Vec<_> = (0..4)
                    .map(|_| {
                        s.spawn(|| {
                            barrier.wait();
                            let l = lock_dir_shared(&d);
                            barrier.wait();
                            l.is_ok()
                        })
                    })
                    .collect();
                hs.into_iter().map(|h| h.join().unwrap()).collect()
            });
            assert!(got.iter().all(|&g| g), "{got:?}");
        }
    }

    // Oracle: the lock leaves nothing in the folder on Unix (it is taken on the folder itself).
    #[cfg(unix)]
    #[test]
    fn the_lock_leaves_no_file_behind() {
        let tmp = tempfile::tempdir().unwrap();
        drop(lock_dir(tmp.path()).unwrap());
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
    }
}
