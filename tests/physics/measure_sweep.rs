//! Sweeps on the anchored spring: observed orders, thread-count independence, sharding.
//! Oracles: textbook global orders (Hairer, Nørsett & Wanner, *Solving ODEs I*: explicit,
//! symplectic and implicit Euler 1; explicit midpoint and Störmer–Verlet 2; classic RK4 4);
//! determinism and shard/merge equality are exact (bitwise) requirements.

use springlab::measure::sweep::{merge, run_sweep, write_sweep, Shard, SweepConfig};
use springlab::scenario::Scenario;

fn anchored() -> Scenario {
    Scenario::from_file("scenarios/anchored_spring.toml").unwrap()
}

fn config(methods: &[&str]) -> SweepConfig {
    SweepConfig {
        dt_min: Some(2e-4),
        dt_max: Some(2e-2),
        points: Some(9),
        duration: Some(2.0),
        repeat_short: false,
        common: springlab::measure::Common {
            methods: methods.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        },
        ..Default::default()
    }
}

#[test]
fn observed_orders_match_theory() {
    let scene = anchored();
    let names = [
        ("explicit_euler", 1.0),
        ("symplectic_euler", 1.0),
        ("implicit_euler", 1.0),
        ("rk2", 2.0),
        ("rk4", 4.0),
        ("velocity_verlet", 2.0),
        ("position_verlet", 2.0),
    ];
    let list: Vec<&str> = names.iter().map(|n| n.0).collect();
    let res = run_sweep(&scene, &config(&list)).unwrap();
    let sum = res.summary.unwrap();
    assert_eq!(sum.reference.kind.name(), "analytic");
    let mut report = String::new();
    for (name, p) in names {
        let s = sum.methods.iter().find(|s| s.method == name).unwrap();
        let q = s.observed_order.unwrap_or(f64::NAN);
        report += &format!("{name}: {q:.3} (theory {p}, {:?})\n", s.fit.dt_range);
        assert!((q - p).abs() <= 0.15, "{report}");
    }
    eprintln!("{report}");
}

/// `summary.json` without its `"command"`, whose `--out` names the folder it was written to.
fn without_command(text: &str) -> String {
    let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
    v.as_object_mut().unwrap().remove("command");
    v.to_string()
}

fn sweep_files(cfg: &SweepConfig, threads: usize) -> (String, String) {
    let scene = anchored();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let res = pool.install(|| run_sweep(&scene, cfg)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), &res).unwrap();
    (
        std::fs::read_to_string(dir.path().join("sweep.csv")).unwrap(),
        without_command(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()),
    )
}

#[test]
fn sweep_is_identical_with_one_and_two_threads() {
    let cfg = SweepConfig {
        points: Some(5),
        ..config(&[
            "symplectic_euler",
            "rk4",
            "implicit_euler",
            "explicit_euler",
        ])
    };
    let (c1, s1) = sweep_files(&cfg, 1);
    let (c2, s2) = sweep_files(&cfg, 2);
    // The wall times are in timing.json: the documents are equal byte for byte.
    assert_eq!(c1, c2);
    assert_eq!(s1, s2);
    assert_eq!(c1.lines().count(), 1 + 4 * 5);
}

#[test]
fn sharded_then_merged_equals_unsharded() {
    let cfg = SweepConfig {
        points: Some(5),
        ..config(&["symplectic_euler", "rk4", "velocity_verlet"])
    };
    let (c, s) = sweep_files(&cfg, 2);
    let scene = anchored();
    let root = tempfile::tempdir().unwrap();
    let mut dirs = Vec::new();
    for i in 0..3 {
        let sc = SweepConfig {
            shard: Some(Shard { index: i, count: 3 }),
            ..cfg.clone()
        };
        let res = run_sweep(&scene, &sc).unwrap();
        let d = root.path().join(format!("shard{i}"));
        write_sweep(&d, &res).unwrap();
        dirs.push(d);
    }
    dirs.reverse(); // order of the directories must not matter
    let merged = merge(&dirs).unwrap();
    let out = root.path().join("merged");
    write_sweep(&out, &merged).unwrap();
    let mc = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let ms = without_command(&std::fs::read_to_string(out.join("summary.json")).unwrap());
    assert_eq!(c, mc);
    assert_eq!(s, ms);
    // A missing shard is an error naming it.
    let err = merge(&dirs[..2]).unwrap_err().to_string();
    assert!(err.contains("missing"), "{err}");
}
