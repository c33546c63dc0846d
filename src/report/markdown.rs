//! `README.md` of the report: the overview table and verdicts in Markdown, for code hosts.

use super::summary::Summary;
use super::verdict::front_row;

fn md(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The Markdown overview: the same front table and per-scene tables as `index.html`.
pub fn readme(sum: &Summary) -> String {
    let mut out = String::from("# springlab report\n\nEvery shipped scene run through every method that applies, against a trusted reference. Open [index.html](index.html) for the plots; each scene page names the documents behind its numbers and the command that re-creates each; numbers in [summary.json](summary.json). Regenerate with `springlab report`.\n\n");
    if sum.quick {
        out += "_Quick pass (`--quick`): coarse sweeps, theory-only stability; numbers are indicative only._\n\n";
    }
    out += "## What to use\n\n| scene | free step: method and step (what verified it) | game rate: method and substeps per frame | Rapier at the game rate | stable steps | blew up at the scene's step |\n|---|---|---|---|---|---|\n";
    for s in &sum.scenes {
        let r = front_row(s);
        let lines = |v: &[String]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.iter().map(|x| md(x)).collect::<Vec<_>>().join("<br>")
            }
        };
        let chart = s
            .game_rate_chart
            .as_ref()
            .map_or(String::new(), |c| format!("<br>[chart]({c})"));
        out += &format!(
            "| [{}]({}) | {} | {} | {}{chart} | {} | {} |\n",
            md(&s.scene),
            s.page,
            md(&r.free),
            md(&r.game),
            md(&r.rapier),
            lines(&r.limits),
            lines(&r.blew)
        );
    }
    out += "\nHow the answers are judged:\n\n";
    for n in super::verdict::judging_notes(crate::measure::study::FRAMERATE_MAX_SUBSTEPS) {
        out += &format!("- {}\n", md(&n));
    }
    if let Some(ss) = &sum.small_steps {
        out += &format!(
            "\n## Small Steps, replicated\n\nn XPBD substeps × 1 iteration against 1 step × n iterations at 60 Hz: [the page]({}).\n\n",
            ss.page
        );
        for v in &ss.verdicts {
            out += &format!("- {}\n", md(v));
        }
    }
    out += "\n## All methods at each scene's step\n\n";
    for s in &sum.scenes {
        out += &format!("### [{}]({})\n\n{}\n\n", md(&s.scene), s.page, s.verdict);
        out += &super::method_table::markdown_head();
        for b in &s.methods {
            out += &super::method_table::markdown_row(b, md);
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
