//! The methods table of a scene, on its page and in `README.md`: one list of columns, each a
//! header, an alignment, whether the Markdown overview shows it, and what writes its cell (the
//! row's own function, or a metric of the metrics table in its page format), so both tables
//! take their columns, order and cells from one place.

use super::finite::{cell, percent};
use super::summary::MethodRow;
use super::verdict::limit_words;
use crate::measure::metric_table::{PageFormat, METRICS};

/// What a column's cell shows.
#[derive(Clone, Copy)]
pub enum Cell {
    /// A cell written by its own function from the row, unescaped.
    Own(fn(&MethodRow) -> String),
    /// A metric of the metrics table, by its row key, in its page format.
    Metric(&'static str, PageFormat),
}

/// One column of the methods table.
pub struct Column {
    /// The header as people read it.
    pub header: &'static str,
    /// Left-aligned (text), else right-aligned (numbers).
    pub left: bool,
    /// Shown in the Markdown overview too (the page shows every column).
    pub in_markdown: bool,
    /// What its cells show.
    pub cell: Cell,
}

impl Column {
    /// The cell of one method's row, unescaped.
    pub fn text(&self, b: &MethodRow) -> String {
        match self.cell {
            Cell::Own(f) => f(b),
            Cell::Metric(key, PageFormat::Significant(sig)) => cell(b.metrics.get(key), sig),
            Cell::Metric(key, PageFormat::Percent(sig)) => percent(b.metrics.get(key), sig),
        }
    }
}

/// A column of the row's own, left-aligned (text) or not, shown in the Markdown overview.
const fn own(header: &'static str, left: bool, cell: fn(&MethodRow) -> String) -> Column {
    Column {
        header,
        left,
        in_markdown: true,
        cell: Cell::Own(cell),
    }
}

/// The columns, in order: the method, its order and status, the metrics the metrics table
/// puts on the page (in its order), then the stability, cost and order columns.
pub fn columns() -> Vec<Column> {
    let mut cols = vec![
        own("method", true, |b| b.method.clone()),
        own("order", false, |b| b.order.to_string()),
        own("status", true, status_cell),
    ];
    cols.extend(METRICS.iter().filter_map(|m| {
        let page = m.page?;
        Some(Column {
            header: page.header,
            left: false,
            in_markdown: page.in_markdown,
            cell: Cell::Metric(m.row_key?, page.format),
        })
    }));
    cols.extend([
        own("observed order", false, order_cell),
        own("stable step", true, stable_cell),
        own("force evaluations", false, evals_cell),
        own("modelled time (ms)", false, |b| {
            cell(Some(b.modelled_seconds * 1e3), 3)
        }),
    ]);
    cols
}

/// The stable step cell: the stability report's limit (`dt ≤ … s (h·ω ≤ …)`, `any step`, …).
pub fn stable_cell(b: &MethodRow) -> String {
    match b.stable_h_omega {
        Some(h) => format!("{} (h·ω ≤ {})", limit_words(b), cell(Some(h), 3)),
        None => limit_words(b),
    }
}

/// The observed-order cell: the sweep's fitted order, or `—` (its reason is on the page).
pub fn order_cell(b: &MethodRow) -> String {
    match (b.observed_order, &b.order_note) {
        (Some(p), _) => cell(Some(p), 3),
        (None, Some(_)) => "none".into(),
        (None, None) => "—".into(),
    }
}

/// The force-evaluation cell: the count, or `—` for methods that never evaluate ours.
pub fn evals_cell(b: &MethodRow) -> String {
    b.force_evals.map_or("—".into(), |n| n.to_string())
}

/// The status cell: `ok` or `unstable at t = …`.
pub fn status_cell(b: &MethodRow) -> String {
    match b.blowup_time {
        Some(t) => format!("unstable at t = {} s", cell(Some(t), 3)),
        None => b.status.to_string(),
    }
}

/// The HTML header row's cells.
pub fn html_head() -> String {
    columns()
        .iter()
        .map(|c| {
            let class = if c.left { " class=\"l\"" } else { "" };
            format!("<th{class}>{}</th>", c.header)
        })
        .collect()
}

/// One method's HTML row, its cells escaped by `esc`.
pub fn html_row(b: &MethodRow, esc: fn(&str) -> String) -> String {
    let cells: String = columns()
        .iter()
        .map(|c| {
            let class = if c.left { " class=\"l\"" } else { "" };
            format!("<td{class}>{}</td>", esc(&c.text(b)))
        })
        .collect();
    format!("<tr class=\"{}\">{cells}</tr>\n", esc(b.status.label()))
}

/// The Markdown header and alignment rows.
pub fn markdown_head() -> String {
    let cols = columns();
    let shown = || cols.iter().filter(|c| c.in_markdown);
    let head: Vec<&str> = shown().map(|c| c.header).collect();
    let align: Vec<&str> = shown()
        .map(|c| if c.left { "---" } else { "---:" })
        .collect();
    format!("| {} |\n|{}|\n", head.join(" | "), align.join("|"))
}

/// One method's Markdown row, its cells escaped by `md`.
pub fn markdown_row(b: &MethodRow, md: fn(&str) -> String) -> String {
    let cells: Vec<String> = columns()
        .iter()
        .filter(|c| c.in_markdown)
        .map(|c| md(&c.text(b)))
        .collect();
    format!("| {} |\n", cells.join(" | "))
}
