//! The methods table of a scene, on its page and in `README.md`: one list of columns, each a
//! header, an alignment, whether the Markdown overview shows it, and the function that writes
//! its cell, so both tables take their columns, order and cells from one place.

use super::finite::cell;
use super::summary::MethodRow;
use super::verdict::limit_words;

/// One column of the methods table.
pub struct Column {
    /// The header as people read it.
    pub header: &'static str,
    /// Left-aligned (text), else right-aligned (numbers).
    pub left: bool,
    /// Shown in the Markdown overview too (the page shows every column).
    pub in_markdown: bool,
    /// The cell of one method's row, unescaped.
    pub cell: fn(&MethodRow) -> String,
}

/// The columns, in order.
pub const COLUMNS: [Column; 12] = [
    Column {
        header: "method",
        left: true,
        in_markdown: true,
        cell: |b| b.method.clone(),
    },
    Column {
        header: "order",
        left: false,
        in_markdown: true,
        cell: |b| b.order.to_string(),
    },
    Column {
        header: "status",
        left: true,
        in_markdown: true,
        cell: status_cell,
    },
    Column {
        header: "max position error (m)",
        left: false,
        in_markdown: true,
        cell: |b| cell(b.max_position_error, 2),
    },
    Column {
        header: "max energy error",
        left: false,
        in_markdown: true,
        cell: |b| drift_cell(b.max_energy_drift),
    },
    Column {
        header: "final energy change",
        left: false,
        in_markdown: false,
        cell: |b| drift_cell(b.final_energy_change),
    },
    Column {
        header: "energy drift rate (J/s)",
        left: false,
        in_markdown: false,
        cell: |b| cell(b.energy_drift_rate, 2),
    },
    Column {
        header: "strain max",
        left: false,
        in_markdown: true,
        cell: |b| cell(b.strain_max, 2),
    },
    Column {
        header: "observed order",
        left: false,
        in_markdown: true,
        cell: order_cell,
    },
    Column {
        header: "stable step",
        left: true,
        in_markdown: true,
        cell: stable_cell,
    },
    Column {
        header: "force evaluations",
        left: false,
        in_markdown: true,
        cell: evals_cell,
    },
    Column {
        header: "modelled time (ms)",
        left: false,
        in_markdown: true,
        cell: |b| cell(Some(b.modelled_seconds * 1e3), 3),
    },
];

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

/// Energy drift in percent.
pub fn drift_cell(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{}%", cell(Some(100.0 * v), 2)),
        _ => "—".into(),
    }
}

/// The HTML header row's cells.
pub fn html_head() -> String {
    COLUMNS
        .iter()
        .map(|c| {
            let class = if c.left { " class=\"l\"" } else { "" };
            format!("<th{class}>{}</th>", c.header)
        })
        .collect()
}

/// One method's HTML row, its cells escaped by `esc`.
pub fn html_row(b: &MethodRow, esc: fn(&str) -> String) -> String {
    let cells: String = COLUMNS
        .iter()
        .map(|c| {
            let class = if c.left { " class=\"l\"" } else { "" };
            format!("<td{class}>{}</td>", esc(&(c.cell)(b)))
        })
        .collect();
    format!("<tr class=\"{}\">{cells}</tr>\n", esc(b.status.label()))
}

/// The Markdown header and alignment rows.
pub fn markdown_head() -> String {
    let shown = || COLUMNS.iter().filter(|c| c.in_markdown);
    let head: Vec<&str> = shown().map(|c| c.header).collect();
    let align: Vec<&str> = shown()
        .map(|c| if c.left { "---" } else { "---:" })
        .collect();
    format!("| {} |\n|{}|\n", head.join(" | "), align.join("|"))
}

/// One method's Markdown row, its cells escaped by `md`.
pub fn markdown_row(b: &MethodRow, md: fn(&str) -> String) -> String {
    let cells: Vec<String> = COLUMNS
        .iter()
        .filter(|c| c.in_markdown)
        .map(|c| md(&(c.cell)(b)))
        .collect();
    format!("| {} |\n", cells.join(" | "))
}
