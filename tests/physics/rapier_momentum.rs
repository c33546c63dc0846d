//! A free pair's momentum through both Rapier engines, measured against conservation.
//!
//! Oracle: Newton's third law. Two free particles of unequal masses joined by a spring, with
//! no external force, keep their total momentum P0 exactly. Impulse joints apply equal and
//! opposite impulses, so rapier_impulse keeps it to round-off. rapier_multibody integrates the
//! pair in reduced coordinates (a free root and a slider link behind a light pivot) and drifts;
//! its drift must shrink as the substeps grow (conservation in the limit), which is what is
//! checked, not a fitted figure.

use crate::rapier_support::record;
use springlab::scenario::Scenario;

/// 1 kg and 0.25 kg, 1.5 m apart on a spring (k = 20 N/m, l0 = 1 m), stretched and spinning,
/// with a net momentum P0 = (0.25, 0.25, 0) kg·m/s.
fn unequal_pair() -> Scenario {
    Scenario::from_toml_str(
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nvelocity = [0.2, 0.5, 0.0]\nmass = 1.0\n\
         [[particle]]\nposition = [1.5, 0.0, 0.0]\nvelocity = [0.2, -1.0, 0.0]\nmass = 0.25\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = 20.0\nrest_length = 1.0\n",
        "unequal_pair.toml",
    )
    .unwrap()
}

/// Largest |P(t) − P0| (kg·m/s) of `name` over 2 s at 60 Hz with `substeps`.
fn drift(name: &str, substeps: usize) -> (f64, f64) {
    let scene = unequal_pair();
    let sys = scene.build();
    let p0 = sys.momentum(&scene.initial_state().v);
    let (rec, out) = record(&scene, name, 1.0 / 60.0, substeps, 120);
    assert!(out.status.is_ok(), "{name}");
    let worst = rec
        .v
        .iter()
        .map(|v| (sys.momentum(v) - p0).norm())
        .fold(0.0, f64::max);
    (worst, p0.norm())
}

#[test]
fn multibody_momentum_drift_shrinks_with_substeps() {
    let counts = [4, 8, 16, 32];
    let d: Vec<f64> = counts
        .iter()
        .map(|&n| drift("rapier_multibody", n).0)
        .collect();
    let p0 = drift("rapier_multibody", 4).1;
    for (n, x) in counts.iter().zip(&d) {
        eprintln!(
            "rapier_multibody: {n} substeps: |P − P0| ≤ {x:.3e} kg·m/s ({:.1} % of |P0|)",
            100.0 * x / p0
        );
    }
    for w in d.windows(2) {
        assert!(w[1] < w[0], "drift does not shrink: {d:?}");
    }
    // A first-order drift halves with each doubling (order 1); convergence is required as
    // more than half that order over the three doublings, and a drift that shrinks each time.
    let order = (d[0] / d[3]).log2() / 3.0;
    eprintln!("observed order {order:.2}");
    assert!(order > 0.5, "drift not converging: {d:?}");
}

#[test]
fn twin_impulse_keeps_momentum_to_round_off() {
    for n in [4, 32] {
        let (x, p0) = drift("rapier_impulse", n);
        eprintln!("rapier_impulse: {n} substeps: |P − P0| ≤ {x:.1e} kg·m/s");
        assert!(x < 1e-12 * p0.max(1.0), "{n} substeps: {x:e}");
    }
}
