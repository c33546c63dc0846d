//! Wall times apart: every JSON and CSV document a command or the report writes keeps only
//! what a re-run reproduces bit for bit, and the measured wall times go to one `timing.json`
//! beside them. Re-running a command or the report then leaves every document whose numbers
//! did not change byte-identical; only `timing.json` moves.
//!
//! A wall time is a field or column named in [`WALL_KEYS`]. [`write_document`] takes them out
//! of a document as it is written and records them under the document's name in the folder's
//! `timing.json`: for JSON, each object that held one, by its JSON pointer, with the names
//! that identify it (method, step, rate, …) and the values; for CSV, each line by number, with
//! its identifying cells and the values as written. [`read_document`] puts them back, so a
//! reader of the full document (a sweep's shards merged) sees what was measured.

use super::atomic::write_atomic;
use crate::error::{Error, Result};
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// Field and column names that hold measured wall times.
pub const WALL_KEYS: &[&str] = &[
    "wall_seconds",
    "wall_per_second",
    "wall_seconds_per_frame",
    "wall_seconds_per_simulated_second",
    "wall_ratio",
    "timing",
];

/// Names that identify the object or line a wall time belongs to, recorded beside it.
const ID_KEYS: &[&str] = &[
    "scene", "method", "n", "hz", "fps", "row", "dt", "steps", "substeps",
];

/// The file every folder's wall times go to.
pub const TIMING_FILE: &str = "timing.json";

/// What `timing.json` says about itself.
const ABOUT: &str = "Measured wall times of the documents in this folder, kept apart so that every other document is the same on every re-run. Per document: each object (JSON pointer `at`) or line (`line`, 1 = header) that held one, with the names that identify it and the values.";

fn is_wall(key: &str) -> bool {
    WALL_KEYS.contains(&key)
}

/// Takes every wall-time field out of `v` (recursively), returning one record per object.
fn split_json(v: &mut Value, at: &str, ids: &Map<String, Value>, out: &mut Vec<Value>) {
    match v {
        Value::Object(map) => {
            let mut ids = ids.clone();
            for k in ID_KEYS {
                if let Some(x) = map.get(*k).filter(|x| !x.is_object() && !x.is_array()) {
                    ids.insert((*k).to_string(), x.clone());
                }
            }
            let walls: Vec<String> = map.keys().filter(|k| is_wall(k)).cloned().collect();
            if !walls.is_empty() {
                let mut rec = Map::new();
                rec.insert("at".into(), Value::String(at.to_string()));
                rec.extend(ids.clone());
                for k in walls {
                    // shift_remove: the fields left keep the order they were written in.
                    if let Some(x) = map.shift_remove(&k) {
                        rec.insert(k, x);
                    }
                }
                out.push(Value::Object(rec));
            }
            for (k, x) in map.iter_mut() {
                let child = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                split_json(x, &child, &ids, out);
            }
        }
        Value::Array(items) => {
            for (i, x) in items.iter_mut().enumerate() {
                split_json(x, &format!("{at}/{i}"), ids, out);
            }
        }
        _ => {}
    }
}

/// Splits a CSV text (first line the header) into the text without its wall-time columns and
/// their record: `columns` (each wall-time column's place in the header) and `lines` (one per
/// data line). Quoted fields are kept whole.
fn split_csv(text: &str) -> (String, Option<Value>) {
    let mut lines = records(text).into_iter();
    let Some(header) = lines.next() else {
        return (text.to_string(), None);
    };
    let head = fields(&header);
    let walls: Vec<usize> = (0..head.len()).filter(|&i| is_wall(&head[i])).collect();
    if walls.is_empty() {
        return (text.to_string(), None);
    }
    let ids: Vec<usize> = (0..head.len())
        .filter(|&i| ID_KEYS.contains(&head[i].as_str()))
        .collect();
    let keep = |f: &[String]| -> String {
        f.iter()
            .enumerate()
            .filter(|(i, _)| !walls.contains(i))
            .map(|(_, s)| s.as_str())
            .collect::<Vec<_>>()
            .join(",")
    };
    let mut out = keep(&head);
    out.push('\n');
    let mut recs = Vec::new();
    for (n, line) in lines.enumerate() {
        let f = fields(&line);
        out.push_str(&keep(&f));
        out.push('\n');
        let mut rec = Map::new();
        rec.insert("line".into(), Value::from(n as u64 + 2));
        for &i in &ids {
            rec.insert(head[i].clone(), Value::String(cell(&f, i)));
        }
        for &i in &walls {
            rec.insert(head[i].clone(), Value::String(cell(&f, i)));
        }
        recs.push(Value::Object(rec));
    }
    let columns: Map<String, Value> = walls
        .iter()
        .map(|&i| (head[i].clone(), Value::from(i as u64)))
        .collect();
    let mut doc = Map::new();
    doc.insert("columns".into(), Value::Object(columns));
    doc.insert("lines".into(), Value::Array(recs));
    (out, Some(Value::Object(doc)))
}

fn cell(f: &[String], i: usize) -> String {
    f.get(i).cloned().unwrap_or_default()
}

/// `text` cut at every `sep` outside double quotes; each piece as written (quotes kept).
fn split_unquoted(text: &str, sep: char) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    for c in text.chars() {
        if c == '"' {
            quoted = !quoted;
        }
        if c == sep && !quoted {
            out.push(std::mem::take(&mut cur));
        } else {
            cur.push(c);
        }
    }
    out.push(cur);
    out
}

/// The records of a CSV text: its lines, except that a line break inside a quoted field stays
/// in its record.
fn records(text: &str) -> Vec<String> {
    let mut r = split_unquoted(text, '\n');
    if r.last().is_some_and(String::is_empty) {
        r.pop();
    }
    r
}

/// The fields of one CSV record as written (a quoted field keeps its quotes).
fn fields(line: &str) -> Vec<String> {
    split_unquoted(line, ',')
}

/// Reads `dir/timing.json`, or an empty one.
fn read_timing(dir: &Path) -> Result<Map<String, Value>> {
    let path = dir.join(TIMING_FILE);
    match std::fs::read(&path) {
        Ok(bytes) => {
            let v: Value = serde_json::from_slice(&bytes).map_err(|e| Error::Parse {
                file: path.clone(),
                location: String::new(),
                field: TIMING_FILE.into(),
                message: e.to_string(),
            })?;
            Ok(v.get("documents")
                .and_then(Value::as_object)
                .cloned()
                .unwrap_or_default())
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Map::new()),
        Err(source) => Err(Error::Read { file: path, source }),
    }
}

/// The folder's timing records, none when its `timing.json` does not parse: that file is this
/// module's own, damaged, so its documents read without wall times and the next write
/// replaces it. Any other failure to read it is an error, for writing and reading alike.
fn read_timing_kept(dir: &Path) -> Result<Map<String, Value>> {
    match read_timing(dir) {
        Err(Error::Parse { .. }) => Ok(Map::new()),
        other => other,
    }
}

/// Document `name`'s bytes without their wall times, and the record of those (`None` when it
/// held none: the bytes are then returned as given).
pub fn split(name: &str, bytes: &[u8]) -> (Vec<u8>, Option<Value>) {
    match Path::new(name).extension().and_then(|e| e.to_str()) {
        Some("json") => match serde_json::from_slice::<Value>(bytes) {
            Ok(mut v) => {
                let mut recs = Vec::new();
                split_json(&mut v, "", &Map::new(), &mut recs);
                if recs.is_empty() {
                    return (bytes.to_vec(), None);
                }
                let mut text = serde_json::to_vec_pretty(&v).expect("a parsed value serialises");
                if bytes.ends_with(b"\n") {
                    text.push(b'\n');
                }
                (text, Some(Value::Array(recs)))
            }
            Err(_) => (bytes.to_vec(), None),
        },
        Some("csv") => {
            let (t, rec) = split_csv(&String::from_utf8_lossy(bytes));
            (t.into_bytes(), rec)
        }
        _ => (bytes.to_vec(), None),
    }
}

/// The text of a `timing.json` holding `documents` (document name → its record).
pub fn timing_text(documents: Map<String, Value>) -> Vec<u8> {
    let mut top = Map::new();
    top.insert("about".into(), Value::String(ABOUT.into()));
    top.insert("documents".into(), Value::Object(documents));
    let mut text = serde_json::to_vec_pretty(&Value::Object(top)).expect("serialisable");
    text.push(b'\n');
    text
}

/// Writes `bytes` as document `path` (atomically), its wall times moved to the folder's
/// `timing.json` (replacing what it held for this document). Returns the paths written: the
/// document, and `timing.json` when it changed.
pub fn write_document(path: impl AsRef<Path>, bytes: &[u8]) -> Result<Vec<PathBuf>> {
    let path = path.as_ref();
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (doc, rec) = split(&name, bytes);
    let mut written = vec![write_atomic(path, &doc)?];
    let dir = path.parent().unwrap_or(Path::new("."));
    // One writer per folder (the commands lock it).
    let mut docs = read_timing_kept(dir)?;
    let had = docs.shift_remove(&name).is_some();
    let has = rec.is_some();
    if let Some(r) = rec {
        docs.insert(name, r);
    }
    if had || has {
        written.push(write_atomic(dir.join(TIMING_FILE), &timing_text(docs))?);
    }
    Ok(written)
}

/// Reads document `path` with its wall times put back from the folder's `timing.json` (a
/// document written by [`write_document`] reads with the values it had before the split; in
/// JSON the restored fields come last in their object).
pub fn read_document(path: impl AsRef<Path>) -> Result<String> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| Error::Read {
        file: path.to_path_buf(),
        source,
    })?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // The folder's own timing.json, else the one a folder above gathered it into.
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut rec = read_timing_kept(dir)?.get(&name).cloned();
    if rec.is_none() {
        if let (Some(up), Some(sub)) = (dir.parent(), dir.file_name()) {
            let key = format!("{}/{name}", sub.to_string_lossy());
            rec = read_timing_kept(up)?.get(&key).cloned();
        }
    }
    Ok(match &rec {
        Some(rec @ Value::Object(_)) => restore_csv(&text, rec),
        Some(Value::Array(recs)) => restore_json(&text, recs),
        _ => text,
    })
}

/// Moves the `timing.json` of each folder directly inside `dir` into `dir`'s own, its
/// documents named by their path from `dir` (`compare/summary.json`): one timing document for
/// a folder of folders, such as a report's scene. Returns whether `dir` now has one.
pub fn gather(dir: &Path) -> Result<bool> {
    let mut docs = read_timing_kept(dir)?;
    let mut subs: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|source| Error::Read {
            file: dir.to_path_buf(),
            source,
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join(TIMING_FILE).is_file())
        .collect();
    subs.sort();
    for sub in &subs {
        let name = sub
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        for (doc, rec) in read_timing_kept(sub)? {
            docs.insert(format!("{name}/{doc}"), rec);
        }
    }
    if subs.is_empty() {
        return Ok(dir.join(TIMING_FILE).is_file());
    }
    write_atomic(dir.join(TIMING_FILE), &timing_text(docs))?;
    for sub in &subs {
        let f = sub.join(TIMING_FILE);
        std::fs::remove_file(&f).map_err(|source| Error::Write { file: f, source })?;
    }
    Ok(true)
}

/// Puts the wall-time fields recorded in `recs` back into JSON `text`, each into the object
/// at its pointer (text that is not JSON is returned as it is).
fn restore_json(text: &str, recs: &[Value]) -> String {
    let Ok(mut v) = serde_json::from_str::<Value>(text) else {
        return text.to_string();
    };
    for r in recs {
        let Some(rec) = r.as_object() else { continue };
        let at = rec.get("at").and_then(Value::as_str).unwrap_or("");
        if let Some(Value::Object(obj)) = v.pointer_mut(at) {
            for (k, x) in rec.iter().filter(|(k, _)| is_wall(k)) {
                obj.insert(k.clone(), x.clone());
            }
        }
    }
    let mut out = serde_json::to_string_pretty(&v).expect("a parsed value serialises");
    if text.ends_with('\n') {
        out.push('\n');
    }
    out
}

/// Puts the wall-time columns recorded in `rec` back into CSV `text`, each at its place. A
/// record that does not fit the text (a wall-time column already there, or another number of
/// lines) is stale: the text is returned as it is.
fn restore_csv(text: &str, rec: &Value) -> String {
    let mut cols: Vec<(usize, &String)> = rec["columns"]
        .as_object()
        .map(|c| {
            c.iter()
                .filter_map(|(k, v)| Some((v.as_u64()? as usize, k)))
                .collect()
        })
        .unwrap_or_default();
    cols.sort();
    let lines_rec = rec["lines"].as_array().map_or(&[][..], Vec::as_slice);
    let rows = records(text);
    let head_has_wall = rows
        .first()
        .is_some_and(|h| fields(h).iter().any(|f| is_wall(f)));
    if head_has_wall || rows.len() != lines_rec.len() + 1 {
        return text.to_string();
    }
    // Each data line's first record by its line number (1 is the header).
    let mut by_line = std::collections::HashMap::new();
    for r in lines_rec {
        if let Some(n) = r.get("line").and_then(Value::as_u64) {
            by_line.entry(n).or_insert(r);
        }
    }
    let mut out = String::new();
    for (n, line) in rows.iter().enumerate() {
        let mut f = fields(line);
        let data = by_line.get(&(n as u64 + 1)).copied();
        for &(at, w) in &cols {
            let v = if n == 0 {
                w.clone()
            } else {
                data.and_then(|r| r.get(w.as_str()))
                    .and_then(Value::as_str)
                    .unwrap_or("")
                    .to_string()
            };
            f.insert(at.min(f.len()), v);
        }
        out.push_str(&f.join(","));
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the documents before the split, written by hand.
    // A damaged timing.json (not JSON) loses only the wall times: the documents beside it
    // still read, as written without them, and the next write replaces the file. Twin: a
    // timing.json that cannot be read at all (here a folder in its place) is an error, never
    // overwritten.
    #[test]
    fn a_damaged_timing_document_loses_only_the_wall_times() {
        let dir = tempfile::tempdir().unwrap();
        let doc = dir.path().join("a.csv");
        write_document(&doc, b"method,wall_seconds\nrk4,1\n").unwrap();
        std::fs::write(dir.path().join(TIMING_FILE), "not json").unwrap();
        assert_eq!(read_document(&doc).unwrap(), "method\nrk4\n");
        write_document(&doc, b"method,wall_seconds\nrk4,2\n").unwrap();
        assert_eq!(read_document(&doc).unwrap(), "method,wall_seconds\nrk4,2\n");
        let other = tempfile::tempdir().unwrap();
        std::fs::create_dir(other.path().join(TIMING_FILE)).unwrap();
        assert!(
            write_document(other.path().join("a.csv"), b"method,wall_seconds\nrk4,1\n").is_err()
        );
    }

    #[test]
    fn wall_times_leave_the_document_and_come_back() {
        let dir = tempfile::tempdir().unwrap();
        let csv = "method,dt,modelled_seconds,wall_seconds,error,note\nrk4,1e-3,2e-3,3.1e-3,1e-9,\"a, b\"\neuler,1e-2,1e-4,1.7e-4,,\n";
        let files = write_document(dir.path().join("a.csv"), csv.as_bytes()).unwrap();
        assert_eq!(files.len(), 2, "the document and timing.json");
        let kept = std::fs::read_to_string(dir.path().join("a.csv")).unwrap();
        assert_eq!(
            kept,
            "method,dt,modelled_seconds,error,note\nrk4,1e-3,2e-3,1e-9,\"a, b\"\neuler,1e-2,1e-4,,\n"
        );
        assert_eq!(read_document(dir.path().join("a.csv")).unwrap(), csv);
        let json = br#"{"command":"x","entries":[{"method":"rk4","dt":0.001,"wall_seconds":0.5,"timing":{"median_seconds":0.5},"error":1.0}]}"#;
        write_document(dir.path().join("b.json"), json).unwrap();
        let back: Value =
            serde_json::from_str(&read_document(dir.path().join("b.json")).unwrap()).unwrap();
        assert_eq!(back, serde_json::from_slice::<Value>(json).unwrap());
        let kept: Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("b.json")).unwrap()).unwrap();
        assert_eq!(
            kept,
            serde_json::json!({"command":"x","entries":[{"method":"rk4","dt":0.001,"error":1.0}]})
        );
        // Values compare without order: the text must keep the fields in their written order.
        let json = br#"{"method":"rk4","wall_seconds":0.5,"error":1.0,"note":"n","status":"ok"}"#;
        write_document(dir.path().join("c.json"), json).unwrap();
        let text = std::fs::read_to_string(dir.path().join("c.json")).unwrap();
        let at = |k: &str| text.find(&format!("\"{k}\"")).unwrap();
        assert!(
            at("method") < at("error") && at("error") < at("note") && at("note") < at("status")
        );
        let t: Value =
            serde_json::from_slice(&std::fs::read(dir.path().join(TIMING_FILE)).unwrap()).unwrap();
        let rec = &t["documents"]["b.json"][0];
        assert_eq!(t["documents"]["a.csv"]["columns"]["wall_seconds"], 3);
        assert_eq!(rec["at"], "/entries/0");
        assert_eq!(rec["method"], "rk4");
        assert_eq!(rec["wall_seconds"], 0.5);
        // Both documents are listed; rewriting one replaces only its own records.
        assert!(t["documents"]["a.csv"]["lines"].is_array());
        write_document(dir.path().join("a.csv"), b"method,wall_seconds\nrk4,1\n").unwrap();
        let t: Value =
            serde_json::from_slice(&std::fs::read(dir.path().join(TIMING_FILE)).unwrap()).unwrap();
        assert_eq!(
            t["documents"]["a.csv"]["lines"].as_array().unwrap().len(),
            1
        );
        assert!(t["documents"]["b.json"].is_array());
        // Gathered into the folder above, the records are found there.
        let up = tempfile::tempdir().unwrap();
        let sub = up.path().join("part");
        std::fs::create_dir(&sub).unwrap();
        write_document(sub.join("a.csv"), csv.as_bytes()).unwrap();
        assert!(gather(up.path()).unwrap());
        assert!(!sub.join(TIMING_FILE).exists());
        assert_eq!(read_document(sub.join("a.csv")).unwrap(), csv);
    }

    // A quoted field may hold a line break; a record that no longer fits is left out.
    #[test]
    fn quoted_line_breaks_and_stale_records() {
        let dir = tempfile::tempdir().unwrap();
        let csv = "method,wall_seconds,note\nrk4,1.5,\"two\nlines\"\neuler,2.5,\n";
        write_document(dir.path().join("a.csv"), csv.as_bytes()).unwrap();
        let kept = std::fs::read_to_string(dir.path().join("a.csv")).unwrap();
        assert_eq!(kept, "method,note\nrk4,\"two\nlines\"\neuler,\n");
        assert_eq!(read_document(dir.path().join("a.csv")).unwrap(), csv);
        // The document replaced behind the record's back: one line fewer reads as it is.
        std::fs::write(dir.path().join("a.csv"), "method,note\nrk4,x\n").unwrap();
        assert_eq!(
            read_document(dir.path().join("a.csv")).unwrap(),
            "method,note\nrk4,x\n"
        );
    }

    // The twin: a document without wall times is written as given and adds no timing file.
    #[test]
    fn a_document_without_wall_times_is_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let files = write_document(dir.path().join("c.csv"), b"method,error\nrk4,1\n").unwrap();
        assert_eq!(files.len(), 1);
        assert!(!dir.path().join(TIMING_FILE).exists());
        let json = b"{\n  \"a\": 1\n}";
        write_document(dir.path().join("d.json"), json).unwrap();
        assert_eq!(std::fs::read(dir.path().join("d.json")).unwrap(), json);
    }
}
