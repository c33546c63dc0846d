//! The reference store: references and ensembles kept on disk between commands, so a second
//! command on the same scene (a `compare` after an `advise`, a report after either) reads what
//! an earlier one solved instead of solving it again.
//!
//! An entry is keyed by the full description of what was solved (the system, the initial
//! state, the sample grids, the horizon, the solver and its work limit) and by the running
//! program's own digest ([`crate::output::digest::program_digest`]), so another build never
//! reads this one's entries. What is read back is the same bits the solve gave: each entry
//! holds a header (JSON, checked to parse back equal before it is written) and its floats as
//! raw bits, with a digest of both; an entry that does not match its digest, its key or its
//! length is solved again and rewritten.
//!
//! Where: `SPRINGLAB_CACHE_DIR` when set, else `$XDG_CACHE_HOME/springlab/references`, else
//! `$HOME/.cache/springlab/references`. The command line uses it unless `--no-cache` (or
//! `SPRINGLAB_NO_CACHE`) is given; the library uses it only after [`use_dir`].
//!
//! Safe under concurrent commands and kill -9: an entry is written under a temporary name
//! unique to the process and thread, then renamed into place, so a reader sees a whole entry
//! or none. The store holds at most [`STORE_BYTES`]; past that the entries read or written
//! longest ago are removed. A store that cannot be written is skipped with one warning.

use crate::output::digest::{digest, program_digest};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::RwLock;
use std::time::{Duration, SystemTime};

/// Most bytes the store keeps; older entries are removed past it.
pub const STORE_BYTES: u64 = 2 << 30;

/// The first line of every entry: the format and its version.
const MAGIC: &[u8] = b"springlab reference store 1\n";

/// A temporary file older than this is left over from a killed writer and removed.
const STALE_TMP: Duration = Duration::from_secs(3600);

static DIR: RwLock<Option<PathBuf>> = RwLock::new(None);
static WARNED: AtomicBool = AtomicBool::new(false);
static TMP_SEQ: AtomicU64 = AtomicU64::new(0);

/// The store's folder on this machine: `SPRINGLAB_CACHE_DIR`, else the platform cache folder;
/// None when neither is known (no store).
pub fn default_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("SPRINGLAB_CACHE_DIR").filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(d));
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("springlab").join("references"))
}

/// Uses the store in `dir` for the rest of the process (None: no store, the default).
pub fn use_dir(dir: Option<PathBuf>) {
    *DIR.write().unwrap_or_else(|e| e.into_inner()) = dir;
}

/// The folder in use, if any.
pub fn dir() -> Option<PathBuf> {
    DIR.read().unwrap_or_else(|e| e.into_inner()).clone()
}

/// The entry of `kind` for `key` from the store in use: its header and floats, or None
/// (no store, no entry, or an entry that fails its checks).
pub(super) fn load(kind: &str, key: &str) -> Option<(Vec<u8>, Vec<f64>)> {
    load_in(&dir()?, kind, key)
}

/// Writes the entry of `kind` for `key` to the store in use (nothing without one).
pub(super) fn save(kind: &str, key: &str, header: &[u8], floats: &[f64]) {
    if let Some(d) = dir() {
        if let Err(e) = save_in(&d, kind, key, header, floats) {
            if !WARNED.swap(true, Ordering::Relaxed) {
                eprintln!(
                    "warning: the reference store {} cannot be written ({e}); references are solved afresh",
                    d.display()
                );
            }
        }
    }
}

/// The entry's file name: its kind and the digest of its key and the program.
fn entry_name(kind: &str, key: &str) -> (String, String) {
    let key_digest = digest(&[key.as_bytes(), program_digest().as_bytes()]);
    (format!("{kind}-{key_digest}.bin"), key_digest)
}

/// The digest of an entry's header and floats.
fn body_digest(header: &[u8], floats: &[u8]) -> String {
    digest(&[header, floats])
}

/// Reads the entry of `kind` for `key` from `dir`; marks it used (its modification time) so
/// the store removes it last.
pub(super) fn load_in(dir: &Path, kind: &str, key: &str) -> Option<(Vec<u8>, Vec<f64>)> {
    let (name, key_digest) = entry_name(kind, key);
    let path = dir.join(name);
    let bytes = std::fs::read(&path).ok()?;
    let (header, floats) = decode(&bytes, &key_digest)?;
    if let Ok(f) = std::fs::File::options().append(true).open(&path) {
        let _ = f.set_modified(SystemTime::now());
    }
    Some((header, floats))
}

/// The header and floats of entry `bytes` when it is whole and for `key_digest`.
fn decode(bytes: &[u8], key_digest: &str) -> Option<(Vec<u8>, Vec<f64>)> {
    let rest = bytes.strip_prefix(MAGIC)?;
    // Line 2: key digest, body digest, header length, float count.
    let nl = rest.iter().position(|&b| b == b'\n')?;
    let line = std::str::from_utf8(&rest[..nl]).ok()?;
    let mut parts = line.split(' ');
    let (k, body, hlen, count) = (
        parts.next()?,
        parts.next()?,
        parts.next()?.parse::<usize>().ok()?,
        parts.next()?.parse::<usize>().ok()?,
    );
    if k != key_digest {
        return None;
    }
    let rest = &rest[nl + 1..];
    if rest.len() != hlen.checked_add(count.checked_mul(8)?)? {
        return None;
    }
    let (header, raw) = rest.split_at(hlen);
    if body_digest(header, raw) != body {
        return None;
    }
    let floats = raw
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect();
    Some((header.to_vec(), floats))
}

/// The bytes of an entry for `key_digest`.
fn encode(key_digest: &str, header: &[u8], floats: &[f64]) -> Vec<u8> {
    let raw: Vec<u8> = floats.iter().flat_map(|x| x.to_le_bytes()).collect();
    let mut out = MAGIC.to_vec();
    out.extend_from_slice(
        format!(
            "{key_digest} {} {} {}\n",
            body_digest(header, &raw),
            header.len(),
            floats.len()
        )
        .as_bytes(),
    );
    out.extend_from_slice(header);
    out.extend_from_slice(&raw);
    out
}

/// Writes the entry under a temporary name unique to this process and thread, renames it into
/// place, then keeps the store within [`STORE_BYTES`].
pub(super) fn save_in(
    dir: &Path,
    kind: &str,
    key: &str,
    header: &[u8],
    floats: &[f64],
) -> std::io::Result<()> {
    let (name, key_digest) = entry_name(kind, key);
    std::fs::create_dir_all(dir)?;
    let tmp = dir.join(format!(
        ".{name}.tmp-{}-{}",
        std::process::id(),
        TMP_SEQ.fetch_add(1, Ordering::Relaxed)
    ));
    crate::output::interrupt::track(&tmp);
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(&encode(&key_digest, header, floats))?;
        f.sync_all()?;
        std::fs::rename(&tmp, dir.join(&name))
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    crate::output::interrupt::untrack(&tmp);
    written?;
    prune(dir, STORE_BYTES);
    Ok(())
}

/// Removes the entries used longest ago until the store holds at most three quarters of
/// `limit` bytes (when it holds more than `limit`), and temporary files left by killed writers.
pub(super) fn prune(dir: &Path, limit: u64) {
    let Ok(list) = std::fs::read_dir(dir) else {
        return;
    };
    let now = SystemTime::now();
    let mut entries: Vec<(SystemTime, u64, PathBuf)> = Vec::new();
    for e in list.flatten() {
        let Ok(meta) = e.metadata() else { continue };
        let modified = meta.modified().unwrap_or(now);
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') && name.contains(".tmp-") {
            if now
                .duration_since(modified)
                .is_ok_and(|age| age > STALE_TMP)
            {
                let _ = std::fs::remove_file(e.path());
            }
            continue;
        }
        if meta.is_file() && name.ends_with(".bin") {
            entries.push((modified, meta.len(), e.path()));
        }
    }
    let mut held: u64 = entries.iter().map(|e| e.1).sum();
    if held <= limit {
        return;
    }
    entries.sort_by(|a, b| a.0.cmp(&b.0).then_with(|| a.2.cmp(&b.2)));
    for (_, len, path) in entries {
        if held <= limit / 4 * 3 {
            break;
        }
        if std::fs::remove_file(&path).is_ok() {
            held -= len;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("springlab-store-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    // Oracle: the floats' bits. Every float read back is the bit pattern written, the
    // non-finite ones and the signed zero included.
    #[test]
    fn an_entry_reads_back_the_same_bits() {
        let d = temp("bits");
        let floats = [
            0.1,
            -0.0,
            f64::MIN_POSITIVE / 3.0,
            f64::INFINITY,
            1.0 / 3.0,
            f64::MAX,
        ];
        save_in(&d, "reference", "key", b"{\"a\":1}", &floats).unwrap();
        let (h, back) = load_in(&d, "reference", "key").unwrap();
        assert_eq!(h, b"{\"a\":1}");
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&floats));
        // Twin: another key (or kind) finds nothing.
        assert!(load_in(&d, "reference", "other key").is_none());
        assert!(load_in(&d, "ensemble", "key").is_none());
        let _ = std::fs::remove_dir_all(&d);
    }

    // Oracle: a half-written or altered entry must never be read. Every truncation of a whole
    // entry, and a flipped bit anywhere in it, fails its checks; the whole entry passes.
    #[test]
    fn a_cut_or_altered_entry_is_not_read() {
        let (_, kd) = entry_name("reference", "key");
        let whole = encode(&kd, b"{\"h\":[1,2]}", &[1.0, 2.0, 3.0]);
        assert!(decode(&whole, &kd).is_some());
        for cut in 0..whole.len() {
            assert!(decode(&whole[..cut], &kd).is_none(), "cut at {cut}");
        }
        for at in 0..whole.len() {
            let mut bad = whole.clone();
            bad[at] ^= 0x10;
            assert!(decode(&bad, &kd).is_none(), "flip at {at}");
        }
    }

    // Oracle: the byte count of the files left. Past the limit the store drops the entries
    // used longest ago down to three quarters of it; within the limit it drops nothing.
    #[test]
    fn the_store_drops_the_oldest_entries_past_its_limit() {
        let d = temp("prune");
        for k in 0..4 {
            save_in(&d, "reference", &format!("key {k}"), b"{}", &[0.0; 100]).unwrap();
            let (name, _) = entry_name("reference", &format!("key {k}"));
            let when = SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000 + k);
            let f = std::fs::File::options()
                .append(true)
                .open(d.join(name))
                .unwrap();
            f.set_modified(when).unwrap();
        }
        let size = std::fs::read_dir(&d)
            .unwrap()
            .flatten()
            .map(|e| e.metadata().unwrap().len())
            .sum::<u64>();
        prune(&d, size);
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 4);
        // A limit of two and a half entries keeps the newest one (three quarters of it).
        prune(&d, size / 8 * 5);
        assert!(load_in(&d, "reference", "key 3").is_some());
        assert!(load_in(&d, "reference", "key 0").is_none());
        assert!(load_in(&d, "reference", "key 1").is_none());
        let _ = std::fs::remove_dir_all(&d);
    }
}
