//! Every shipped scenario parses, builds and runs a few steps with every method that
//! applies to it; methods that do not apply say why.

use crate::common;
use common::*;
use springlab::scenario::Scenario;

#[test]
fn every_shipped_scenario_runs_with_every_applicable_method() {
    let mut files: Vec<_> = std::fs::read_dir("scenarios")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 8,
        "expected the shipped scenarios, found {files:?}"
    );
    for f in files {
        let scene = Scenario::from_file(&f).unwrap_or_else(|e| panic!("{e}"));
        let sys = scene.build();
        let dt = scene.run.dt.expect("shipped scenes give a step");
        let mut ran = 0;
        for name in springlab::method::Registry::builtin().native_names() {
            let mut i = stepper(name);
            if let Err(why) = i.check(&sys) {
                assert!(!why.is_empty());
                continue;
            }
            let plan = springlab::run::RunPlan::new(dt, 20);
            let out = springlab::run::run(
                &sys,
                &mut i,
                scene.initial_state(),
                &plan,
                &mut springlab::run::NoObserver,
            )
            .unwrap();
            assert!(out.final_energy.is_finite(), "{} {name}", scene.name);
            assert!(out.final_state.first_non_finite().is_none());
            ran += 1;
        }
        assert!(ran >= 1, "{}: no method applies", scene.name);
    }
}

#[test]
fn only_the_terms_a_scene_uses_are_built() {
    let osc = Scenario::from_file("scenarios/anchored_spring.toml")
        .unwrap()
        .build();
    assert_eq!(osc.active_terms(), vec!["springs"]);
    let chain = Scenario::from_file("scenarios/hanging_chain.toml")
        .unwrap()
        .build();
    assert_eq!(chain.active_terms(), vec!["springs+dampers", "gravity"]);
    let rod = Scenario::from_file("scenarios/pendulum_rod.toml")
        .unwrap()
        .build();
    assert_eq!(rod.active_terms(), vec!["gravity", "constraints"]);
}

#[test]
fn generated_blocks_follow_the_documented_index_order() {
    let toml = "[[particle]]\nposition=[5.0,5.0,5.0]\nmass=1.0\n\
        [[chain]]\nstart=[0.0,0.0,0.0]\nend=[1.0,0.0,0.0]\ncount=3\nmass=0.1\nstiffness=10.0\nfix=[\"first\"]\n\
        [[cloth]]\norigin=[0.0,0.0,0.0]\nsize=[1.0,1.0]\ncount=[3,2]\nmass=0.1\nstiffness=10.0\nbend_stiffness=1.0\nfix=[\"top_right\"]\n";
    let s = Scenario::from_toml_str(toml, "blocks.toml").unwrap();
    assert_eq!(s.particles.len(), 1 + 3 + 6);
    assert!(s.particles[1].fixed && !s.particles[3].fixed);
    // Cloth 3×2: structural 2·2 + 3·1 = 7, shear 2·2 = 4, bend along x: 2 rows × 1 = 2.
    assert_eq!(s.springs.len(), 2 + 7 + 4 + 2);
    // top_right is the last particle of the top row (x fastest).
    assert!(s.particles[9].fixed);
    assert_eq!(s.blocks.len(), 2);
}
