//! The stability map over the extremes: the stiff anchored spring with stiffness from
//! 1e-3 to 1e9 N/m (1 kg) and steps from 1e-6 to 1 s, for every native method and Rapier.
//!
//! Oracles, none tuned here:
//! - textbook stability limits of the undamped oscillator (Hairer, Lubich & Wanner, Geometric
//!   Numerical Integration, §I.1 and the RK stability polynomial): symplectic Euler and both
//!   Verlets stable for hω < 2, classical RK4 for hω < 2√2, backward Euler for every h,
//!   forward Euler and RK2 for none;
//! - linear growth: on a linear oscillator the energy after n steps grows like ρ²ⁿ (ρ: spectral
//!   radius of the one-step map), so the empirical run must blow up when ρ²ⁿ is well past the
//!   cap (1 + 1e4 here), and must stay stable when ρ²ⁿ < 2: a rise below the scene's energy
//!   scale fires no rule of the verdict (`run::verdict`). Between the two, rules 3 to 5 decide
//!   on how the growth unfolds, and the test leaves the cell alone. These oracles judge the
//!   cell's run (`run_stable`); the cell's verdict (`stable`) follows the spectral radius.
//!
//! The map runs with `--blowup-factor 1e4` here, to keep the cap well away from the bounded
//! swings this test also crosses. `tests/physics/verdicts.rs` checks the map at the default cap.

use springlab::measure::stability::{stability_map, MapConfig, MapRow, Verdict};
use springlab::scenario::Scenario;

const STIFFNESS_SCALES: [f64; 5] = [1e-9, 1e-6, 1e-3, 1.0, 1e3]; // k = 1e-3 … 1e9 N/m
const DTS: [f64; 7] = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0];

fn map(methods: &[&str]) -> Vec<MapRow> {
    let scene = Scenario::from_file("scenarios/stiff_spring.toml").unwrap();
    let cfg = MapConfig {
        stiffness_scales: STIFFNESS_SCALES.to_vec(),
        dts: DTS.to_vec(),
        common: springlab::measure::Common {
            methods: methods.iter().map(|s| s.to_string()).collect(),
            blowup_factor: 1e4,
            ..Default::default()
        },
        ..Default::default()
    };
    let rows = stability_map(&scene, &cfg).unwrap();
    assert_eq!(
        rows.len(),
        methods.len() * STIFFNESS_SCALES.len() * DTS.len()
    );
    rows
}

#[test]
fn map_of_the_stiff_spring_shows_the_textbook_boundaries() {
    let names = [
        "explicit_euler",
        "symplectic_euler",
        "implicit_euler",
        "rk2",
        "rk4",
        "velocity_verlet",
        "position_verlet",
    ];
    let rows = map(&names);
    let mut decided = 0;
    for r in &rows {
        let hw = r.h_omega;
        // Textbook verdicts and limits.
        let textbook = match r.method.as_str() {
            "symplectic_euler" | "velocity_verlet" | "position_verlet" => Some(2.0),
            "rk4" => Some(2.0 * 2f64.sqrt()),
            _ => None,
        };
        let verdict = r
            .theory_verdict
            .expect("native linear methods have a theory");
        match (r.method.as_str(), textbook) {
            ("implicit_euler", _) => assert_eq!(verdict, Verdict::UnconditionallyStable),
            ("explicit_euler" | "rk2", _) => assert_eq!(verdict, Verdict::UnstableForAllDt),
            (_, Some(limit)) => {
                assert_eq!(verdict, Verdict::StableBelow, "{r:?}");
                let got = r.theory_max_dt.unwrap() * r.omega_max;
                assert!(
                    (got - limit).abs() < 1e-6 * limit,
                    "{}: hω limit {got}",
                    r.method
                );
            }
            _ => unreachable!(),
        }
        // The empirical run against the growth the spectral radius predicts over its steps.
        let rho = r.spectral_radius.unwrap();
        // The map's documented step count: 50 periods, within [MAP_MIN_STEPS, MAP_MAX_STEPS].
        let steps = ((50.0 * std::f64::consts::TAU / r.omega_max / r.dt).ceil()).clamp(
            springlab::measure::stability::MAP_MIN_STEPS as f64,
            springlab::measure::stability::MAP_MAX_STEPS as f64,
        );
        let growth = 2.0 * steps * rho.ln(); // ln of the energy growth factor
        let threshold = (1.0f64 + 1e4).ln();
        if growth > 2.0 * threshold {
            assert!(
                !r.run_stable,
                "{} at k×{:e}, dt {:e} (hω {hw:e}): ρ = {rho} predicts blow-up",
                r.method, r.stiffness_scale, r.dt
            );
            decided += 1;
        } else if growth < 0.9 * 2f64.ln() {
            assert!(
                r.run_stable,
                "{} at k×{:e}, dt {:e} (hω {hw:e}): ρ = {rho} predicts bounded",
                r.method, r.stiffness_scale, r.dt
            );
            decided += 1;
        }
        // The cell's verdict follows the theory at its step where the run agrees with it or the
        // scene still has that radius at the run's end (forward Euler on this undamped spring
        // is unstable at every step, however slowly its growth shows).
        if r.decided_by == springlab::measure::stability::CellDecidedBy::SpectralRadius {
            let theory = match verdict {
                Verdict::UnconditionallyStable => true,
                Verdict::StableBelow => r.dt <= r.theory_max_dt.unwrap(),
                _ => false,
            };
            assert_eq!(r.stable, theory, "{r:?}");
        }
        // Where the textbook says stable with margin, the run must be stable, whatever ρ says.
        if let Some(limit) = textbook {
            if hw < 0.9 * limit {
                assert!(r.stable, "{} stable below hω = {limit}, at {hw}", r.method);
            } else if hw > 1.1 * limit {
                assert!(
                    !r.stable,
                    "{} unstable above hω = {limit}, at {hw}",
                    r.method
                );
            }
        }
        if r.method == "implicit_euler" {
            assert!(r.stable, "backward Euler is A-stable: hω = {hw}");
        }
    }
    // Most cells are far from the threshold: the oracle must actually decide them.
    assert!(
        decided >= rows.len() * 3 / 4,
        "decided {decided} of {}",
        rows.len()
    );
}

#[test]
fn rapier_runs_every_cell_of_the_extreme_map_without_nan() {
    // The contract for every cell: a status (the map returns an error on a failed run) and
    // finite numbers.
    let rows = map(&["rapier_impulse"]);
    for r in &rows {
        assert!(r.omega_max.is_finite() && r.h_omega.is_finite());
    }
    // Oracle: Rapier integrates joint springs as substepped backward Euler (the scheme
    // `springlab::rapier::scheme` predicts and `tests/physics/rapier_scheme.rs` checks against
    // Rapier's energy curves), which is A-stable: every cell, up to hω = 3e4, stays bounded.
    let stable = rows.iter().filter(|r| r.stable).count();
    eprintln!("rapier_impulse: stable in {stable} of {} cells", rows.len());
    assert_eq!(stable, rows.len(), "substepped backward Euler is A-stable");
}
