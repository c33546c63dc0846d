//! The benchmark subcommands end to end on tiny cloths: the files they promise, one row per
//! method and size (bench-scaling) or per targeted ratio (bench-ratios), with finite positive
//! timings. Speed itself is not asserted here: speed claims live in `cargo bench` and in the
//! commands' own output, never in timed tests.

use crate::support::ok as springlab;
use std::path::Path;

/// Each `(ratio, numerator, denominator)` column triple of CSV row `r`: the ratio is positive
/// and finite and is the quotient of its own two columns (numbers are written in full, so the
/// quotient is exact).
fn assert_quotients(r: &[String], triples: &[(usize, usize, usize)]) {
    let col = |k: usize| -> f64 { r[k].parse().unwrap() };
    for &(ratio, num, den) in triples {
        assert!(col(ratio).is_finite() && col(ratio) > 0.0, "{r:?}");
        assert_eq!(col(ratio), col(num) / col(den), "{r:?}");
    }
}

fn csv_rows(p: &Path) -> Vec<Vec<String>> {
    let mut r = csv::Reader::from_path(p).unwrap();
    r.records()
        .map(|rec| rec.unwrap().iter().map(str::to_string).collect())
        .collect()
}

#[test]
fn bench_scaling_writes_one_row_per_method_and_size_and_a_plot() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().to_str().unwrap();
    springlab(&[
        "bench-scaling",
        "--sizes",
        "4,6",
        "--reps",
        "1",
        "--out",
        out,
    ]);
    let rows = csv_rows(&d.path().join("scaling.csv"));
    let methods = springlab::perf::methods_for(&springlab::perf::cloth(4));
    assert_eq!(rows.len(), 2 * methods.len(), "{rows:?}");
    for name in &methods {
        for n in ["4", "6"] {
            let row = rows
                .iter()
                .find(|r| r[0] == *name && r[1] == n)
                .unwrap_or_else(|| panic!("no row for {name} at {n}"));
            assert_eq!(row[7], "ok", "{row:?}");
            let t: f64 = row[5].parse().unwrap();
            assert!(t.is_finite() && t > 0.0, "{row:?}");
        }
    }
    let svg = std::fs::read_to_string(d.path().join("scaling.svg")).unwrap();
    assert!(svg.contains("<svg"));
}

#[test]
fn bench_ratios_writes_every_targeted_ratio_and_the_implicit_costs() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().to_str().unwrap();
    let stdout = springlab(&[
        "bench-ratios",
        "--rounds",
        "3",
        "--size",
        "6",
        "--thread-size",
        "6",
        "--implicit-sizes",
        "4,5",
        "--implicit-steps",
        "2",
        "--out",
        out,
    ]);
    let rows = csv_rows(&d.path().join("ratios.csv"));
    let measures: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        measures,
        [
            "step_vs_hand_loop",
            "rapier_frame_vs_step",
            "step_vs_best_loop",
            "step_vs_best_loop",
            "thread_speedup_forces",
            "thread_speedup_step"
        ]
    );
    for r in &rows {
        // The ratio of the minima and of the medians over the rounds, and the target judged on
        // the ratio of the minima.
        assert_quotients(r, &[(6, 3, 5), (9, 7, 8)]);
        let col = |k: usize| -> f64 { r[k].parse().unwrap() };
        // Over three rounds the minimum is at most the median, for each contender.
        assert!(col(3) <= col(7) && col(5) <= col(8), "{r:?}");
        let met = match r[10].split_once(' ') {
            Some(("<=", t)) => col(6) <= t.parse::<f64>().unwrap(),
            Some((">=", t)) => col(6) >= t.parse::<f64>().unwrap(),
            _ => panic!("target {:?}", r[10]),
        };
        assert_eq!(r[11], met.to_string(), "{r:?}");
    }
    let imp = csv_rows(&d.path().join("implicit.csv"));
    // Every implicit method at each size, in a `method` column, with its solver.
    let methods: Vec<(&str, &str)> = imp.iter().map(|r| (r[0].as_str(), r[2].as_str())).collect();
    let mut want = Vec::new();
    for n in ["4", "5"] {
        for m in [
            "implicit_euler",
            "implicit_midpoint",
            "bdf2",
            "linear_implicit_euler",
        ] {
            want.push((m, n));
        }
    }
    assert_eq!(methods, want);
    for r in &imp {
        assert_eq!(r[1], "block_jacobi_cg", "{r:?}");
        assert_eq!(r[22], "ok", "{r:?}");
        // The ratio to a symplectic step, from the minimum and from the median round.
        assert_quotients(r, &[(17, 6, 16), (20, 18, 19)]);
        let col = |k: usize| -> f64 { r[k].parse().unwrap() };
        assert!(col(6) <= col(18) && col(16) <= col(19), "{r:?}");
        let newton: f64 = r[8].parse().unwrap();
        let linear: f64 = r[9].parse().unwrap();
        let newton_max: f64 = r[11].parse().unwrap();
        let switches: f64 = r[12].parse().unwrap();
        let patch: f64 = r[13].parse().unwrap();
        assert!(
            newton_max >= newton && switches >= 0.0 && patch >= 0.0,
            "the hardest step takes at least the mean Newton count: {r:?}"
        );
        assert!(
            newton >= 1.0 && linear >= newton,
            "at least one Newton iteration per step, one linear iteration each: {r:?}"
        );
    }
    assert!(stdout.contains("implicit methods at dt = 1/60"));
}

#[test]
fn bench_ratios_takes_the_ic0_solver_and_reports_it() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().to_str().unwrap();
    springlab(&[
        "bench-ratios",
        "--rounds",
        "1",
        "--size",
        "6",
        "--thread-size",
        "6",
        "--no-rapier",
        "--implicit-sizes",
        "5",
        "--implicit-steps",
        "2",
        "--implicit-solver",
        "block_ic0_cg",
        "--out",
        out,
    ]);
    let imp = csv_rows(&d.path().join("implicit.csv"));
    assert_eq!(imp.len(), 4, "{imp:?}");
    for r in &imp {
        assert_eq!(r[1], "block_ic0_cg", "{r:?}");
        assert_eq!(r[22], "ok", "{r:?}");
        // One IC(0) factorisation per linear solve (Newton iteration).
        let newton: f64 = r[8].parse().unwrap();
        let factors: f64 = r[14].parse().unwrap();
        assert_eq!(factors, newton, "{r:?}");
    }
}
