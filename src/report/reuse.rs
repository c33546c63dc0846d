//! A report does not study again what has not changed: each scene folder (and the Small Steps
//! folder) holds [`INPUTS_FILE`], the digest of everything that produced it (the scene as
//! loaded, meshes included; the report's options; the program's own bytes). When a folder's
//! digest matches, its documents are kept as they are and its summary is read back from its
//! `results.json`; any change to the scene, the options or the program studies it again, and
//! `report --no-cache` studies every scene whatever the digests say.
//!
//! The digest file is written inside the folder's transaction, so it is present only with the
//! documents it describes: a folder swapped in whole, never half a folder under a new digest.

use super::generate::ReportOptions;
use super::summary::SceneSummary;
use crate::error::Result;
use crate::output::digest::{digest, program_digest};
use crate::scenario::Scenario;
use std::path::Path;

/// The digest file of a report folder.
pub const INPUTS_FILE: &str = "inputs.txt";

/// The text of a folder's digest file for `what` (a description of every input).
fn inputs_text(what: &str) -> String {
    format!(
        "{}\nDigest of the inputs that produced this folder (scene, report options, program); \
         `springlab report` keeps the folder while they are unchanged (--no-cache studies it \
         again).\n",
        digest(&[what.as_bytes(), program_digest().as_bytes()])
    )
}

/// The digest file's text for a scene studied with `opts`.
pub fn scene_inputs(scene: &Scenario, opts: &ReportOptions) -> String {
    let methods = opts.registry.names();
    inputs_text(&format!(
        "scene {scene:?}\nquick {}\nenergy_terms {}\nblowup {:?}\nmethods {methods:?}",
        opts.quick, opts.energy_terms, opts.blowup_factor
    ))
}

/// The digest file's text for the Small Steps page over `scenes` with its settings `cfg`.
pub fn small_steps_inputs(scenes: &[Scenario], cfg: &impl std::fmt::Debug) -> String {
    inputs_text(&format!("small steps {scenes:?}\nsettings {cfg:?}"))
}

/// True when `folder` holds a digest file equal to `inputs`.
pub fn unchanged(folder: &Path, inputs: &str) -> bool {
    std::fs::read_to_string(folder.join(INPUTS_FILE)).is_ok_and(|t| t == inputs)
}

/// The summary of scene folder `folder` when its digest file equals `inputs` (its wall times
/// put back from its `timing.json`); None when anything differs or cannot be read, so the
/// scene is studied again.
pub fn reusable_scene(folder: &Path, inputs: &str) -> Option<SceneSummary> {
    if !unchanged(folder, inputs) {
        return None;
    }
    let text = crate::output::read_document(folder.join("results.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// Writes `inputs` as `folder`'s digest file (inside the folder's transaction).
pub fn write_inputs(folder: &Path, inputs: &str) -> Result<()> {
    crate::output::write_atomic(folder.join(INPUTS_FILE), inputs.as_bytes())?;
    Ok(())
}
