//! Cross-check of the adaptive reference against an independent, well-kept solver crate.
//!
//! Oracle: the `ode_solvers` crate on the same equations written out here by hand (three 1 kg
//! beads on Hookean springs hanging from a fixed anchor in gravity, released from a horizontal
//! line so the swing is large and nonlinear):
//! - its own DOP853 implementation (independent code) at rtol = atol = 1e-12, the tolerance
//!   our reference claims: positions at every sample time must agree to 1e-9 m, within the
//!   reference's own measured uncertainty;
//! - its Dopri5 (Dormand–Prince 5(4), a different method) at 1e-11: agreement to 1e-7 m. (Its
//!   error stalls near 3e-8 m whatever the tolerance, 1e-11 … 1e-14, while the two DOP853 codes
//!   agree to 3e-13 m at 1e-12: a fifth-order method's round-off over ~10⁵ steps.)

use ode_solvers::{DVector, Dopri5, System as OdeSystem};
use springlab::measure::grid::TimeGrid;
use springlab::measure::reference::Reference;
use springlab::scenario::Scenario;

const K: f64 = 80.0;
const L: f64 = 0.5;
const G: f64 = 9.81;

struct Chain;

impl OdeSystem<f64, DVector<f64>> for Chain {
    fn system(&self, _t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        // y = [x1 x2 x3 (3 each), v1 v2 v3]; the anchor is at the origin.
        let pos = |i: usize| -> [f64; 3] {
            if i == 0 {
                [0.0; 3]
            } else {
                let b = 3 * (i - 1);
                [y[b], y[b + 1], y[b + 2]]
            }
        };
        let mut acc = [[0.0, -G, 0.0]; 3];
        for s in 0..3 {
            // Spring s joins node s and node s + 1 (node 0 = anchor).
            let (a, b) = (pos(s), pos(s + 1));
            let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let f = K * (len - L) / len;
            for k in 0..3 {
                // Force on node s + 1 is −f d, on node s +f d (unit masses).
                acc[s][k] -= f * d[k];
                if s > 0 {
                    acc[s - 1][k] += f * d[k];
                }
            }
        }
        for i in 0..9 {
            dy[i] = y[9 + i];
        }
        for (p, a) in acc.iter().enumerate() {
            for k in 0..3 {
                dy[9 + 3 * p + k] = a[k];
            }
        }
    }
}

fn scene() -> Scenario {
    let mut toml = format!("[world]\ngravity = [0.0, {:e}, 0.0]\n", -G);
    toml += "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n";
    for i in 1..=3 {
        toml += &format!(
            "[[particle]]\nposition = [{:e}, 0.0, 0.0]\nmass = 1.0\n",
            i as f64 * L
        );
        toml += &format!(
            "[[spring]]\nbetween = [{}, {}]\nstiffness = {K:e}\nrest_length = {L:e}\n",
            i - 1,
            i
        );
    }
    Scenario::from_toml_str(&toml, "chain3.toml").unwrap()
}

#[test]
fn dop853_reference_agrees_with_ode_solvers_dopri5_on_a_swinging_chain() {
    let dt = 0.01;
    let steps = 200;
    let sc = scene();
    let sys = sc.build();
    let s0 = sc.initial_state();
    let grid = TimeGrid::new(dt, steps, 1000);
    let r = Reference::compute(&sys, &s0, &[grid], grid.time(steps)).unwrap();
    assert_eq!(r.info.kind.name(), "dop853");
    assert_eq!(r.info.predictability_horizon, None, "{:?}", r.info);

    let mut y0 = DVector::zeros(18);
    for i in 0..3 {
        y0[3 * i] = (i + 1) as f64 * L;
    }
    let dop853 = |tol: f64| {
        let mut s =
            ode_solvers::Dop853::new(Chain, 0.0, grid.time(steps), dt, y0.clone(), tol, tol);
        s.integrate().unwrap();
        (s.x_out().clone(), s.y_out().clone())
    };
    let dopri5 = |tol: f64| {
        let mut s = Dopri5::new(Chain, 0.0, grid.time(steps), dt, y0.clone(), tol, tol);
        s.integrate().unwrap();
        (s.x_out().clone(), s.y_out().clone())
    };
    let gap = |(ts, ys): (Vec<f64>, Vec<DVector<f64>>)| {
        let mut worst: f64 = 0.0;
        let mut compared = 0;
        for n in grid.sample_steps() {
            let t = grid.time(n);
            let Some(k) = ts.iter().position(|&u| (u - t).abs() < 1e-9) else {
                continue;
            };
            let x = r.positions(0, n).unwrap();
            for p in 1..4 {
                let b = 3 * (p - 1);
                let d = (x[p] - vec3(ys[k][b], ys[k][b + 1], ys[k][b + 2])).norm();
                worst = worst.max(d);
            }
            compared += 1;
        }
        assert!(compared >= 150, "{compared}");
        worst
    };
    let moved = grid
        .sample_steps()
        .flat_map(|n| (1..4).map(move |p| (n, p)))
        .map(|(n, p)| (r.positions(0, n).unwrap()[p] - s0.x[p]).norm())
        .fold(0.0, f64::max);
    let (same, other) = (gap(dop853(1e-12)), gap(dopri5(1e-11)));
    eprintln!(
        "chain3: vs ode_solvers DOP853 {same:e} m, vs Dopri5 {other:e} m, reference uncertainty {:e} m, motion {moved}",
        r.info.uncertainty
    );
    assert!(moved > 0.5, "large-amplitude swing expected: {moved}");
    assert!(same < 1e-9, "{same:e}");
    assert!(
        same <= r.info.uncertainty,
        "{same:e} vs {:e}",
        r.info.uncertainty
    );
    assert!(other < 1e-7, "{other:e}");
}

fn vec3(x: f64, y: f64, z: f64) -> springlab::model::Vec3 {
    springlab::model::Vec3::new(x, y, z)
}
