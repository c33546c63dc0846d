//! Multibody topology: trees become multibody joints, loops fall back to impulse joints and the
//! method says so; impulses reach Rapier after the runner's reset.
//! Oracles: graph counting (a connected graph with V vertices has a spanning tree of V−1 edges,
//! so E − (V − 1) edges close loops); momentum balance of an impulse (Δp = m·Δv).
use crate::rapier_support;
use rapier_support::*;
use springlab::rapier::{FallbackReason, Mode, RapierStepper, Topology, MAX_TREE_PARTICLES};
use springlab::scenario::Scenario;

fn small_cloth() -> Scenario {
    Scenario::from_toml_str(
        "[world]\ngravity=[0.0,-9.81,0.0]\n[[cloth]]\norigin=[0.0,0.0,0.0]\nsize=[1.0,1.0]\ncount=[4,4]\n\
         mass=0.01\nstiffness=200.0\ndamping=0.01\nplane=\"xz\"\nfix=[\"top_left\"]\n",
        "cloth4.toml",
    )
    .unwrap()
}

#[test]
fn cloth_loops_fall_back_and_are_reported() {
    let scene = small_cloth();
    let sys = scene.build();
    let topo = Topology::of(&sys, MAX_TREE_PARTICLES);
    let (v, e) = (sys.len(), sys.springs.len());
    assert_eq!(topo.tree.len(), v - 1, "one spanning tree");
    assert_eq!(topo.fallback.len(), e - (v - 1));
    // Loops make the method use the smaller tree cap; the note reports that forest.
    assert_eq!(
        springlab::rapier::tree_cap(&sys),
        springlab::rapier::MAX_TREE_PARTICLES_WITH_LOOPS
    );
    let used = Topology::of(&sys, springlab::rapier::tree_cap(&sys));
    assert!(topo
        .fallback
        .iter()
        .all(|(_, r)| *r == FallbackReason::Loop));
    let note = RapierStepper::new(Mode::Multibody, 4)
        .topology_note(&sys)
        .unwrap();
    assert!(
        note.contains(&format!("{} edge(s) fell back", used.fallback.len())),
        "{note}"
    );
    assert!(RapierStepper::new(Mode::Impulse, 4)
        .topology_note(&sys)
        .is_none());
    // It runs: a few frames, finite, the pinned corner stays put.
    let (rec, out) = record(&scene, "rapier_multibody", 1.0 / 60.0, 4, 10);
    assert!(out.status.is_ok(), "{:?}", out.status);
    let pinned = (0..v).find(|&p| !sys.free[p]).unwrap();
    assert_eq!(rec.x.last().unwrap()[pinned], rec.x[0][pinned]);
}

#[test]
fn shipped_cloth_reports_its_fallback() {
    let scene = Scenario::from_file("scenarios/cloth.toml").unwrap();
    let sys = scene.build();
    let topo = Topology::of(&sys, MAX_TREE_PARTICLES);
    let note = topo.describe();
    eprintln!("cloth.toml: {note}");
    // Every spring is either a multibody joint or a fallback joint, none lost.
    assert_eq!(topo.tree.len() + topo.fallback.len(), sys.springs.len());
    assert!(note.contains("fell back"), "{note}");
}

#[test]
fn chain_is_one_tree_without_fallback() {
    let scene = Scenario::from_file("scenarios/hanging_chain.toml").unwrap();
    let sys = scene.build();
    let note = RapierStepper::new(Mode::Multibody, 4)
        .topology_note(&sys)
        .unwrap();
    assert!(note.contains("no fallback"), "{note}");
}

const KICK: &str = "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n[[particle]]\nposition=[1.2,0.0,0.0]\nmass=3.0\n\
     [[spring]]\nbetween=[0,1]\nstiffness=10.0\nrest_length=1.0\n\
     [[impulse]]\ntime=0.105\nparticle=1\ndelta_v=[0.0,2.0,0.0]\n";

/// Largest |p − p_exact| over a run with the kick (p_exact = 0 before, m·Δv = (0, 6, 0) after).
fn worst_momentum_error(name: &str, h: f64, steps: u64) -> f64 {
    let scene = Scenario::from_toml_str(KICK, "kick.toml").unwrap();
    let sys = scene.build();
    let (rec, _) = record(&scene, name, h, 4, steps);
    rec.v
        .iter()
        .zip(&rec.energy)
        .map(|(v, &(t, _))| {
            let want = if t < 0.105 + 1e-9 { 0.0 } else { 6.0 };
            (sys.momentum(v) - springlab::model::Vec3::new(0.0, want, 0.0)).norm()
        })
        .fold(0.0, f64::max)
}

#[test]
fn impulses_reach_rapier_after_reset() {
    // Impulse joints: equal and opposite impulses, momentum exact to rounding.
    let e = worst_momentum_error("rapier_impulse", 0.01, 50);
    assert!(e < 1e-9, "rapier_impulse: momentum error {e}");
    // Multibody (rebuilt from the kicked state): its reduced-coordinate integration of the
    // spinning pair drifts, at first order in h (measured 9e-3 at h = 0.01, 9e-4 at 1e-3 over
    // 0.5 s): the kick must arrive (error ≪ 6) and the drift must shrink ~10× with h.
    let coarse = worst_momentum_error("rapier_multibody", 0.01, 50);
    let fine = worst_momentum_error("rapier_multibody", 0.001, 500);
    assert!(coarse < 0.05, "multibody: error {coarse}");
    assert!(
        coarse / fine > 5.0,
        "multibody drift not first order: {coarse} vs {fine}"
    );
}
