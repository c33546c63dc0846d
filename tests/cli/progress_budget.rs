//! Long commands without a terminal: progress lines at most every interval, and the time
//! budgets of `sweep`, `compare`, `stability`, `advise` and `framerate` through the binary.
//!
//! Oracles: the interval's definition (`SPRINGLAB_PROGRESS_INTERVAL`, default 10 s) and the
//! command's own counts (done ≤ total); a budget far below any run's cost leaves every method
//! out, naming the budget and the measured figure; a budget that is not a positive number is
//! refused naming the flag.

use crate::support::bin;

fn sweep(env: Option<&str>, extra: &[&str]) -> std::process::Output {
    let out = tempfile::tempdir().unwrap();
    let mut c = bin();
    c.args([
        "sweep",
        "scenarios/hanging_chain.toml",
        "--methods",
        "implicit_euler,implicit_midpoint",
        "--out",
    ])
    .arg(out.path())
    .args(extra);
    match env {
        Some(v) => c.env("SPRINGLAB_PROGRESS_INTERVAL", v),
        None => c.env_remove("SPRINGLAB_PROGRESS_INTERVAL"),
    };
    c.output().unwrap()
}

fn progress_lines(o: &std::process::Output) -> Vec<(u64, u64)> {
    String::from_utf8_lossy(&o.stderr)
        .lines()
        .filter_map(|l| l.strip_prefix("progress: sweep hanging_chain: "))
        .map(|l| {
            let counts = l.split(' ').next().unwrap();
            let (d, t) = counts.split_once('/').unwrap();
            (d.parse().unwrap(), t.parse().unwrap())
        })
        .collect()
}

#[test]
fn a_sweep_in_a_pipe_prints_progress_lines() {
    let o = sweep(Some("0.2"), &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lines = progress_lines(&o);
    assert!(!lines.is_empty(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(lines.iter().all(|(d, t)| d <= t && *t > 0));
}

#[test]
fn twin_a_sweep_shorter_than_the_default_interval_prints_none() {
    let o = sweep(None, &[]);
    assert!(o.status.success());
    assert!(progress_lines(&o).is_empty());
}

#[test]
fn a_tiny_budget_leaves_every_method_out_with_its_figure() {
    let o = sweep(None, &["--budget", "1e-6"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    for m in ["implicit_euler", "implicit_midpoint"] {
        let line = text
            .lines()
            .find(|l| l.starts_with(m) && l.contains("skipped"))
            .unwrap_or_else(|| panic!("{m} not left out:\n{text}"));
        assert!(
            line.contains("budget of 1.00e-6 s") && line.contains("ms per step"),
            "{line}"
        );
    }
}

#[test]
fn a_budget_that_is_not_positive_is_refused_naming_the_flag() {
    for bad in ["0", "-1", "inf", "nan"] {
        let o = sweep(None, &["--budget", bad]);
        assert!(!o.status.success(), "{bad}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("--budget") && err.lines().count() == 1,
            "{bad}: {err}"
        );
    }
}

fn compare(budget: &str) -> String {
    let out = tempfile::tempdir().unwrap();
    let o = bin()
        .args([
            "compare",
            "scenarios/anchored_spring.toml",
            "--methods",
            "rk4,implicit_euler",
            "--budget",
            budget,
            "--out",
        ])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(out.path().join("compare.csv")).unwrap()
}

#[test]
fn compare_leaves_out_what_exceeds_its_budget_with_the_figure() {
    // The budget covers the reference first: its closed form is priced at 1001 samples of
    // about 1.04 µs (1.04 ms), so 1.1 ms leaves less than either run's 0.2 ms or more.
    let csv = compare("1.1e-3");
    for m in ["rk4", "implicit_euler"] {
        let row = csv.lines().find(|l| l.starts_with(m)).unwrap();
        assert!(
            row.contains("skipped") && row.contains("ms per step"),
            "{row}"
        );
    }
}

#[test]
fn twin_compare_within_its_budget_runs_every_method() {
    let csv = compare("60");
    for m in ["rk4", "implicit_euler"] {
        let row = csv.lines().find(|l| l.starts_with(m)).unwrap();
        assert!(!row.contains("skipped"), "{row}");
    }
}

fn measure(cmd: &[&str], budget: &str, doc: &str) -> serde_json::Value {
    let out = tempfile::tempdir().unwrap();
    let o = bin()
        .args(cmd)
        .args(["--budget", budget, "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&std::fs::read(out.path().join(doc)).unwrap()).unwrap()
}

const STABILITY: [&str; 4] = [
    "stability",
    "scenarios/anchored_spring.toml",
    "--methods",
    "xpbd",
];

#[test]
fn stability_leaves_out_a_search_beyond_its_budget_with_the_figure() {
    let doc = measure(&STABILITY, "1e-9", "stability.json");
    let x = &doc["methods"][0];
    assert_eq!(x["verdict"], "not_analysed");
    let note = x["note"].as_str().unwrap();
    assert!(
        note.contains("left out") && note.contains("ms per step"),
        "{note}"
    );
}

#[test]
fn twin_stability_within_its_budget_searches() {
    let doc = measure(&STABILITY, "120", "stability.json");
    assert_eq!(doc["methods"][0]["decided_by"], "empirical_bisection");
}

const ADVISE: [&str; 6] = [
    "advise",
    "scenarios/anchored_spring.toml",
    "--tolerance",
    "1e-3",
    "--methods",
    "rk4",
];

#[test]
fn advise_leaves_out_a_method_beyond_its_budget_with_the_figure() {
    let doc = measure(&ADVISE, "1e-9", "advice.json");
    assert!(doc["method"].is_null());
    let text = doc.to_string();
    assert!(
        text.contains("left out") && text.contains("ms per step"),
        "{text}"
    );
}

#[test]
fn twin_advise_within_its_budget_answers() {
    let doc = measure(&ADVISE, "120", "advice.json");
    assert_eq!(doc["method"], "rk4");
}

const FRAMERATE: [&str; 6] = [
    "framerate",
    "scenarios/anchored_spring.toml",
    "--methods",
    "rk4",
    "--hz",
    "60",
];

#[test]
fn framerate_leaves_out_a_search_beyond_its_budget_with_the_figure() {
    let doc = measure(&FRAMERATE, "1e-9", "framerate.json");
    let text = doc["skipped"].to_string();
    assert!(
        text.contains("left out") && text.contains("ms per substep"),
        "{text}"
    );
}

#[test]
fn twin_framerate_within_its_budget_searches() {
    let doc = measure(&FRAMERATE, "120", "framerate.json");
    assert!(doc["skipped"].as_array().unwrap().is_empty(), "{doc}");
}

/// `compare` of the hanging chain at 1/60 s × 1024 substeps with rapier_impulse, under `budget`
/// (none: the default), its compare.csv row of the method.
fn substepped_engine_row(budget: Option<&str>) -> String {
    let out = tempfile::tempdir().unwrap();
    let mut c = bin();
    c.args([
        "compare",
        "scenarios/hanging_chain.toml",
        "--dt",
        "1/60",
        "--substeps",
        "1024",
        "--methods",
        "rapier_impulse",
        "--out",
    ])
    .arg(out.path());
    if let Some(b) = budget {
        c.args(["--budget", b]);
    }
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.path().join("compare.csv")).unwrap();
    csv.lines()
        .find(|l| l.starts_with("rapier_impulse"))
        .unwrap()
        .to_string()
}

// Oracle: the engine's cost model prices a frame of 1024 substeps at 6.14 ms, so the run's 120
// frames cost about 0.74 s: far inside the default budget of 120 s when the substeps are
// counted once, far outside it (about 755 s) when counted twice.
#[test]
fn a_substepped_engine_compare_runs_under_the_default_budget() {
    let row = substepped_engine_row(None);
    assert!(!row.contains("skipped"), "{row}");
}

#[test]
fn twin_a_substepped_engine_compare_past_its_budget_is_left_out_with_the_figure() {
    let row = substepped_engine_row(Some("0.5"));
    assert!(
        row.contains("skipped")
            && row.contains("about 0.737 s")
            && row.contains("6.14 ms per frame"),
        "{row}"
    );
}
