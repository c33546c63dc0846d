//! Atomic file writes: write to a temporary name beside the target, then rename, so an
//! interrupted run never destroys or half-writes an earlier output.

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
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(werr)?;
        }
        let name = target
            .file_name()
            .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
        let tmp = target.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
        let f = File::create(&tmp).map_err(werr)?;
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
        let f = out.into_inner().map_err(|e| werr(e.into_error()))?;
        f.sync_all().map_err(werr)?;
        std::fs::rename(&self.tmp, &self.target).map_err(werr)?;
        Ok(self.target.clone())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
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

/// A directory rewritten whole: the earlier one is moved aside under a hidden name while the
/// new one is written in place, then removed on [`FreshDir::commit`]. A directory rewritten by
/// a later run thus holds exactly what that run wrote (no stale file of an earlier run
/// survives), and a run that fails before committing (an error, or an interrupt that unwinds)
/// puts the earlier directory back.
#[derive(Debug)]
pub struct FreshDir {
    target: PathBuf,
    old: Option<PathBuf>,
    committed: bool,
}

impl FreshDir {
    /// Moves any earlier `target` aside and creates it empty.
    pub fn create(target: impl AsRef<Path>) -> Result<Self> {
        let target = target.as_ref().to_path_buf();
        let werr = |file: &Path, source| Error::Write {
            file: file.to_path_buf(),
            source,
        };
        let old = if target.exists() {
            let name = target
                .file_name()
                .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
            let old = target.with_file_name(format!(".{name}.old-{}", std::process::id()));
            if old.exists() {
                std::fs::remove_dir_all(&old).map_err(|e| werr(&old, e))?;
            }
            std::fs::rename(&target, &old).map_err(|e| werr(&target, e))?;
            Some(old)
        } else {
            None
        };
        std::fs::create_dir_all(&target).map_err(|e| werr(&target, e))?;
        Ok(FreshDir {
            target,
            old,
            committed: false,
        })
    }
    /// The directory to write into (its final path).
    pub fn path(&self) -> &Path {
        &self.target
    }
    /// Keeps the new directory and removes the earlier one.
    pub fn commit(mut self) -> Result<PathBuf> {
        self.committed = true;
        if let Some(old) = &self.old {
            std::fs::remove_dir_all(old).map_err(|source| Error::Write {
                file: old.clone(),
                source,
            })?;
        }
        Ok(self.target.clone())
    }
}

impl Drop for FreshDir {
    fn drop(&mut self) {
        if !self.committed {
            if let Some(old) = &self.old {
                let _ = std::fs::remove_dir_all(&self.target);
                let _ = std::fs::rename(old, &self.target);
            }
        }
    }
}

#[cfg(test)]
mod fresh_dir_tests {
    use super::*;

    // Oracle: the definition of a whole rewrite. The new directory holds exactly the files
    // written into it; the earlier directory's other files are gone; an uncommitted rewrite
    // leaves the earlier directory as it was.
    #[test]
    fn commit_replaces_the_whole_directory_and_drop_keeps_the_old_one() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("scene");
        std::fs::create_dir_all(target.join("sweep")).unwrap();
        std::fs::write(target.join("sweep/old.csv"), "old").unwrap();
        std::fs::write(target.join("index.html"), "old").unwrap();
        {
            let st = FreshDir::create(&target).unwrap();
            std::fs::write(st.path().join("index.html"), "abandoned").unwrap();
        }
        assert_eq!(
            std::fs::read_to_string(target.join("index.html")).unwrap(),
            "old"
        );
        assert!(target.join("sweep/old.csv").exists());
        let st = FreshDir::create(&target).unwrap();
        write_atomic(st.path().join("index.html"), b"new").unwrap();
        st.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(target.join("index.html")).unwrap(),
            "new"
        );
        assert!(!target.join("sweep").exists());
        let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "no earlier directory is left behind");
    }
}
