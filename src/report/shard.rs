//! A report over many scenes shards like a sweep: studies are independent per scene, so
//! `report --shard I/N` studies and writes the scenes with index k ≡ I (mod N) (scene files in
//! name order) and records them in `shards/I-of-N.json`; `report --merge` then checks that every
//! shard of one report is present exactly once and builds the overview from the scenes' own
//! `results.json`, in the order an unsharded report lists them.

use super::summary::{SceneSummary, Summary};
use crate::error::{Error, Result};
use crate::measure::sweep::Shard;
use crate::output::write_atomic;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What one shard of a report wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReportShard {
    /// This shard.
    pub shard: Shard,
    /// (index among the scene files, scene folder name) of every scene it wrote.
    pub scenes: Vec<(usize, String)>,
    /// (index, scenario file, error) of every scene it could not report.
    pub failed: Vec<(usize, String, String)>,
}

/// The shard record's path under the report folder.
pub fn shard_path(out: &Path, shard: Shard) -> PathBuf {
    out.join("shards")
        .join(format!("{}-of-{}.json", shard.index, shard.count))
}

/// Writes a shard's record.
pub fn write_shard(out: &Path, rec: &ReportShard) -> Result<PathBuf> {
    let mut json = serde_json::to_vec_pretty(rec).expect("serialisable");
    json.push(b'\n');
    write_atomic(shard_path(out, rec.shard), &json)
}

/// Reads a JSON document with its wall times put back from its `timing.json`.
fn read_json<T: for<'de> Deserialize<'de>>(p: &Path) -> Result<T> {
    let text = crate::output::read_document(p)?;
    serde_json::from_str(&text).map_err(|e| Error::invalid(p, "(document)", e.to_string()))
}

/// Joins the shards recorded under `out/shards/` into the report's summary (scenes in file
/// order; a failed scene keeps the earlier overview's row, as in [`super::overview::assemble`]);
/// errors name the shard file and what is missing or repeated.
pub fn merge_shards(out: &Path, generator: &str, quick: bool) -> Result<Summary> {
    let dir = out.join("shards");
    let rd = match std::fs::read_dir(&dir) {
        Ok(rd) => Some(rd),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(source) => {
            return Err(Error::Read {
                file: dir.clone(),
                source,
            })
        }
    };
    let mut files: Vec<PathBuf> = rd
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(Error::option(
            "--merge",
            format!(
                "{}: no shard records (run report --shard I/N first)",
                dir.display()
            ),
        ));
    }
    let mut count = None;
    let mut seen: Vec<bool> = Vec::new();
    let mut outcomes: Vec<(usize, String, std::result::Result<SceneSummary, String>)> = Vec::new();
    for f in &files {
        // A shard's record has no wall times: read as written.
        let text = std::fs::read_to_string(f).map_err(|source| Error::Read {
            file: f.clone(),
            source,
        })?;
        let rec: ReportShard = serde_json::from_str(&text)
            .map_err(|e| Error::invalid(f, "(document)", e.to_string()))?;
        let n = *count.get_or_insert(rec.shard.count);
        if rec.shard.count != n {
            return Err(Error::invalid(
                f,
                "shard.count",
                format!("{} but another shard says {n}", rec.shard.count),
            ));
        }
        seen.resize(n, false);
        if std::mem::replace(&mut seen[rec.shard.index], true) {
            return Err(Error::invalid(
                f,
                "shard.index",
                format!("shard {} recorded twice", rec.shard.index),
            ));
        }
        for (k, name) in rec.scenes {
            let s: SceneSummary = read_json(&out.join(&name).join("results.json"))?;
            outcomes.push((k, s.file.clone(), Ok(s)));
        }
        outcomes.extend(rec.failed.into_iter().map(|(k, f, e)| (k, f, Err(e))));
    }
    if let Some(missing) = seen.iter().position(|s| !s) {
        return Err(Error::option(
            "--merge",
            format!("shard {missing}/{} is missing", seen.len()),
        ));
    }
    outcomes.sort_by_key(|(k, _, _)| *k);
    let previous = super::overview::previous_summary(out);
    let mut sum = super::overview::assemble(
        generator,
        quick,
        outcomes.into_iter().map(|(_, f, r)| (f, r)).collect(),
        previous.as_ref(),
    );
    sum.small_steps = super::small_steps::read_link(out);
    Ok(sum)
}
