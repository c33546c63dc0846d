//! The sweep's time budget removes runs and never changes one. Oracle: the same sweep without
//! a budget. Every row of a budgeted sweep equals, bit for bit (wall time aside), the row of the
//! unbudgeted sweep at the same method and step; a budget far above the projected total cuts
//! nothing; one at a fifth of it cuts the costliest method (implicit Euler's Newton solves cost
//! tens of symplectic steps) and says so with its figures.

use springlab::measure::sweep::{run_sweep, SweepConfig, SweepResult, SweepRow};
use springlab::scenario::Scenario;

fn sweep(budget: Option<f64>) -> SweepResult {
    let scene = Scenario::from_file("scenarios/hanging_chain.toml").unwrap();
    let cfg = SweepConfig {
        duration: Some(1.0),
        extend: Some(false),
        repeat_short: false,
        common: springlab::measure::Common {
            methods: vec!["symplectic_euler".into(), "implicit_euler".into()],
            budget_seconds: budget,
            ..Default::default()
        },
        ..Default::default()
    };
    run_sweep(&scene, &cfg).unwrap()
}

/// Rows without their wall time, by (method, step bits).
fn rows(r: &SweepResult) -> Vec<(String, u64, SweepRow)> {
    r.rows
        .iter()
        .map(|row| {
            let mut x = row.clone();
            x.wall_seconds = 0.0;
            (row.method.clone(), row.dt.to_bits(), x)
        })
        .collect()
}

#[test]
fn a_budget_removes_the_costliest_runs_and_changes_none() {
    let free = sweep(None);
    let all = rows(&free);
    assert!(free.plan.budget.is_none());
    // Far above the total: nothing is cut, and nothing is recorded.
    let wide = sweep(Some(1e6));
    assert!(wide.plan.budget.is_none());
    assert_eq!(rows(&wide), all);
    // Far below: every method is left out, each named with the budget and its measured cost.
    let none = sweep(Some(1e-9));
    assert!(none.rows.is_empty());
    assert!(none
        .plan
        .budget
        .as_ref()
        .is_some_and(|b| b.methods.is_empty()));
    assert_eq!(none.plan.skipped.len(), 2);
    for s in &none.plan.skipped {
        assert!(
            s.1.contains("budget of") && s.1.contains("ms per step"),
            "{s:?}"
        );
    }
    // A fifth of the unbudgeted runs' modelled cost: implicit Euler loses its finest steps;
    // symplectic Euler keeps all of them; every row left is the unbudgeted one.
    let total: f64 = free.rows.iter().map(|r| r.modelled_seconds).sum();
    let tight = sweep(Some(0.2 * total));
    let tb = tight.plan.budget.as_ref().unwrap();
    let implicit_cut = tb
        .of("implicit_euler")
        .is_none_or(|m| m.finest > tight.plan.base_from);
    assert!(implicit_cut, "{tb:?}");
    let kept = rows(&tight);
    assert!(kept.len() < all.len());
    for r in &kept {
        assert!(all.contains(r), "a budgeted row differs: {:?}", r.2);
    }
    let sym =
        |v: &[(String, u64, SweepRow)]| v.iter().filter(|r| r.0 == "symplectic_euler").count();
    assert_eq!(sym(&kept), sym(&all));
    // The summary records the cut (a method left out names the figure in `skipped`).
    let sum = tight.summary.unwrap();
    let named = sum
        .skipped
        .iter()
        .any(|s| s.1.contains("budget of") && s.1.contains("ms per step"))
        || sum
            .budget
            .as_ref()
            .and_then(|b| b.of("implicit_euler"))
            .is_some_and(|m| m.finest > tight.plan.base_from);
    assert!(named, "{sum:?}");
}
