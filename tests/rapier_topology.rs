//! Multibody topology: trees become multibody joints, loops fall back to impulse joints and the
//! backend says so; impulses reach Rapier after the runner's reset.
//! Oracles: graph counting (a connected graph with V vertices has a spanning tree of V−1 edges,
//! so E − (V − 1) edges close loops); momentum balance of an impulse (Δp = m·Δv).
mod rapier_support;
use rapier_support::*;
use springlab::rapier::{FallbackReason, RapierBackend, Mode, Topology, MAX_TREE_PARTICLES};
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
    assert!(topo.fallback.iter().all(|(_, r)| *r == FallbackReason::Loop));
    let note = RapierBackend::new(Mode::Multibody, 4).topology_note(&sys).unwrap();
    assert!(note.contains(&format!("{} edge(s) fell back", e - (v - 1))), "{note}");
    assert!(RapierBackend::new(Mode::Impulse, 4).topology_note(&sys).is_none());
    // It runs: a few frames, finite, the pinned corner stays put.
    let (rec, out) = record(&scene, "rapier_multibody", 1.0 / 60.0, 4, 10);
    assert!(out.status.is_ok(), "{:?}", out.status);
    let pinned = (0..v).find(|&p| !sys.free[p]).unwrap();
    assert_eq!(rec.x.last().unwrap()[pinned], rec.x[0][pinned]);
}

#[test]
fn chain_is_one_tree_without_fallback() {
    let scene = Scenario::from_file("scenarios/hanging_chain.toml").unwrap();
    let sys = scene.build();
    let note = RapierBackend::new(Mode::Multibody, 4).topology_note(&sys).unwrap();
    assert!(note.contains("no fallback"), "{note}");
}

#[test]
fn impulses_reach_rapier_after_reset() {
    for name in BACKENDS {
        let scene = Scenario::from_toml_str(
            "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\n[[particle]]\nposition=[1.2,0.0,0.0]\nmass=3.0\n\
             [[spring]]\nbetween=[0,1]\nstiffness=10.0\nrest_length=1.0\n\
             [[impulse]]\ntime=0.105\nparticle=1\ndelta_v=[0.0,2.0,0.0]\n",
            "kick.toml",
        )
        .unwrap();
        let sys = scene.build();
        let (rec, _) = record(&scene, name, 0.01, 4, 50);
        // Before the kick the momentum is zero; after it, m·Δv = (0, 6, 0) and conserved.
        for (f, v) in rec.v.iter().enumerate() {
            let p = sys.momentum(v);
            let want = if f <= 10 { 0.0 } else { 6.0 };
            assert!((p.y - want).abs() < 1e-4, "{name} frame {f}: p = {p}");
        }
    }
}
