//! Ctrl-C (SIGINT) and SIGTERM end a command cleanly: every output not yet published (an
//! atomic file's temporary name, a transaction's staging folder) is removed, one line on stderr
//! says what was kept, and the command exits with 128 + the signal (130, 143).
//!
//! Writers register what they have in flight ([`track`], [`untrack`]) and publish under
//! [`publishing`], so the cleanup never runs in the middle of a rename: it waits for the
//! publication in progress, then removes what is still unpublished. A transaction interrupted
//! between its journal and its last rename is not undone here but finished by the next command
//! in the folder (its journal says how, see [`super::recover`]). The handler itself only writes
//! the signal's number to a pipe; a watcher thread does the rest.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// The outputs in flight and the publication guard.
struct Registry {
    /// Unpublished outputs: temporary files and staging folders, by path.
    pending: Mutex<Vec<PathBuf>>,
    /// Held while an output is published (renamed into place), and by the cleanup.
    publish: Mutex<()>,
}

/// A registry's guards held by the cleanup until the process ends.
type Held<'a> = (MutexGuard<'a, ()>, MutexGuard<'a, Vec<PathBuf>>);

impl Registry {
    const fn new() -> Self {
        Registry {
            pending: Mutex::new(Vec::new()),
            publish: Mutex::new(()),
        }
    }

    fn pending(&self) -> MutexGuard<'_, Vec<PathBuf>> {
        self.pending.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn track(&self, p: &Path) {
        self.pending().push(p.to_path_buf());
    }

    fn untrack(&self, p: &Path) {
        let mut v = self.pending();
        if let Some(i) = v.iter().rposition(|q| q == p) {
            v.swap_remove(i);
        }
    }

    fn publish_guard(&self) -> MutexGuard<'_, ()> {
        self.publish.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Removes every unpublished output (waiting out a publication in progress); returns the
    /// guards, held so that no new output starts, and how many outputs were removed.
    fn remove_pending(&self) -> (Held<'_>, usize) {
        let publish = self.publish_guard();
        let v = self.pending();
        let mut removed = 0;
        for p in v.iter() {
            let gone = match std::fs::symlink_metadata(p) {
                Ok(m) if m.is_dir() => std::fs::remove_dir_all(p).is_ok(),
                Ok(_) => std::fs::remove_file(p).is_ok(),
                Err(_) => false,
            };
            removed += usize::from(gone);
        }
        ((publish, v), removed)
    }
}

/// The process's registry.
static REGISTRY: Registry = Registry::new();

/// Registers `p` (a temporary file or staging folder about to be created) as unpublished.
pub fn track(p: &Path) {
    REGISTRY.track(p);
}

/// Forgets `p`: published, or removed by its writer.
pub fn untrack(p: &Path) {
    REGISTRY.untrack(p);
}

/// Runs `f` (a publication: renames into place) with the cleanup held off until it ends.
pub fn publishing<R>(f: impl FnOnce() -> R) -> R {
    let _g = REGISTRY.publish_guard();
    f()
}

/// The line printed when a signal ends the command.
fn farewell(name: &str, removed: usize) -> String {
    format!(
        "springlab: stopped by {name}: removed {removed} unfinished output(s); every file finished before it is kept"
    )
}

/// Installs the SIGINT and SIGTERM handlers (once, at the start of the command; a library
/// user's program keeps its own).
#[cfg(unix)]
pub fn install() {
    use std::sync::atomic::{AtomicI32, Ordering};
    static WRITE_FD: AtomicI32 = AtomicI32::new(-1);
    extern "C" fn on_signal(sig: libc::c_int) {
        let b = sig as u8;
        let fd = WRITE_FD.load(Ordering::Relaxed);
        // SAFETY: write(2) is async-signal-safe; the byte lives on this frame.
        unsafe {
            libc::write(fd, (&b as *const u8).cast(), 1);
        }
    }
    let mut fds = [0 as libc::c_int; 2];
    // SAFETY: pipe(2) fills the two descriptors.
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return;
    }
    WRITE_FD.store(fds[1], Ordering::Relaxed);
    let read_fd = fds[0];
    std::thread::spawn(move || {
        let mut b = 0u8;
        // SAFETY: reading one byte into a local from the pipe's read end.
        let n = unsafe { libc::read(read_fd, (&mut b as *mut u8).cast(), 1) };
        if n != 1 {
            return;
        }
        let sig = libc::c_int::from(b);
        let name = if sig == libc::SIGINT {
            "SIGINT (Ctrl-C)"
        } else {
            "SIGTERM"
        };
        let (_held, removed) = REGISTRY.remove_pending();
        eprintln!("{}", farewell(name, removed));
        std::process::exit(128 + sig);
    });
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: a handler that only writes to a pipe; installed before any output is written.
        unsafe {
            let mut sa: libc::sigaction = std::mem::zeroed();
            sa.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as usize;
            sa.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut sa.sa_mask);
            libc::sigaction(sig, &sa, std::ptr::null_mut());
        }
    }
}

/// Elsewhere the default handling stays (the next command recovers what was left).
#[cfg(not(unix))]
pub fn install() {}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the cleanup's contract: what is tracked and not yet published is removed (a file
    // and a folder), what was untracked (published) stays.
    #[test]
    fn unpublished_outputs_are_removed_and_published_ones_kept() {
        let tmp = tempfile::tempdir().unwrap();
        let (f, d, kept) = (
            tmp.path().join(".a.tmp-1"),
            tmp.path().join(".s.new-1"),
            tmp.path().join(".b.tmp-1"),
        );
        let reg = Registry::new();
        for p in [&f, &kept] {
            reg.track(p);
            std::fs::write(p, b"x").unwrap();
        }
        reg.track(&d);
        std::fs::create_dir(&d).unwrap();
        std::fs::write(d.join("inner"), b"y").unwrap();
        reg.untrack(&kept);
        let (held, removed) = reg.remove_pending();
        drop(held);
        assert_eq!(removed, 2);
        assert!(!f.exists() && !d.exists() && kept.exists());
        assert!(farewell("SIGTERM", 2).contains("removed 2 unfinished"));
    }
}
