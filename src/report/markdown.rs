//! `README.md` of the report: the overview table and verdicts in Markdown, for code hosts.

use super::finite::cell;
use super::html::{drift_cell, evals_cell, order_cell, stable_cell, status_cell};
use super::summary::Summary;
use super::verdict::{dt_words, limit_words};

fn md(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The Markdown overview: the same front table and per-scene tables as `index.html`.
pub fn readme(sum: &Summary) -> String {
    let mut out = String::from("# springlab report\n\nEvery shipped scene run through every method that applies, against a trusted reference. Open [index.html](index.html) for the plots; each scene page names the documents behind its numbers and the command that re-creates each; numbers in [summary.json](summary.json). Regenerate with `springlab report`.\n\n");
    if sum.quick {
        out += "_Quick pass (`--quick`): coarse sweeps, theory-only stability; numbers are indicative only._\n\n";
    }
    out += "## What to use\n\n| scene | advised method and step (stated tolerance) | stable steps | blew up at the scene's step |\n|---|---|---|---|\n";
    for s in &sum.scenes {
        let pick = match &s.pick {
            Some(p) => match (&p.integrator, p.dt) {
                (Some(m), Some(dt)) => format!(
                    "**{}** at dt = {} (error {} m ≤ {} m over {} s)",
                    md(m),
                    dt_words(dt),
                    cell(p.verified_error, 2),
                    cell(Some(p.tolerance), 2),
                    cell(Some(p.horizon), 3)
                ),
                _ => format!("nothing meets {} m on the grid", cell(Some(p.tolerance), 2)),
            },
            None => "no advice (no candidate applies)".into(),
        };
        let limits: Vec<String> = s
            .backends
            .iter()
            .filter(|b| b.stability.is_some())
            .map(|b| format!("{}: {}", md(&b.backend), md(&limit_words(b))))
            .collect();
        let blew: Vec<String> = s
            .backends
            .iter()
            .filter(|b| b.status != "ok")
            .map(|b| format!("{} at t = {} s", md(&b.backend), cell(b.blowup_time, 3)))
            .collect();
        out += &format!(
            "| [{}]({}) | {pick} | {} | {} |\n",
            md(&s.scene),
            s.page,
            limits.join("<br>"),
            if blew.is_empty() {
                "none".into()
            } else {
                blew.join("<br>")
            }
        );
    }
    out += "\n## All methods at each scene's step\n\n";
    for s in &sum.scenes {
        out += &format!("### [{}]({})\n\n{}\n\n", md(&s.scene), s.page, s.verdict);
        out += "| backend | order | status | max position error (m) | max energy error | observed order | stable step | force evaluations | wall time (ms) |\n|---|---:|---|---:|---:|---:|---|---:|---:|\n";
        for b in &s.backends {
            out += &format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                md(&b.backend),
                b.order,
                md(&status_cell(b)),
                cell(b.max_position_error, 2),
                drift_cell(b.max_energy_drift),
                order_cell(b),
                md(&stable_cell(b)),
                evals_cell(b),
                cell(Some(b.wall_seconds * 1e3), 3)
            );
        }
        out += "\n";
    }
    if !sum.failed.is_empty() {
        out += "## Scenarios that could not be reported\n\n";
        for (f, e) in &sum.failed {
            out += &format!("- `{f}`: {}\n", md(e));
        }
    }
    out
}
