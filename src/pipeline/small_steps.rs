//! The report's Small Steps page: its runs (`springlab small-steps` on the shipped stiff chain
//! and cloth), unless its folder already holds what these scenes produce, then the report's
//! writer.

use crate::error::Result;
use crate::measure::small_steps::{small_steps, SmallStepsConfig, DEFAULT_SCENES};
use crate::report::small_steps::{read_link, write_page, SmallStepsLink};
use crate::scenario::Scenario;
use std::path::Path;

/// Measures and writes `out/small_steps/` (documents, chart, page) when both scenes are in
/// `scenarios`; `None` otherwise (a report of other scenes has no such page). A folder that
/// already holds what these scenes produce is kept ([`crate::report::reuse`]), unless
/// `no_cache`.
pub fn small_steps_page(
    scenarios: &Path,
    out: &Path,
    no_cache: bool,
) -> Result<Option<SmallStepsLink>> {
    let paths: Vec<_> = DEFAULT_SCENES.iter().map(|s| scenarios.join(s)).collect();
    if !paths.iter().all(|p| p.is_file()) {
        return Ok(None);
    }
    let scenes = paths
        .iter()
        .map(Scenario::from_file)
        .collect::<Result<Vec<_>>>()?;
    let cfg = SmallStepsConfig::default();
    let inputs = crate::report::reuse::small_steps_inputs(&scenes, &cfg);
    if !no_cache && crate::report::reuse::unchanged(&out.join("small_steps"), &inputs) {
        if let Some(link) = read_link(out) {
            return Ok(Some(link));
        }
    }
    let doc = small_steps(&scenes, &cfg)?;
    write_page(out, &doc, &inputs).map(Some)
}
