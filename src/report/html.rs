//! HTML pages: the overview (`index.html`) and one page per scene. Self-contained: inline
//! CSS, no scripts, no web fonts; images and data are relative links next to the page.

use super::finite::cell;
use super::summary::{BackendSummary, SceneSummary, Summary};
use super::verdict::dt_words;

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
figure{margin:1.2em 0}figure img{max-width:100%;border:1px solid #e3e3e3}figcaption{font-size:.9em;color:#444;margin-top:.3em}
.note{color:#555;font-size:.9em}code{background:#f3f3f3;padding:0 .2em}";

fn page(title: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>\n{CSS}\n</style>\n</head>\n<body>\n{body}\n</body>\n</html>\n",
        esc(title)
    )
}

/// The stable step cell: `h·ω ≤ θ (dt ≤ …)`, `none` or `—`.
pub fn stable_cell(b: &BackendSummary) -> String {
    match (b.stable_h_omega, b.stable_dt) {
        (Some(h), Some(dt)) => format!("h·ω ≤ {} (dt ≤ {} s)", cell(Some(h), 2), cell(Some(dt), 2)),
        _ if b.unstable_at_every_scanned_step => "none scanned".into(),
        _ => "—".into(),
    }
}

/// The status cell: `ok` or `unstable at t = …`.
pub fn status_cell(b: &BackendSummary) -> String {
    match b.blowup_time {
        Some(t) => format!("unstable at t = {} s", cell(Some(t), 3)),
        None => b.status.clone(),
    }
}

/// Energy drift in percent.
pub fn drift_cell(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{}%", cell(Some(100.0 * v), 2)),
        _ => "—".into(),
    }
}

fn backend_rows(s: &SceneSummary, link: Option<&str>) -> String {
    let mut rows = String::new();
    for (k, b) in s.backends.iter().enumerate() {
        let scene_cell = match (k, link) {
            (0, Some(l)) => format!(
                "<td class=\"l\" rowspan=\"{}\"><a href=\"{}\">{}</a></td>",
                s.backends.len(),
                esc(l),
                esc(&s.scene)
            ),
            (_, Some(_)) => String::new(),
            (_, None) => String::new(),
        };
        rows += &format!(
            "<tr class=\"{}\">{scene_cell}<td class=\"l\">{}</td><td>{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td></tr>\n",
            esc(&b.status),
            esc(&b.backend),
            b.order,
            esc(&status_cell(b)),
            cell(b.max_position_error, 2),
            drift_cell(b.max_energy_drift),
            drift_cell(b.final_energy_change),
            cell(b.convergence_slope, 3),
            esc(&stable_cell(b)),
            b.force_evals,
            cell(Some(b.wall_seconds * 1e3), 3),
        );
    }
    rows
}

const TABLE_HEAD: &str = "<th class=\"l\">backend</th><th>order</th><th class=\"l\">status</th><th>max position error (m)</th><th>max energy drift</th><th>final energy change</th><th>fitted order</th><th class=\"l\">stable step</th><th>force evaluations</th><th>wall time (ms)</th>";

/// A scene's page.
pub fn scene_page(s: &SceneSummary, figures: &[Figure], notes: &[String]) -> String {
    let mut body = format!(
        "<p><a href=\"../index.html\">← all scenes</a></p>\n<h1>{}</h1>\n<p>{}</p>\n<p class=\"verdict\">{}</p>\n",
        esc(&s.scene),
        esc(&s.description),
        esc(&s.verdict)
    );
    body += &format!(
        "<h2>Comparison at dt = {} over {} s</h2>\n<p class=\"note\">Reference: {}. Position error is the RMS over free particles; energy drift is |E(t) − E(0)| divided by the scene's energy scale, E the total account (kinetic + gravity + elastic + dissipated − injected), which the exact solution keeps constant.</p>\n<table>\n<tr>{TABLE_HEAD}</tr>\n{}</table>\n",
        esc(&dt_words(s.dt)),
        cell(Some(s.duration), 3),
        esc(&s.reference),
        backend_rows(s, None)
    );
    if s.backends.iter().any(|b| b.tunnelling.is_some()) {
        body += "<h2>Contacts</h2>\n<table>\n<tr><th class=\"l\">backend</th><th>mean measured restitution</th><th>mean specified restitution</th><th>deepest penetration (m)</th><th>tunnelling paths</th></tr>\n";
        for b in &s.backends {
            body += &format!(
                "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                esc(&b.backend),
                cell(b.restitution_measured, 3),
                cell(b.restitution_expected, 3),
                cell(b.max_penetration, 2),
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
    for f in figures {
        body += &format!(
            "<h2>{}</h2>\n<figure><img src=\"{stem}.svg\" alt=\"{}\"><figcaption>{} <a href=\"{stem}.csv\">Data (CSV)</a>.</figcaption></figure>\n",
            esc(&f.title),
            esc(&f.title),
            esc(&f.caption),
            stem = esc(&f.stem)
        );
    }
    if !notes.is_empty() {
        body += "<h2>Notes</h2>\n<ul class=\"note\">\n";
        for n in notes {
            body += &format!("<li>{}</li>\n", esc(n));
        }
        body += "</ul>\n";
    }
    page(&format!("springlab: {}", s.scene), &body)
}

/// The overview page.
pub fn index_page(sum: &Summary) -> String {
    let mut body = String::from("<h1>springlab report</h1>\n<p>Every shipped scene run through every integrator that applies, against a trusted reference: accuracy, energy, stable step and cost. Regenerate with <code>springlab report</code>; machine-readable numbers in <a href=\"summary.json\">summary.json</a>.</p>\n");
    if sum.quick {
        body += "<p class=\"note\"><strong>Quick pass</strong> (<code>--quick</code>): short runs and coarse sweeps; numbers are indicative only.</p>\n";
    }
    body += &format!("<table>\n<tr><th class=\"l\">scene</th>{TABLE_HEAD}</tr>\n");
    for s in &sum.scenes {
        body += &backend_rows(s, Some(&s.page));
    }
    body += "</table>\n<h2>Verdicts</h2>\n";
    for s in &sum.scenes {
        body += &format!(
            "<h3><a href=\"{}\">{}</a></h3>\n<p>{}</p>\n",
            esc(&s.page),
            esc(&s.scene),
            esc(&s.verdict)
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
