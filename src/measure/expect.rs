//! Holding a scene to its answer: the `[expect]` table's run against the reference, one row per
//! expectation (what is expected, what was measured, pass or fail), and those rows as JUnit XML
//! for a CI server.
//!
//! The run is the one `compare` makes for a single method, so a number here is the number
//! `compare --methods NAME --dt FRAME --substeps N` prints.

use super::compare::{compare, CompareConfig};
use super::probe::sig3;
use crate::error::Result;
use crate::scenario::{Expect, Scenario};

/// One expectation of one scene: the line of the table and one JUnit testcase.
#[derive(Debug, Clone, PartialEq)]
pub struct ExpectRow {
    /// The scene as named on the command line (its file path): the JUnit classname.
    pub scene: String,
    /// Which expectation, e.g. `max_strain`: the JUnit testcase name, the same whatever its
    /// limit, so a CI server's history of a test case survives a change of limit.
    pub name: String,
    /// What is expected, e.g. `max_strain ≤ 0.05`, as the table prints it (the limit is also
    /// in the failure message).
    pub expectation: String,
    /// What was measured, or why there is no number.
    pub measured: String,
    /// Why it failed (the JUnit failure message); `None` when it passed or was skipped.
    pub failure: Option<String>,
    /// True for a scene with no `[expect]` table: listed, neither passed nor failed.
    pub skipped: bool,
}

impl ExpectRow {
    /// True when the expectation held (or there was none to hold).
    pub fn passed(&self) -> bool {
        self.failure.is_none()
    }
    /// `pass`, `FAIL` or `skipped`, as the table prints it.
    pub fn verdict(&self) -> &'static str {
        match (self.skipped, self.passed()) {
            (true, _) => "skipped",
            (false, true) => "pass",
            (false, false) => "FAIL",
        }
    }
}

/// The expectations of an `[expect]` table as written, one line each (what `check` shows).
pub fn expectations(e: &Expect) -> Vec<String> {
    let mut out = Vec::new();
    if e.stable == Some(true) {
        out.push("stable".to_string());
    }
    if let Some(x) = e.max_position_error {
        out.push(format!("max_position_error ≤ {x} m"));
    }
    if let Some(x) = e.max_strain {
        out.push(format!("max_strain ≤ {x}"));
    }
    if let Some(x) = e.max_energy_drift_rate {
        out.push(format!("max_energy_drift_rate ≤ {x} J/s"));
    }
    out
}

/// How the run is made, in words: method, frame step and substeps.
pub fn describe(e: &Expect) -> String {
    format!(
        "{} at dt = {} s ({} Hz) × {} substep{} per frame",
        e.method,
        sig3(e.frame_dt),
        sig3(1.0 / e.frame_dt),
        e.substeps,
        if e.substeps == 1 { "" } else { "s" }
    )
}

/// A row for a scene that does not load: it always fails.
pub fn error_row(scene: &str, what: &str, why: &str) -> ExpectRow {
    ExpectRow {
        scene: scene.to_string(),
        name: what.to_string(),
        expectation: what.to_string(),
        measured: why.to_string(),
        failure: Some(why.to_string()),
        skipped: false,
    }
}

/// The row of a scene without an `[expect]` table: skipped, not failed, so a folder of scenes
/// of which only some carry expectations can be checked with one glob.
pub fn skipped_row(scene: &str) -> ExpectRow {
    ExpectRow {
        scene: scene.to_string(),
        name: "[expect] table".into(),
        expectation: "[expect] table".into(),
        measured: "no [expect] table".into(),
        failure: None,
        skipped: true,
    }
}

/// The config of the one-method comparison an expectation is measured with, its run and
/// reference held to `budget` (modelled seconds; `None`: none).
fn config(e: &Expect, budget: Option<f64>) -> CompareConfig {
    CompareConfig {
        dt: Some(e.frame_dt),
        frame_substeps: Some(e.substeps),
        series_points: 0,
        common: crate::measure::Common {
            methods: vec![e.method.clone()],
            budget_seconds: budget,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// A numeric check: `measured` against `limit`; a run with no number fails with `why`.
fn numeric(
    label: &str,
    expectation: String,
    measured: Measured,
    limit: f64,
) -> (String, String, Option<String>) {
    match measured {
        Ok((x, note)) => {
            let cell = format!("{}{note}", sig3(x));
            let failure = (x.is_nan() || x > limit).then(|| {
                format!(
                    "{label}: measured {} > limit {}{note}",
                    sig3(x),
                    crate::error::num(limit)
                )
            });
            (expectation, cell, failure)
        }
        Err(why) => (
            expectation,
            why.clone(),
            Some(format!(
                "{label} (limit {}): {}",
                crate::error::num(limit),
                why.trim_start_matches("—, ")
            )),
        ),
    }
}

/// Runs `scene`'s `[expect]` run against the reference and checks every expectation; `label`
/// names the scene in the rows (its path as given). A scene without `[expect]` gives one
/// skipped row saying so. With a `budget` (modelled seconds, as `compare --budget`), a
/// reference projected past it is an error naming `--budget`, and a run projected past what
/// the reference leaves fails every expectation with the figure.
///
/// The position error is compared over the reference's predictable horizon (compare's
/// `error_max_predictable`): when the reference is not predictable over the whole run, the
/// measured cell says up to when.
pub fn check_scene(scene: &Scenario, label: &str, budget: Option<f64>) -> Result<Vec<ExpectRow>> {
    let Some(e) = &scene.expect else {
        return Ok(vec![skipped_row(label)]);
    };
    let res = compare(scene, &config(e, budget))?;
    let case = res.entries.first().and_then(|en| en.result.clone());
    let skip = res
        .entries
        .first()
        .and_then(|en| en.skip_reason.clone())
        .unwrap_or_else(|| "not run".into());
    let not_ok = |c: &Option<super::case::CaseResult>| -> Option<String> {
        match c {
            None => Some(format!("—, {skip}")),
            Some(r) if !r.ok() => Some(format!(
                "—, run unstable at t = {} s",
                r.unstable_time.map_or("?".into(), sig3)
            )),
            Some(_) => None,
        }
    };
    let failed = not_ok(&case);
    let metrics = case.as_ref().and_then(|c| c.metrics.clone());
    let value = |f: &dyn Fn(&super::Metrics) -> f64| -> Measured {
        match (&failed, &metrics) {
            (Some(why), _) => Err(why.clone()),
            (None, Some(m)) => Ok((f(m), String::new())),
            (None, None) => Err("—, no metrics".into()),
        }
    };
    let mut checks: Vec<(String, String, Option<String>)> = Vec::new();
    if e.stable == Some(true) {
        checks.push(match &failed {
            None => ("stable".into(), "stable".into(), None),
            Some(why) => (
                "stable".into(),
                why.trim_start_matches("—, ").to_string(),
                Some(why.trim_start_matches("—, ").to_string()),
            ),
        });
    }
    if let Some(limit) = e.max_position_error {
        let measured = position_error(&res, e.frame_dt, &failed, metrics.as_ref());
        checks.push(numeric(
            "max_position_error",
            format!("max_position_error ≤ {} m", crate::error::num(limit)),
            measured,
            limit,
        ));
    }
    if let Some(limit) = e.max_strain {
        checks.push(numeric(
            "max_strain",
            format!("max_strain ≤ {}", crate::error::num(limit)),
            value(&|m| m.strain_max),
            limit,
        ));
    }
    if let Some(limit) = e.max_energy_drift_rate {
        checks.push(numeric(
            "max_energy_drift_rate",
            format!("max_energy_drift_rate ≤ {} J/s", crate::error::num(limit)),
            value(&|m| m.energy_drift_rate.abs()),
            limit,
        ));
    }
    Ok(rows_of(label, checks))
}

/// What a number of an expectation's run is: the number and a note beside it, or why there is
/// none.
type Measured = std::result::Result<(f64, String), String>;

/// The position error the `[expect]` run is held to (its frame step `frame_dt`): over the
/// reference's predictable horizon when that ends before the run (`failed`: why the run has no
/// number; `metrics`: the run's, when it has them).
fn position_error(
    res: &super::compare::CompareResult,
    frame_dt: f64,
    failed: &Option<String>,
    metrics: Option<&super::Metrics>,
) -> Measured {
    let horizon = res
        .reference
        .predictability_horizon
        .filter(|h| *h < res.duration);
    match (horizon, failed) {
        (_, Some(why)) => Err(why.clone()),
        (Some(h), None) if h < frame_dt => Err(format!(
            "—, the reference is not predictable past t = {} s, shorter than one frame",
            sig3(h)
        )),
        (horizon, None) => match (horizon, metrics) {
            (_, None) => Err("—, no metrics".into()),
            (None, Some(m)) => Ok((m.error_max, String::new())),
            (Some(h), Some(m)) => Ok((
                m.error_max_predictable,
                format!(
                    " (up to t = {} s: the reference is predictable only that far of {} s)",
                    sig3(h),
                    sig3(res.duration)
                ),
            )),
        },
    }
}

/// The rows of scene `label` from its checks (expectation, measured, failure), each named by
/// its expectation's first word.
fn rows_of(label: &str, checks: Vec<(String, String, Option<String>)>) -> Vec<ExpectRow> {
    checks
        .into_iter()
        .map(|(expectation, measured, failure)| ExpectRow {
            scene: label.to_string(),
            name: expectation
                .split_once(' ')
                .map_or(expectation.clone(), |(n, _)| n.to_string()),
            expectation,
            measured,
            failure,
            skipped: false,
        })
        .collect()
}

/// Text with the five XML special characters escaped, for attribute values and content.
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters other than tab and newline are not allowed in XML 1.0.
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// The rows as a JUnit XML document: one `testsuite` named `springlab expect`, one
/// `testcase` per row (classname the scene, name the expectation's name without its limit), a
/// `failure` where it failed (its message names the limit).
pub fn junit(rows: &[ExpectRow]) -> String {
    let failures = rows.iter().filter(|r| !r.passed()).count();
    let skipped = rows.iter().filter(|r| r.skipped).count();
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    out.push_str(&format!(
        "<testsuite name=\"springlab expect\" tests=\"{}\" failures=\"{failures}\" errors=\"0\" skipped=\"{skipped}\">\n",
        rows.len()
    ));
    for r in rows {
        let head = format!(
            "  <testcase classname=\"{}\" name=\"{}\"",
            xml_escape(&r.scene),
            xml_escape(&r.name)
        );
        match &r.failure {
            None if r.skipped => out.push_str(&format!(
                "{head}>\n    <skipped message=\"{}\"/>\n  </testcase>\n",
                xml_escape(&r.measured)
            )),
            None => out.push_str(&format!("{head}/>\n")),
            Some(why) => out.push_str(&format!(
                "{head}>\n    <failure message=\"{}\"/>\n  </testcase>\n",
                xml_escape(why)
            )),
        }
    }
    out.push_str("</testsuite>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn junit_escapes_and_counts() {
        let rows = vec![
            ExpectRow {
                scene: "a<&>\"'.toml".into(),
                name: "stable".into(),
                expectation: "stable".into(),
                measured: "stable".into(),
                failure: None,
                skipped: false,
            },
            error_row("b.toml", "scene loads", "cannot read"),
            skipped_row("c.toml"),
        ];
        let x = junit(&rows);
        assert!(x.contains("classname=\"a&lt;&amp;&gt;&quot;&apos;.toml\""));
        assert!(x.contains("tests=\"3\" failures=\"1\" errors=\"0\" skipped=\"1\""));
        assert_eq!(x.matches("<failure").count(), 1);
        assert_eq!(x.matches("<skipped").count(), 1);
    }
}
