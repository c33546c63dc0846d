//! One scene of the report: its study, unless its folder already holds what these inputs
//! produce, then the report's writers.

use crate::error::Result;
use crate::measure::study::{study, StudyConfig};
use crate::report::summary::SceneSummary;
use crate::report::ReportOptions;
use crate::scenario::Scenario;

/// Studies and writes one scene; a scene whose folder already holds what these inputs produce
/// is kept as it is ([`crate::report::reuse`]), unless `opts.no_cache`. The flag is true when the
/// folder was kept.
pub fn report_scene(scene: &Scenario, opts: &ReportOptions) -> Result<(SceneSummary, bool)> {
    if !opts.no_cache {
        let inputs = crate::report::reuse::scene_inputs(scene, opts);
        if let Some(sum) =
            crate::report::reuse::reusable_scene(&opts.out.join(&scene.name), &inputs)
        {
            return Ok((sum, true));
        }
    }
    let cfg = StudyConfig {
        quick: opts.quick,
        common: crate::measure::Common {
            registry: opts.registry.clone(),
            blowup_factor: opts.blowup_factor,
            ..Default::default()
        },
        ..Default::default()
    };
    let s = study(scene, &cfg)?;
    Ok((crate::report::write_scene(scene, &s, opts)?, false))
}
