//! Reading TOML into [`ScenarioFile`], with the field path and line/column of any error.

use super::file::ScenarioFile;
use crate::error::{Error, Result};
use std::path::Path;

/// Line and column (1-based) of a byte offset in `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Parses scenario TOML; `file` is only used to label errors.
pub fn parse_toml(text: &str, file: &Path) -> Result<ScenarioFile> {
    let located = |e: &toml::de::Error| match e.span() {
        Some(span) => {
            let (l, c) = line_col(text, span.start);
            format!(", line {l}, column {c}")
        }
        None => String::new(),
    };
    let de = toml::de::Deserializer::parse(text).map_err(|e| Error::Parse {
        file: file.to_path_buf(),
        location: located(&e),
        field: "(document)".into(),
        message: e.message().trim().to_string(),
    })?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        Error::Parse {
            file: file.to_path_buf(),
            location: located(&inner),
            field: if path == "." || path.is_empty() {
                "(document)".into()
            } else {
                path
            },
            message: inner.message().trim().to_string(),
        }
    })
}

/// Largest scenario file read (bytes): far above any scene written by hand (generators make
/// the big ones from a few lines), and a bound on what a wrong path such as /dev/zero costs.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// Largest mesh file read (bytes).
pub const MAX_MESH_BYTES: u64 = 64 << 20;

/// Reads at most `limit` bytes of `path`: `Ok(None)` when the file holds more (it is never
/// read further, so a device that never ends costs `limit` bytes).
pub fn read_limited(path: &Path, limit: u64) -> std::io::Result<Option<Vec<u8>>> {
    use std::io::Read;
    let mut buf = Vec::new();
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut buf)?;
    Ok((buf.len() as u64 <= limit).then_some(buf))
}

/// Reads and parses a scenario file.
pub fn read_file(path: &Path) -> Result<(ScenarioFile, String)> {
    let bytes = read_limited(path, MAX_SCENE_BYTES)
        .map_err(|source| Error::Read {
            file: path.to_path_buf(),
            source,
        })?
        .ok_or_else(|| Error::Parse {
            file: path.to_path_buf(),
            location: String::new(),
            field: "(document)".into(),
            message: format!(
                "larger than the limit of {} MiB for a scenario file: is this a scenario file?",
                MAX_SCENE_BYTES >> 20
            ),
        })?;
    let text = String::from_utf8(bytes).map_err(|e| Error::Parse {
        file: path.to_path_buf(),
        location: String::new(),
        field: "(document)".into(),
        message: format!(
            "not UTF-8 text (invalid byte at offset {}): is this a scenario file?",
            e.utf8_error().valid_up_to()
        ),
    })?;
    Ok((parse_toml(&text, path)?, text))
}
