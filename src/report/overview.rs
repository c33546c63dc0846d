//! The overview's rows from per-file outcomes: a scene whose study failed this time keeps the
//! earlier report's row, marked as failed, so the overview never loses a scene.

use super::summary::{SceneSummary, Summary};
use std::path::Path;

/// The scenario file's name, by which a later report recognises a scene it cannot load.
pub(crate) fn file_key(f: &Path) -> String {
    f.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// The earlier overview in `out`, when there is a readable one.
pub fn previous_summary(out: &Path) -> Option<Summary> {
    let text = crate::output::read_document(out.join("summary.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// The overview of per-file outcomes in file order. A failed file whose scene the `previous`
/// overview holds keeps that row, marked as failed this time (its folder is the earlier one);
/// every failure is also listed under `failed`.
pub fn assemble(
    generator: &str,
    quick: bool,
    outcomes: Vec<(String, std::result::Result<SceneSummary, String>)>,
    previous: Option<&Summary>,
) -> Summary {
    let mut sum = Summary {
        generator: generator.to_string(),
        quick,
        scenes: Vec::new(),
        failed: Vec::new(),
        small_steps: None,
    };
    for (file, res) in outcomes {
        match res {
            Ok(s) => sum.scenes.push(s),
            Err(e) => {
                let key = file_key(Path::new(&file));
                let stem = key.strip_suffix(".toml").unwrap_or(&key);
                let old = previous.and_then(|p| {
                    p.scenes.iter().find(|s| {
                        if s.file.is_empty() {
                            s.scene == stem
                        } else {
                            s.file == key
                        }
                    })
                });
                if let Some(old) = old {
                    let mut kept = old.clone();
                    if kept.failed_this_time.is_none() {
                        kept.verdict = format!(
                            "Kept from the previous report: this report could not study the scene (see below). {}",
                            kept.verdict
                        );
                    }
                    kept.failed_this_time = Some(e.clone());
                    sum.scenes.push(kept);
                }
                sum.failed.push((file, e));
            }
        }
    }
    sum
}
