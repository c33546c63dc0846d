//! The whole report as one library call: lock the folder, study and write every scene (two at a
//! time, beside the Small Steps page), then the overview, last. What a command line adds is
//! parsing; a library user gets the same report from [`build`].
//!
//! The overview never loses a scene because this report failed on it: a scene whose study or
//! writing failed keeps its earlier folder (scene folders are swapped in whole), and its earlier
//! row is carried into the new overview, marked as failed this time.

use super::scene::report_scene;
use super::small_steps::small_steps_page;
use crate::error::{Error, Result};
use crate::measure::sweep::Shard;
use crate::report::overview::{assemble, previous_summary};
use crate::report::shard::{write_shard, ReportShard};
use crate::report::summary::{SceneSummary, Summary};
use crate::report::{scenario_files, write_overview, ReportOptions};
use crate::scenario::Scenario;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

/// What to build.
#[derive(Debug, Clone)]
pub struct BuildConfig {
    /// Folder of scenario files (`*.toml`).
    pub scenarios: PathBuf,
    /// How every scene is studied and where the report goes (`opts.out`).
    pub opts: ReportOptions,
    /// Only the scenes of this shard (recorded under `out/shards/`, no overview).
    pub shard: Option<Shard>,
    /// Which program writes it (`summary.json`'s `generator`).
    pub generator: String,
}

/// What [`build`] wrote.
#[derive(Debug)]
pub enum Built {
    /// A whole report: its overview.
    Overview(Summary),
    /// One shard's scenes and the record for `report --merge`.
    Shard(ReportShard, PathBuf),
}

/// Studies and writes every scene of `cfg.scenarios` (or of its shard) under `cfg.opts.out`,
/// then the overview (or the shard's record). `say` receives one line per finished scene; a
/// progress bar is drawn where progress is shown (see [`crate::run::progress_bar`]).
/// Scenes that failed are listed in the overview's `failed` (the caller decides the exit).
pub fn build(cfg: &BuildConfig, say: &(dyn Fn(&str) + Sync)) -> Result<Built> {
    let out = &cfg.opts.out;
    // Shards of one report write disjoint scenes side by side: they share the folder.
    let _lock = match cfg.shard {
        Some(_) => crate::output::lock_dir_shared(out)?,
        None => crate::output::lock_dir(out)?,
    };
    let files: Vec<(usize, PathBuf)> = scenario_files(&cfg.scenarios)?
        .into_iter()
        .enumerate()
        .filter(|(k, _)| cfg.shard.is_none_or(|s| s.owns(*k)))
        .collect();
    if files.is_empty() {
        return Err(Error::option(
            "--scenarios",
            format!("{}: no scenario files (*.toml)", cfg.scenarios.display()),
        ));
    }
    let bar = crate::run::progress_bar(files.len() as u64, "report", true);
    let line = |l: &str| {
        if bar.is_hidden() {
            say(l)
        } else {
            bar.println(l)
        }
    };
    // The report-level Small Steps page (shard 0 of a sharded report) runs beside the scenes.
    let small_steps_here = cfg.shard.is_none_or(|s| s.index == 0) && !cfg.opts.quick;
    // Scenes are independent: they are studied concurrently (two at a time on two cores,
    // sharing rayon's pool with their own inner loops) and gathered in file order, so the
    // documents and the overview do not depend on which finished first.
    let (results, small_steps) = rayon::join(
        || {
            files
                .par_iter()
                .with_max_len(1)
                .map(|(k, f)| {
                    let t0 = Instant::now();
                    let _stage = crate::run::progress_stage(
                        format!(
                            "report {}",
                            f.file_stem().unwrap_or_default().to_string_lossy()
                        ),
                        true,
                    );
                    let res = Scenario::from_file(f).and_then(|s| report_scene(&s, &cfg.opts));
                    match &res {
                        Ok((s, false)) => line(&scene_line(s, t0.elapsed().as_secs_f64())),
                        Ok((s, true)) => line(&format!(
                            "report: {} kept: its scene, the flags and the program are unchanged (--no-cache studies it again)",
                            s.scene
                        )),
                        Err(e) => line(&format!("report: {}: {e}", f.display())),
                    }
                    let res = res.map(|(s, _)| s);
                    bar.inc(1);
                    (*k, f.display().to_string(), res.map_err(|e| e.to_string()))
                })
                .collect::<Vec<_>>()
        },
        || {
            small_steps_here
                .then(|| small_steps_page(&cfg.scenarios, out, cfg.opts.no_cache))
                .transpose()
        },
    );
    bar.finish_and_clear();
    let small_steps = match small_steps {
        Ok(link) => link.flatten(),
        Err(e) => {
            line(&format!("report: small steps: {e}"));
            crate::report::small_steps::read_link(out)
        }
    };
    if let Some(shard) = cfg.shard {
        let rec = ReportShard {
            shard,
            scenes: results
                .iter()
                .filter_map(|(k, _, r)| r.as_ref().ok().map(|s| (*k, s.scene.clone())))
                .collect(),
            failed: results
                .iter()
                .filter_map(|(k, f, r)| r.as_ref().err().map(|e| (*k, f.clone(), e.clone())))
                .collect(),
        };
        let p = write_shard(out, &rec)?;
        return Ok(Built::Shard(rec, p));
    }
    let previous = previous_summary(out);
    let outcomes = results.into_iter().map(|(_, f, r)| (f, r)).collect();
    let mut sum = assemble(&cfg.generator, cfg.opts.quick, outcomes, previous.as_ref());
    sum.small_steps = small_steps;
    write_overview(&sum, out)?;
    Ok(Built::Overview(sum))
}

fn scene_line(s: &SceneSummary, seconds: f64) -> String {
    let p = s.seconds;
    format!(
        "report: {} done in {seconds:.1} s (compare {:.1}, sweep {:.1}, stability {:.1}, advice {:.1}, frame rates {:.1})",
        s.scene, p.compare, p.sweep, p.stability, p.advice, p.framerate
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(name: &str, file: &str) -> SceneSummary {
        let mut s: SceneSummary = serde_json::from_value(serde_json::json!({
            "scene": name, "description": "", "dt": 0.01, "duration": 1.0, "reference": "",
            "omega_max": null, "answer": null, "methods": [], "skipped": [],
            "verdict": "Fine.", "page": format!("{name}/index.html"), "documents": [], "notes": []
        }))
        .unwrap();
        s.file = file.into();
        s
    }

    // Oracle: the overview's rule. A scene that failed now keeps its earlier row, marked, in
    // file order; a new scene that failed has no row; both are listed as failed; a legacy row
    // without a file name is recognised by its scene name.
    #[test]
    fn failed_scenes_keep_their_earlier_rows_marked() {
        let prev = assemble(
            "g",
            false,
            vec![
                ("s/a.toml".into(), Ok(scene("a", "a.toml"))),
                ("s/b.toml".into(), Ok(scene("b", ""))),
            ],
            None,
        );
        let now = assemble(
            "g",
            false,
            vec![
                ("s/a.toml".into(), Err("disk full".into())),
                ("s/b.toml".into(), Err("bad".into())),
                ("s/c.toml".into(), Err("new and bad".into())),
            ],
            Some(&prev),
        );
        let names: Vec<_> = now.scenes.iter().map(|s| s.scene.as_str()).collect();
        assert_eq!(names, ["a", "b"]);
        assert_eq!(now.scenes[0].failed_this_time.as_deref(), Some("disk full"));
        assert!(now.scenes[0]
            .verdict
            .starts_with("Kept from the previous report"));
        assert!(now.scenes[0].verdict.ends_with("Fine."));
        assert_eq!(now.failed.len(), 3);
        // Failing again does not stack the mark.
        let again = assemble(
            "g",
            false,
            vec![("s/a.toml".into(), Err("still".into()))],
            Some(&now),
        );
        assert_eq!(again.scenes[0].verdict, now.scenes[0].verdict);
    }
}
