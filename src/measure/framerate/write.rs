//! `framerate.csv` and `framerate.json`, written atomically.

use super::{FrameRun, Framerate, RateEntry, RowKind};
use crate::error::Result;
use crate::output::write_document;
use std::path::{Path, PathBuf};

/// The header of `framerate.csv`: two rows per method and rate (`one_substep`, `fewest`).
pub const FRAMERATE_HEADER: &str = "method,hz,row,substeps,status,meets_tolerance,error,max_position_error,energy_drift,modelled_seconds_per_frame,wall_seconds_per_frame,force_evals_per_frame,unstable_time,note";

fn csv_text(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn row(e: &RateEntry, kind: RowKind, r: Option<&FrameRun>) -> String {
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
    match r {
        Some(r) => format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            e.method,
            e.hz,
            kind.label(),
            r.substeps,
            r.status,
            r.meets_tolerance,
            o(r.error),
            o(r.max_position_error),
            o(r.energy_drift),
            o(r.modelled_seconds_per_frame),
            o(r.wall_seconds_per_frame),
            o(r.force_evals_per_frame),
            o(r.unstable_time),
            csv_text(r.unstable_reason.as_deref().unwrap_or("")),
        ),
        None => format!(
            "{},{},{},,not_reached,false,,,,,,,,{}",
            e.method,
            e.hz,
            kind.label(),
            csv_text(e.fewest_note.as_deref().unwrap_or("")),
        ),
    }
}

/// Writes `framerate.csv` and `framerate.json` into `dir` (with `--out dir` in the command).
pub fn write_framerate(dir: &Path, fr: &Framerate) -> Result<Vec<PathBuf>> {
    let mut csv = String::from(FRAMERATE_HEADER);
    csv.push('\n');
    for e in &fr.entries {
        csv.push_str(&row(e, RowKind::OneSubstep, Some(&e.one_substep)));
        csv.push('\n');
        csv.push_str(&row(e, RowKind::Fewest, e.fewest.as_ref()));
        csv.push('\n');
    }
    let doc = Framerate {
        head: fr.head.written_to(dir),
        ..fr.clone()
    };
    let mut json = serde_json::to_vec_pretty(&doc).expect("serialisable");
    json.push(b'\n');
    let mut files = write_document(dir.join("framerate.csv"), csv.as_bytes())?;
    files.extend(write_document(dir.join("framerate.json"), &json)?);
    Ok(files)
}
