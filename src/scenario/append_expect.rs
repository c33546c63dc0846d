//! Appending an `[expect]` table to a scenario file: how `advise --write-expect` holds a scene
//! to the answer it just verified. The file is rewritten atomically, and only when the result
//! still loads; a file that already has an `[expect]` table is left alone (an error).

use super::file::ExpectSpec;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Appends `spec` as an `[expect]` table to the scenario file at `path`, after a comment line
/// `comment` (say, the command that verified it); returns the path written. Fails, writing
/// nothing, when the file already has an `[expect]` table or would no longer load.
pub fn append_expect(path: &Path, spec: &ExpectSpec, comment: &str) -> Result<PathBuf> {
    let (raw, text) = super::parse::read_file(path)?;
    if raw.expect.is_some() {
        return Err(Error::invalid(
            path,
            "expect",
            "the file already has an [expect] table; remove it to write a new one",
        ));
    }
    #[derive(serde::Serialize)]
    struct Table<'a> {
        expect: &'a ExpectSpec,
    }
    let table = toml::to_string(&Table { expect: spec })
        .map_err(|e| Error::invalid(path, "expect", format!("cannot write the table: {e}")))?;
    let mut out = text;
    if !out.is_empty() && !out.ends_with('\n') {
        out.push('\n');
    }
    out.push('\n');
    for line in comment.lines() {
        out.push_str("# ");
        out.push_str(line);
        out.push('\n');
    }
    out.push_str(&table);
    super::Scenario::from_toml_str(&out, path)?;
    crate::output::write_atomic(path, out.as_bytes())
}
