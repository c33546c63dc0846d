//! HTML pages: the overview (`index.html`) and one page per scene. Self-contained: inline
//! CSS, no scripts, no web fonts; images and data are relative links next to the page.

use super::finite::cell;
use super::summary::{MethodRow, SceneSummary, Summary};
use super::verdict::{dt_words, front_row};
use crate::measure::metric_table::PENETRATION_MAX;
use crate::measure::stability::StabilityReport;
use crate::measure::study::SceneStudy;

/// One chart on a scene page.
#[derive(Debug, Clone)]
pub struct Figure {
    /// File stem: `<stem>.svg` and `<stem>.csv` sit next to the page.
    pub stem: String,
    /// Heading.
    pub title: String,
    /// What the chart shows and how to read it.
    pub caption: String,
}

/// Escapes text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const CSS: &str = "body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;max-width:1280px;margin:1.5em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.6em;margin-bottom:.2em}h2{margin-top:1.6em;border-bottom:1px solid #ddd;padding-bottom:.2em}
table{border-collapse:collapse;margin:.8em 0;font-size:.92em}th,td{border:1px solid #ccc;padding:.3em .6em;text-align:right}
th{background:#f2f2f2}td.l,th.l{text-align:left}tr.unstable td{background:#fde8e6}
p.verdict{background:#f5f8ff;border-left:4px solid #4a7bd0;padding:.7em 1em}
img.fare{width:300px;border:1px solid #e3e3e3;margin-top:.3em}figure{margin:1.2em 0}figure img{max-width:100%;border:1px solid #e3e3e3}figcaption{font-size:.9em;color:#444;margin-top:.3em}
figure.pb{display:inline-block;margin:.3em;vertical-align:top;width:242px}figure.pb canvas{border:1px solid #e3e3e3}
.note{color:#555;font-size:.9em}code{background:#f3f3f3;padding:0 .2em}";

pub(crate) fn page(title: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>\n{CSS}\n</style>\n</head>\n<body>\n{body}\n</body>\n</html>\n",
        esc(title)
    )
}

fn method_rows(s: &SceneSummary) -> String {
    s.methods
        .iter()
        .map(|b| super::method_table::html_row(b, esc))
        .collect()
}

fn documents(s: &SceneSummary) -> String {
    let mut out = String::from("<h2>Documents</h2>\n<p class=\"note\">Every number on this page comes from these files, written by the commands beside them; re-running a command gives the same file, byte for byte; the measured wall times are apart, in <a href=\"timing.json\">timing.json</a>.</p>\n<table>\n<tr><th class=\"l\">document</th><th class=\"l\">command</th></tr>\n");
    for d in &s.documents {
        out += &format!(
            "<tr><td class=\"l\"><a href=\"{f}\">{f}</a></td><td class=\"l\"><code>{}</code></td></tr>\n",
            esc(&d.command),
            f = esc(&d.file)
        );
    }
    out + "</table>\n"
}

fn stability_table(st: &StabilityReport) -> String {
    let mut out = format!("<h2>Stability</h2>\n<p class=\"note\">From <a href=\"stability/stability.json\">stability/stability.json</a>: ω_max = {} rad/s. Theory: {}. Empirical: a run of {} s is stable when its energy balance stays bounded: unstable once it diverges, rises past {}× the scene's energy scale, keeps doubling window after window, stays ten scales above its start, or passes ten scales after growing tenfold over each of the run's last three octaves.</p>\n<table>\n<tr><th class=\"l\">method</th><th class=\"l\">verdict</th><th>largest stable step (s)</th><th>h·ω_max</th><th class=\"l\">decided by</th><th>theory limit (s)</th><th>empirical limit (s)</th><th class=\"l\">statement</th></tr>\n",
        cell(Some(st.omega_max), 4), esc(&st.theory_criterion), cell(Some(st.empirical_criterion.horizon), 3), cell(Some(st.empirical_criterion.blowup_factor), 2));
    for i in &st.methods {
        out += &format!(
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td></tr>\n",
            esc(&i.method),
            esc(i.verdict.words()),
            cell(i.max_stable_dt, 4),
            cell(i.h_omega, 4),
            esc(i.decided_by.name()),
            cell(i.theory_max_stable_dt, 4),
            cell(i.empirical.as_ref().and_then(|e| e.max_stable_dt), 4),
            esc(&match &i.note {
                Some(n) => format!("{} ({n})", i.statement),
                None => i.statement.clone(),
            })
        );
    }
    out + "</table>\n"
}

fn order_table(s: &SceneSummary) -> String {
    let rows: Vec<&MethodRow> = s
        .methods
        .iter()
        .filter(|b| b.observed_order.is_some() || b.order_note.is_some())
        .collect();
    if rows.is_empty() {
        return String::new();
    }
    let mut out = String::from("<h2>Convergence orders</h2>\n<p class=\"note\">From <a href=\"sweep/summary.json\">sweep/summary.json</a>: the slope of log error against log dt over each method's asymptotic range, or why there is none.</p>\n<table>\n<tr><th class=\"l\">method</th><th>theoretical order</th><th>observed order</th><th class=\"l\">reason when none</th></tr>\n");
    for b in rows {
        out += &format!(
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td></tr>\n",
            esc(&b.method),
            b.order,
            super::method_table::order_cell(b),
            esc(b.order_note.as_deref().unwrap_or(""))
        );
    }
    out + "</table>\n"
}

/// A scene's page.
pub fn scene_page(
    s: &SceneSummary,
    st: &SceneStudy,
    figures: &[Figure],
    sections: &[String],
    notes: &[String],
) -> String {
    let mut body = format!(
        "<p><a href=\"../index.html\">← all scenes</a></p>\n<h1>{}</h1>\n<p>{}</p>\n<p class=\"verdict\">{}</p>\n",
        esc(&s.scene),
        esc(&s.description),
        esc(&s.verdict)
    );
    body += &format!(
        "<h2>Comparison at dt = {} over {} s</h2>\n<p class=\"note\">From <a href=\"compare/summary.json\">compare/summary.json</a> and <a href=\"compare/compare.csv\">compare/compare.csv</a>. Reference: {}. Position error is the largest distance of any particle from the reference; energy error is |E(t) − E(0)| relative to the scene's energy scale, E the total account (kinetic + gravity + elastic + dissipated − injected); energy drift rate is the least-squares slope of E(t) − E(0) in joules per second; strain max is the largest |l/l0 − 1| of any spring or rod over the run.</p>\n<table>\n<tr>{}</tr>\n{}</table>\n",
        esc(&dt_words(s.dt)),
        cell(Some(s.duration), 3),
        esc(&s.reference),
        super::method_table::html_head(),
        method_rows(s)
    );
    body += &stability_table(&st.stability);
    body += &order_table(s);
    if s.methods.iter().any(|b| b.tunnelling.is_some()) {
        body += "<h2>Contacts</h2>\n<p class=\"note\">From <a href=\"compare/contacts.json\">compare/contacts.json</a>.</p>\n<table>\n<tr><th class=\"l\">method</th><th>mean measured restitution</th><th>mean specified restitution</th><th>deepest penetration (m)</th><th>tunnelling paths</th></tr>\n";
        for b in &s.methods {
            body += &format!(
                "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                esc(&b.method),
                cell(b.restitution_measured, 3),
                cell(b.restitution_expected, 3),
                cell(b.metrics.get(PENETRATION_MAX), 2),
                b.tunnelling.map_or("—".into(), |t| t.to_string())
            );
        }
        body += "</table>\n";
    }
    if !s.skipped.is_empty() {
        body += "<p class=\"note\">Not run on this scene:</p>\n<ul class=\"note\">\n";
        for (n, why) in &s.skipped {
            body += &format!("<li><code>{}</code>: {}</li>\n", esc(n), esc(why));
        }
        body += "</ul>\n";
    }
    for sec in sections {
        body += sec;
    }
    for f in figures {
        body += &format!(
            "<h2>{}</h2>\n<figure><img src=\"{stem}.svg\" alt=\"{}\"><figcaption>{} <a href=\"{stem}.csv\">Data (CSV)</a>.</figcaption></figure>\n",
            esc(&f.title),
            esc(&f.title),
            f.caption.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace("&lt;code&gt;", "<code>").replace("&lt;/code&gt;", "</code>"),
            stem = esc(&f.stem)
        );
    }
    body += &documents(s);
    if !notes.is_empty() {
        body += "<h2>Notes</h2>\n<ul class=\"note\">\n";
        for n in notes {
            body += &format!("<li>{}</li>\n", esc(n));
        }
        body += "</ul>\n";
    }
    page(&format!("springlab: {}", s.scene), &body)
}

/// The answer line of a scene on the front page: what to use, limits, blow-ups.
fn front_tr(s: &SceneSummary) -> String {
    let r = front_row(s);
    let lines = |v: &[String]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|x| esc(x)).collect::<Vec<_>>().join("<br>")
        }
    };
    let chart = s.game_rate_chart.as_ref().map_or(String::new(), |c| {
        format!(
            "<br><a href=\"{0}\"><img class=\"fare\" src=\"{0}\" alt=\"{1}: error against cost per frame at the game rate, Rapier as triangles, the answer ringed\"></a>",
            esc(c),
            esc(&s.scene)
        )
    });
    format!(
        "<tr><td class=\"l\"><a href=\"{}\">{}</a></td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}{chart}</td><td class=\"l\">{}</td><td class=\"l\">{}</td></tr>\n",
        esc(&s.page),
        esc(&s.scene),
        esc(&r.free),
        esc(&r.game),
        esc(&r.rapier),
        lines(&r.limits),
        lines(&r.blew)
    )
}

/// The overview page: per scene, what to use, each method's stability limit and what blew up;
/// then the full tables.
pub fn index_page(sum: &Summary) -> String {
    let mut body = String::from("<h1>springlab report</h1>\n<p>Every shipped scene run through every method that applies, against a trusted reference. Each scene page names the documents behind its numbers and the command that re-creates each. Regenerate with <code>springlab report</code>; machine-readable numbers in <a href=\"summary.json\">summary.json</a>.</p>\n");
    if sum.quick {
        body += "<p class=\"note\"><strong>Quick pass</strong> (<code>--quick</code>): coarse sweeps, theory-only stability; numbers are indicative only.</p>\n";
    }
    body += "<h2>What to use</h2>\n<table>\n<tr><th class=\"l\">scene</th><th class=\"l\">free step: method and step (what verified it)</th><th class=\"l\">game rate: method and substeps per frame</th><th class=\"l\">Rapier at the game rate (chart: every method, ▲ Rapier, ○ the answer)</th><th class=\"l\">stable steps</th><th class=\"l\">blew up at the scene's step</th></tr>\n";
    for s in &sum.scenes {
        body += &front_tr(s);
    }
    body += "</table>\n<p>How the answers are judged:</p>\n<ul>\n";
    for n in super::verdict::judging_notes(crate::measure::study::FRAMERATE_MAX_SUBSTEPS) {
        body += &format!("<li>{}</li>\n", esc(&n));
    }
    body += "</ul>\n";
    if let Some(ss) = &sum.small_steps {
        body += &format!(
            "<h2>Small Steps, replicated</h2>\n<p>n XPBD substeps × 1 iteration against 1 step × n iterations at 60 Hz: <a href=\"{}\">the page</a>.</p>\n<ul>\n",
            esc(&ss.page)
        );
        for v in &ss.verdicts {
            body += &format!("<li>{}</li>\n", esc(v));
        }
        body += "</ul>\n";
    }
    body += "<h2>All methods at each scene's step</h2>\n";
    for s in &sum.scenes {
        body += &format!(
            "<h3><a href=\"{}\">{}</a></h3>\n<p>{}</p>\n<table>\n<tr>{}</tr>\n{}</table>\n",
            esc(&s.page),
            esc(&s.scene),
            esc(&s.verdict),
            super::method_table::html_head(),
            method_rows(s)
        );
    }
    if !sum.failed.is_empty() {
        body += "<h2>Scenarios that could not be reported</h2>\n<ul>\n";
        for (f, e) in &sum.failed {
            body += &format!("<li><code>{}</code>: {}</li>\n", esc(f), esc(e));
        }
        body += "</ul>\n";
    }
    page("springlab report", &body)
}
