//! Shard files and the merge: `shard.json` records what a shard ran; `merge` joins the
//! shards of one sweep into exactly the unsharded result.

use super::plan::SweepPlan;
use super::SweepSummary;
use super::{summarise, Shard, SweepResult, SweepRow, SWEEP_HEADER};
use crate::error::{Error, Result};
use crate::measure::reference::ReferenceInfo;
use crate::output::{write_atomic, write_document};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `shard.json`: what a shard ran, so `merge` can check and join shards.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardFile {
    /// The sweep's plan (identical in every shard).
    pub plan: SweepPlan,
    /// This shard.
    pub shard: Shard,
    /// Case indices of the rows of this shard's `sweep.csv`, in order.
    pub cases: Vec<usize>,
    /// Reference used.
    pub reference: ReferenceInfo,
    /// Error floor (m) per candidate step, for the order fits.
    pub floors: Vec<f64>,
    /// Saturation bound (m) for the order fits.
    pub saturation: f64,
}

pub(super) fn json<T: Serialize>(v: &T) -> Vec<u8> {
    let mut b = serde_json::to_vec_pretty(v).expect("serialisable");
    b.push(b'\n');
    b
}

/// Writes `sweep.csv` and, for a full sweep, `summary.json`; for a shard, `shard.json`.
pub fn write_sweep(dir: &Path, res: &SweepResult) -> Result<Vec<PathBuf>> {
    let mut csv = String::from(SWEEP_HEADER);
    csv.push('\n');
    for r in &res.rows {
        csv.push_str(&r.csv_line());
        csv.push('\n');
    }
    let mut out = write_document(dir.join("sweep.csv"), csv.as_bytes())?;
    match (&res.summary, res.shard) {
        (Some(s), _) => {
            let doc = SweepSummary {
                command: crate::measure::command::with_out(&s.command, dir),
                ..s.clone()
            };
            out.push(write_atomic(dir.join("summary.json"), &json(&doc))?)
        }
        (None, Some(shard)) => {
            let f = ShardFile {
                plan: res.plan.clone(),
                shard,
                cases: res.case_indices.clone(),
                reference: res.reference.clone(),
                floors: res.floors.clone(),
                saturation: res.saturation,
            };
            out.push(write_atomic(dir.join("shard.json"), &json(&f))?);
        }
        (None, None) => {}
    }
    Ok(out)
}

fn read_rows(path: &Path) -> Result<Vec<SweepRow>> {
    let bad = |line: usize, m: String| Error::invalid(path, format!("line {line}"), m);
    // The wall times come back from the shard's timing.json.
    let text = crate::output::read_document(path)?;
    let mut lines = text.lines();
    if lines.next() != Some(SWEEP_HEADER) {
        return Err(bad(1, format!("header must be '{SWEEP_HEADER}'")));
    }
    let mut rows = Vec::new();
    for (i, l) in lines.enumerate() {
        let n = i + 2;
        let f: Vec<&str> = l.split(',').collect();
        if f.len() != 11 {
            return Err(bad(n, format!("expected 11 fields, got {}", f.len())));
        }
        let num = |k: usize, name: &str| -> Result<f64> {
            f[k].parse::<f64>()
                .map_err(|_| bad(n, format!("{name}: not a number: '{}'", f[k])))
        };
        let opt = |k: usize, name: &str| -> Result<Option<f64>> {
            if f[k].is_empty() {
                Ok(None)
            } else {
                num(k, name).map(Some)
            }
        };
        let int = |k: usize, name: &str| -> Result<u64> {
            f[k].parse::<u64>()
                .map_err(|_| bad(n, format!("{name}: not a whole number: '{}'", f[k])))
        };
        rows.push(SweepRow {
            method: f[0].to_string(),
            dt: num(1, "dt")?,
            steps: int(2, "steps")?,
            force_evals: int(3, "force_evals")?,
            modelled_seconds: num(4, "modelled_seconds")?,
            wall_seconds: num(5, "wall_seconds")?,
            error_final: opt(6, "error_final")?,
            error_max: opt(7, "error_max")?,
            error_rms: opt(8, "error_rms")?,
            energy_drift: opt(9, "energy_drift")?,
            status: crate::run::RunStatus::from_label(f[10]).ok_or_else(|| {
                bad(
                    n,
                    format!("status: expected ok or unstable, got '{}'", f[10]),
                )
            })?,
        });
    }
    Ok(rows)
}

/// Shard directory `d`'s `shard.json` (and its path) with the rows of its `sweep.csv`, one
/// per case it lists.
fn read_shard(d: &Path) -> Result<(PathBuf, ShardFile, Vec<SweepRow>)> {
    let sp = d.join("shard.json");
    let text = std::fs::read_to_string(&sp).map_err(|source| Error::Read {
        file: sp.clone(),
        source,
    })?;
    let sf: ShardFile = serde_json::from_str(&text)
        .map_err(|e| Error::invalid(&sp, "(document)", e.to_string()))?;
    let rows = read_rows(&d.join("sweep.csv"))?;
    if rows.len() != sf.cases.len() {
        return Err(Error::invalid(
            d.join("sweep.csv"),
            "(rows)",
            format!(
                "{} rows but shard.json lists {} cases",
                rows.len(),
                sf.cases.len()
            ),
        ));
    }
    Ok((sp, sf, rows))
}

/// Refuses shard `sf` (read from `sp`) unless it belongs to the sweep of the first shard `f`
/// and agrees with it on the shard count.
fn check_same_sweep(f: &ShardFile, sf: &ShardFile, sp: &Path) -> Result<()> {
    if f.plan != sf.plan || f.reference != sf.reference || f.floors != sf.floors {
        return Err(Error::invalid(
            sp,
            "plan",
            "this shard belongs to a different sweep (plan, reference or grid differ)",
        ));
    }
    if f.shard.count != sf.shard.count {
        return Err(Error::invalid(
            sp,
            "shard.count",
            format!(
                "{} but the first shard says {}",
                sf.shard.count, f.shard.count
            ),
        ));
    }
    Ok(())
}

/// Joins the shard directories of one sweep into the full result (rows in case order and
/// the summary); errors name the directory and what does not match.
pub fn merge(dirs: &[PathBuf]) -> Result<SweepResult> {
    if dirs.is_empty() {
        return Err(Error::option("merge", "give at least one shard directory"));
    }
    let mut first: Option<ShardFile> = None;
    let mut slots: Vec<Option<SweepRow>> = Vec::new();
    let mut seen: Vec<bool> = Vec::new();
    for d in dirs {
        let (sp, sf, rows) = read_shard(d)?;
        match &first {
            None => {
                slots = vec![None; sf.plan.case_count()];
                seen = vec![false; sf.shard.count];
                first = Some(sf.clone());
            }
            Some(f) => check_same_sweep(f, &sf, &sp)?,
        }
        if std::mem::replace(&mut seen[sf.shard.index], true) {
            return Err(Error::invalid(
                &sp,
                "shard.index",
                format!("shard {} given twice", sf.shard.index),
            ));
        }
        for (k, r) in sf.cases.iter().zip(rows) {
            if *k >= slots.len() || !sf.shard.owns(*k / p_of(&sf.plan)) {
                return Err(Error::invalid(
                    &sp,
                    "cases",
                    format!("case {k} is out of range or not this shard's"),
                ));
            }
            slots[*k] = Some(r);
        }
    }
    let f = first.expect("at least one shard");
    if let Some(missing) = seen.iter().position(|s| !s) {
        return Err(Error::option(
            "merge",
            format!("shard {missing}/{} is missing", f.shard.count),
        ));
    }
    // Every method's base grid must be there; extension cases are there when run.
    let p = f.plan.dts.len();
    let base = |k: usize| f.plan.base_start(&f.plan.methods[k / p]);
    if let Some(k) = (0..slots.len()).find(|&k| k % p >= base(k) && slots[k].is_none()) {
        return Err(Error::option("merge", format!("case {k} is missing")));
    }
    let (case_indices, rows): (Vec<usize>, Vec<SweepRow>) = slots
        .into_iter()
        .enumerate()
        .filter_map(|(k, r)| r.map(|r| (k, r)))
        .unzip();
    let mut res = SweepResult {
        case_indices,
        rows,
        cases: Vec::new(),
        reference: f.reference,
        floors: f.floors,
        saturation: f.saturation,
        summary: None,
        shard: None,
        plan: f.plan,
    };
    res.summary = Some(summarise(&res));
    Ok(res)
}

fn p_of(plan: &SweepPlan) -> usize {
    plan.dts.len().max(1)
}
