//! Mesh sidedness: an open mesh is a two-sided thin sheet, whatever its
//! winding; a closed mesh has an inside, whatever its winding.
//!
//! Oracles: geometry alone. A particle below a sheet is not touching it (its distance is its
//! height below); a particle thrown at a sheet from either side ends on the side it came from
//! (a sheet is impenetrable to the impulse response); nothing is ever moved further than its
//! own travel in a step ("teleporting").

use springlab::collide::{mesh, ObstacleDef, ObstacleSet, ShapeDef};
use springlab::measure::contacts::ContactMetrics;
use springlab::method::MethodOptions;
use springlab::model::Vec3;
use springlab::run::{run, RunPlan};
use springlab::scenario::Scenario;

/// Two triangles covering [−1, 1]² at y = 0; `reversed`: wound to face −y instead of +y.
fn sheet_toml(reversed: bool) -> String {
    let tris = if reversed {
        "[[0, 1, 2], [0, 2, 3]]"
    } else {
        "[[0, 2, 1], [0, 3, 2]]"
    };
    format!(
        "[[obstacle]]\nshape = \"mesh\"\nvertices = [[-1.0,0.0,-1.0],[1.0,0.0,-1.0],[1.0,0.0,1.0],[-1.0,0.0,1.0]]\ntriangles = {tris}\nrestitution = 0.5\n"
    )
}

fn scene(y: f64, vy: f64, gravity: f64, reversed: bool) -> Scenario {
    Scenario::from_toml_str(
        &format!(
            "[world]\ngravity = [0.0, {gravity}, 0.0]\n[[particle]]\nposition = [0.2, {y}, 0.1]\nvelocity = [0.0, {vy}, 0.0]\nmass = 0.1\n{}[collision]\nresponse = \"impulse\"\n",
            sheet_toml(reversed)
        ),
        "sheet.toml",
    )
    .unwrap()
}

/// Runs `scene` with symplectic Euler at `dt` for `steps`, checking that no step moves the
/// particle further than its own speed allows (|Δx| ≤ h·max(|v_before|, |v_after|) + round-off),
/// and returns the final height and the tunnelling count.
fn fly(scene: &Scenario, dt: f64, steps: u64) -> (f64, u64) {
    struct NoJump {
        prev: Option<(Vec3, f64)>,
        dt: f64,
        worst: f64,
        metrics: ContactMetrics,
    }
    impl springlab::run::Observer for NoJump {
        fn observe(
            &mut self,
            step: u64,
            s: &springlab::model::State,
            e: &springlab::run::EnergyRecord,
        ) -> springlab::error::Result<()> {
            let (x, v) = (s.x[0], s.v[0].norm());
            if let Some((x0, v0)) = self.prev {
                let jump = (x - x0).norm() - self.dt * v.max(v0) - 1e-12;
                self.worst = self.worst.max(jump);
            }
            self.prev = Some((x, v));
            self.metrics.observe(step, s, e)
        }
    }
    let sys = scene.build();
    let mut stepper =
        springlab::method::create("symplectic_euler", &MethodOptions::default()).unwrap();
    let mut obs = NoJump {
        prev: None,
        dt,
        worst: 0.0,
        metrics: ContactMetrics::new(&sys, dt).unwrap(),
    };
    let out = run(
        &sys,
        &mut stepper,
        scene.initial_state(),
        &RunPlan::new(dt, steps),
        &mut obs,
    )
    .unwrap();
    assert!(out.status.is_ok());
    assert!(
        obs.worst <= 0.0,
        "a step moved the particle {} m beyond its travel",
        obs.worst
    );
    (
        out.final_state.x[0].y,
        obs.metrics.report().tunnelling_count,
    )
}

#[test]
fn a_sheet_has_no_inside_whatever_its_winding() {
    for reversed in [false, true] {
        let text = sheet_toml(reversed);
        let s = Scenario::from_toml_str(
            &format!("[[particle]]\nposition = [0.0, 1.0, 0.0]\nmass = 1.0\n{text}"),
            "s.toml",
        )
        .unwrap();
        let set = ObstacleSet::build(&s.collision.as_ref().unwrap().obstacles);
        for y in [-0.48, -1e-3, 1e-3, 0.48] {
            let c = set.query(0, &Vec3::new(0.2, y, 0.1), 0.0);
            assert!(
                (c.distance - y.abs()).abs() < 1e-15 && c.normal.y * y > 0.0,
                "reversed = {reversed}, y = {y}: {c:?}"
            );
        }
    }
}

#[test]
fn a_particle_below_a_reversed_sheet_stays_below_and_is_never_teleported() {
    // A user's case: at rest 0.48 m below the sheet, it was moved onto its top at step 1.
    let (y, tunnels) = fly(&scene(-0.48, 0.0, 0.0, true), 1e-3, 100);
    assert_eq!((y, tunnels), (-0.48, 0));
    // Falling away from the sheet's underside under gravity: never touched.
    let (y, _) = fly(&scene(-0.01, 0.0, -9.81, true), 1e-3, 100);
    assert!(y < -0.01);
}

#[test]
fn swept_tests_stop_a_fast_particle_from_either_side_of_either_winding() {
    // 200 m/s at dt = 1 ms crosses the sheet in one step (20 cm per step): the swept test
    // must catch it from below as from above, and nothing may be counted as tunnelling.
    for reversed in [false, true] {
        let (y, tunnels) = fly(&scene(-0.3, 200.0, 0.0, reversed), 1e-3, 10);
        assert!(
            y < 0.0 && tunnels == 0,
            "from below, reversed = {reversed}: y = {y}, {tunnels} tunnels"
        );
        let (y, tunnels) = fly(&scene(0.3, -200.0, 0.0, reversed), 1e-3, 10);
        assert!(
            y > 0.0 && tunnels == 0,
            "from above, reversed = {reversed}: y = {y}, {tunnels} tunnels"
        );
    }
}

#[test]
fn a_closed_mesh_wound_inside_out_still_has_its_inside() {
    // Oracle: the unit tetrahedron's centroid (1/4, 1/4, 1/4) is inside, nearest to the face
    // x + y + z = 1 at distance (1 − 3/4)/√3; (1, 1, 1) is outside.
    let v = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
    let outward = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let inside_out: Vec<[u32; 3]> = outward.iter().map(|&[a, b, c]| [a, c, b]).collect();
    assert!(mesh::is_closed(&v, &inside_out));
    for tris in [outward, inside_out] {
        let set = ObstacleSet::build(&[ObstacleDef {
            shape: ShapeDef::Mesh {
                vertices: v.clone(),
                triangles: tris,
            },
            restitution: 0.0,
            friction: 0.0,
        }]);
        assert!(!set.obstacles()[0].two_sided);
        let c = set.query(0, &Vec3::new(0.25, 0.25, 0.25), 0.0);
        assert!((c.distance + 0.25 / 3f64.sqrt()).abs() < 1e-12, "{c:?}");
        assert!(set.query(0, &Vec3::new(1.0, 1.0, 1.0), 0.0).distance > 0.0);
    }
}
