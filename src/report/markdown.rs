//! `README.md` of the report: the overview table and verdicts in Markdown, for code hosts.

use super::finite::cell;
use super::html::{drift_cell, stable_cell, status_cell};
use super::summary::Summary;

fn md(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The Markdown overview.
pub fn readme(sum: &Summary) -> String {
    let mut out = String::from("# springlab report\n\nEvery shipped scene run through every integrator that applies, against a trusted reference. Open [index.html](index.html) for the plots; numbers in [summary.json](summary.json). Regenerate with `springlab report`.\n\n");
    if sum.quick {
        out += "_Quick pass (`--quick`): short runs and coarse sweeps; numbers are indicative only._\n\n";
    }
    out += "| scene | backend | status | max position error (m) | max energy drift | fitted order | stable step | force evaluations | wall time (ms) |\n|---|---|---|---:|---:|---:|---|---:|---:|\n";
    for s in &sum.scenes {
        for b in &s.backends {
            out += &format!(
                "| [{}]({}) | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                md(&s.scene),
                s.page,
                md(&b.backend),
                md(&status_cell(b)),
                cell(b.max_position_error, 2),
                drift_cell(b.max_energy_drift),
                cell(b.convergence_slope, 3),
                md(&stable_cell(b)),
                b.force_evals,
                cell(Some(b.wall_seconds * 1e3), 3)
            );
        }
    }
    out += "\n## Verdicts\n\n";
    for s in &sum.scenes {
        out += &format!("### [{}]({})\n\n{}\n\n", md(&s.scene), s.page, s.verdict);
    }
    if !sum.failed.is_empty() {
        out += "## Scenarios that could not be reported\n\n";
        for (f, e) in &sum.failed {
            out += &format!("- `{f}`: {}\n", md(e));
        }
    }
    out
}
