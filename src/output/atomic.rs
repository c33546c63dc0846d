//! Atomic file writes: write to a temporary name beside the target, then rename, so an
//! interrupted run never destroys or half-writes an earlier output.
//!
//! A rename lands on whatever the path names, so a path that is not a plain file is never
//! renamed over: a symbolic link is written through (atomically, beside the file it points
//! to, and the link stays a link), and a device, FIFO or socket is written directly (the node
//! stays what it is; `/dev/full` reports its error).

use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file being written under a temporary name; [`AtomicFile::commit`] renames it into place.
/// Dropping it uncommitted removes the temporary file and leaves any earlier file untouched.
#[derive(Debug)]
pub struct AtomicFile {
    target: PathBuf,
    tmp: PathBuf,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `target` (its directory is created if missing).
    pub fn create(target: impl AsRef<Path>) -> Result<Self> {
        let target = target.as_ref().to_path_buf();
        let werr = |source| Error::Write {
            file: target.clone(),
            source,
        };
        let target = through_links(&target).map_err(werr)?;
        let werr = |source| Error::Write {
            file: target.clone(),
            source,
        };
        if std::fs::metadata(&target).is_ok_and(|m| is_special(&m.file_type())) {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .map_err(werr)?;
            return Ok(AtomicFile {
                tmp: target.clone(),
                target,
                out: Some(BufWriter::with_capacity(1 << 16, f)),
            });
        }
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(werr)?;
        }
        let name = target
            .file_name()
            .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
        let tmp = target.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
        super::interrupt::track(&tmp);
        let f = File::create(&tmp).map_err(|e| {
            super::interrupt::untrack(&tmp);
            werr(e)
        })?;
        Ok(AtomicFile {
            target,
            tmp,
            out: Some(BufWriter::with_capacity(1 << 16, f)),
        })
    }
    /// The writer for the file's contents.
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.out.as_mut().expect("writer used after commit")
    }
    /// The final path.
    pub fn target(&self) -> &Path {
        &self.target
    }
    /// Flushes, syncs and renames the file into place.
    pub fn commit(mut self) -> Result<PathBuf> {
        let werr = |source| Error::Write {
            file: self.target.clone(),
            source,
        };
        let out = self.out.take().expect("commit once");
        if self.tmp == self.target {
            // Written directly into a device or FIFO: nothing to sync or rename.
            out.into_inner().map_err(|e| werr(e.into_error()))?;
            return Ok(self.target.clone());
        }
        // A failed flush, sync or rename (a full disk, a file-size limit) removes the
        // temporary file before the error goes up: nothing hidden is left behind.
        let published = out
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all())
            .and_then(|()| {
                super::interrupt::publishing(|| {
                    let r = std::fs::rename(&self.tmp, &self.target);
                    if r.is_ok() {
                        super::interrupt::untrack(&self.tmp);
                    }
                    r
                })
            });
        if let Err(e) = published {
            let _ = std::fs::remove_file(&self.tmp);
            super::interrupt::untrack(&self.tmp);
            return Err(werr(e));
        }
        Ok(self.target.clone())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.take().is_some() && self.tmp != self.target {
            let _ = std::fs::remove_file(&self.tmp);
            super::interrupt::untrack(&self.tmp);
        }
    }
}

/// True for a node a rename must not replace: a device, a FIFO or a socket.
fn is_special(t: &std::fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    t.is_block_device() || t.is_char_device() || t.is_fifo() || t.is_socket()
}

/// The path a write to `path` must land on: `path` itself, or, through any chain of symbolic
/// links, the file the last link names (which may not exist yet).
fn through_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

/// Writes `bytes` to `target` atomically.
pub fn write_atomic(target: impl AsRef<Path>, bytes: &[u8]) -> Result<PathBuf> {
    let mut f = AtomicFile::create(target)?;
    let target = f.target().to_path_buf();
    f.writer().write_all(bytes).map_err(|source| Error::Write {
        file: target,
        source,
    })?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: what a rename does to the node a path names (POSIX rename(2) replaces it). A write
    // through a link must leave the link a link and put the bytes in the file it names; a write
    // to a character device must leave the device a device; a plain file is replaced whole.
    #[test]
    fn a_link_stays_a_link_a_device_a_device_and_a_file_is_replaced() {
        let dir = std::env::temp_dir().join(format!("springlab-atomic-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let real = dir.join("real.txt");
        let link = dir.join("link.txt");
        std::fs::write(&real, "old").unwrap();
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        // A dangling link: the file it names is created, the link kept.
        let dangling = dir.join("dangling.txt");
        std::os::unix::fs::symlink("later.txt", &dangling).unwrap();
        write_atomic(&dangling, b"x").unwrap();
        assert!(std::fs::symlink_metadata(&dangling)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(dir.join("later.txt")).unwrap(), "x");
        // The twin: a plain file is replaced by the rename, whole.
        write_atomic(&real, b"plain").unwrap();
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "plain");
        assert!(std::fs::symlink_metadata(&real)
            .unwrap()
            .file_type()
            .is_file());
        // A device is written through and stays a device; /dev/full says it is full.
        use std::os::unix::fs::FileTypeExt;
        write_atomic("/dev/null", b"gone").unwrap();
        assert!(std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device());
        if std::path::Path::new("/dev/full").exists() {
            assert!(write_atomic("/dev/full", b"no room").is_err());
            assert!(std::fs::metadata("/dev/full")
                .unwrap()
                .file_type()
                .is_char_device());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
