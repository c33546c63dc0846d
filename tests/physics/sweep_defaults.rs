//! Default sweeps: the grid comes from the scene's dynamics, each method is refined until its
//! error is asymptotic, and no order outside the theoretical one is ever printed.
//!
//! Oracles: textbook global orders (Hairer, Nørsett & Wanner, *Solving ODEs I*: explicit,
//! symplectic and implicit Euler 1; explicit midpoint, velocity and position Verlet 2; classic
//! RK4 4); ω = √(k/m) for a particle on a spring to an anchor; shard/merge equality is exact.

use springlab::measure::sweep::{
    merge, run_sweep, step_grid, write_sweep, Shard, Stop, SweepConfig, SweepResult,
};
use springlab::scenario::Scenario;

const METHODS: [(&str, f64); 7] = [
    ("explicit_euler", 1.0),
    ("symplectic_euler", 1.0),
    ("implicit_euler", 1.0),
    ("rk2", 2.0),
    ("velocity_verlet", 2.0),
    ("position_verlet", 2.0),
    ("rk4", 4.0),
];

/// A particle on a spring to an anchor: m = 1 kg, k = 100 N/m (ω = 10 rad/s), c = 2 N·s/m
/// (ζ = c / (2mω) = 0.1), stretched 0.5 m, with a scene dt of 0.37 s (hω = 3.7: past every
/// explicit method's stability limit).
fn coarse_spring() -> Scenario {
    Scenario::from_toml_str(
        r#"
name = "coarse_spring"
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true
[[particle]]
position = [1.5, 0.0, 0.0]
mass = 1.0
[[spring]]
between = [0, 1]
stiffness = 100.0
rest_length = 1.0
damping = 2.0
[run]
dt = 0.37
duration = 4.0
"#,
        "coarse_spring.toml",
    )
    .unwrap()
}

/// A 30-particle rope pinned at one end, released horizontally under gravity: stiff springs
/// (ω_max in the hundreds of rad/s) and large nonlinear swings, so the coarse steps of the
/// grid are far from the asymptotic range.
fn rope() -> Scenario {
    Scenario::from_toml_str(
        r#"
name = "rope30"
[world]
gravity = [0.0, -9.81, 0.0]
[[chain]]
start = [0.0, 0.0, 0.0]
end = [1.5, 0.0, 0.0]
count = 30
mass = 0.02
stiffness = 400.0
damping = 0.02
fix = ["first"]
[run]
dt = 0.02
duration = 1.0
"#,
        "rope30.toml",
    )
    .unwrap()
}

fn config(names: &[&str]) -> SweepConfig {
    SweepConfig {
        repeat_short: false,
        common: springlab::measure::Common {
            methods: names.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Checks every method: an order within 0.15 of theory, or null with a reason whose fact is
/// verified from the rows (at the floor, out of budget, or not converging). Returns the number
/// of methods with an order and a printable table.
fn check_orders(res: &SweepResult) -> (usize, String) {
    let sum = res.summary.as_ref().unwrap();
    let plan = &res.plan;
    let p = plan.dts.len();
    let mut with_order = 0;
    let mut table = String::new();
    for (name, order) in METHODS {
        let s = sum.methods.iter().find(|s| s.method == name).unwrap();
        table += &format!(
            "{name}: {:?} ({:?}, {:?}) {:?}\n",
            s.observed_order, s.extension_stop, s.fit.reason, s.fit.note
        );
        let i = plan.methods.iter().position(|n| n == name).unwrap();
        let rows: Vec<(usize, &springlab::measure::sweep::SweepRow)> = res
            .case_indices
            .iter()
            .zip(&res.rows)
            .filter(|(k, _)| *k / p == i)
            .map(|(k, r)| (*k % p, r))
            .collect();
        let (jf, finest) = *rows.iter().min_by_key(|r| r.0).unwrap();
        match s.observed_order {
            Some(q) => {
                assert!((q - order).abs() <= 0.15, "{name}: order {q}\n{table}");
                // The fitted window starts at the smallest usable step.
                let usable_min = rows
                    .iter()
                    .filter(|(j, r)| r.status.is_ok() && r.error_max.unwrap() > res.floors[*j])
                    .map(|(_, r)| r.dt)
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(s.fit.dt_range.unwrap()[0], usable_min, "{name}\n{table}");
                with_order += 1;
            }
            None => {
                assert!(s.fit.reason.is_some() && s.fit.note.is_some(), "{table}");
                match s.extension_stop {
                    Stop::Floor => {
                        assert!(finest.error_max.unwrap() <= res.floors[jf], "{table}")
                    }
                    Stop::CostCap => {
                        let next = 2.0 * finest.steps as f64 * plan.particles as f64;
                        assert!(
                            s.particle_steps + next > plan.rule.cost_cap_particle_steps,
                            "{table}"
                        );
                    }
                    Stop::NotConverging => {
                        let mut e: Vec<(f64, f64)> = rows
                            .iter()
                            .map(|(_, r)| (r.dt, r.error_max.unwrap()))
                            .collect();
                        e.sort_by(|a, b| a.0.total_cmp(&b.0));
                        assert!(2.0 * e[0].1 > e[3].1, "{table}");
                    }
                    other => panic!("{name}: no order and a dishonest stop {other:?}\n{table}"),
                }
            }
        }
    }
    (with_order, table)
}

#[test]
fn coarse_spring_default_sweep_gives_textbook_orders() {
    let scene = coarse_spring();
    let names: Vec<&str> = METHODS.iter().map(|m| m.0).collect();
    let res = run_sweep(&scene, &config(&names)).unwrap();
    let sum = res.summary.as_ref().unwrap();
    assert_eq!(sum.reference.kind.name(), "analytic");
    // The grid comes from the dynamics (ω = 10 rad/s), not from the scene's dt of 0.37 s.
    assert!((sum.grid_rule.omega_max - 10.0).abs() < 1e-9);
    assert!(sum.grid_rule.dt_max < 0.37 && sum.grid_rule.extend);
    let (with_order, table) = check_orders(&res);
    eprintln!("{table}");
    // On a linear scene with an exact reference, the budget reaches the asymptotic range of
    // every method: at most the methods at the floor may lack an order.
    assert!(with_order >= 6, "{table}");
}

#[test]
fn rope_never_prints_an_order_off_theory() {
    let scene = rope();
    let names: Vec<&str> = METHODS.iter().map(|m| m.0).collect();
    let res = run_sweep(&scene, &config(&names)).unwrap();
    let (_, table) = check_orders(&res);
    eprintln!("{table}");
    // The scene is pre-asymptotic at the coarse end: some method's local slope over its two
    // largest stable steps is more than 0.15 off its order (else this test would be idle).
    let p = res.plan.dts.len();
    let pre = METHODS.iter().any(|(name, order)| {
        let i = res.plan.methods.iter().position(|n| n == name).unwrap();
        let mut e: Vec<(f64, f64)> = res
            .case_indices
            .iter()
            .zip(&res.rows)
            .filter(|(k, r)| *k / p == i && r.status.is_ok())
            .map(|(_, r)| (r.dt, r.error_max.unwrap()))
            .collect();
        e.sort_by(|a, b| b.0.total_cmp(&a.0));
        e.len() >= 2 && {
            let s = (e[0].1 / e[1].1).ln() / (e[0].0 / e[1].0).ln();
            (s - order).abs() > 0.15
        }
    });
    assert!(
        pre,
        "the rope must be pre-asymptotic at its coarse steps\n{table}"
    );
}

#[test]
fn shards_of_a_refined_sweep_merge_to_the_unsharded_one() {
    let scene = coarse_spring();
    let cfg = config(&["explicit_euler", "rk4", "implicit_euler"]);
    let full = run_sweep(&scene, &cfg).unwrap();
    // The extension ran: some method has steps below the base grid.
    assert!(full
        .case_indices
        .iter()
        .any(|k| k % full.plan.dts.len() < full.plan.base_from));
    let root = tempfile::tempdir().unwrap();
    write_sweep(&root.path().join("full"), &full).unwrap();
    let mut dirs = Vec::new();
    for i in 0..2 {
        let sc = SweepConfig {
            shard: Some(Shard { index: i, count: 2 }),
            ..cfg.clone()
        };
        let d = root.path().join(format!("s{i}"));
        write_sweep(&d, &run_sweep(&scene, &sc).unwrap()).unwrap();
        dirs.push(d);
    }
    let merged = merge(&dirs).unwrap();
    write_sweep(&root.path().join("merged"), &merged).unwrap();
    let read = |d: &str, f: &str| std::fs::read_to_string(root.path().join(d).join(f)).unwrap();
    assert_eq!(read("full", "sweep.csv"), read("merged", "sweep.csv"));
    // Equal but for the command's --out, which names the folder each was written to.
    let without_command = |text: String| {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v.as_object_mut().unwrap().remove("command");
        v
    };
    assert_eq!(
        without_command(read("full", "summary.json")),
        without_command(read("merged", "summary.json"))
    );
}

#[test]
fn explicit_grid_flags_are_honoured_exactly() {
    let scene = coarse_spring();
    let cfg = SweepConfig {
        dt_min: Some(1e-3),
        dt_max: Some(1e-1),
        points: Some(5),
        ..config(&["rk4", "explicit_euler"])
    };
    let res = run_sweep(&scene, &cfg).unwrap();
    let want: Vec<f64> = step_grid(1e-3, 1e-1, 5, 4.0).iter().map(|g| g.0).collect();
    let sum = res.summary.unwrap();
    assert_eq!(sum.dts, want);
    assert!(!sum.grid_rule.extend);
    for s in &sum.methods {
        assert_eq!(s.stable_points + s.unstable_points, want.len());
    }
}
