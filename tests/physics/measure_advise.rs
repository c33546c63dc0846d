//! The advisor's pick, re-run independently, meets the tolerance.
//! Oracle: the anchored spring's closed form x(t) = 1 + 0.5 cos(2t) (k = 4, m = 1, l0 = 1,
//! released at rest from 1.5 m), evaluated here, not through springlab's reference.

use springlab::measure::advise::{advise, AdviseConfig};
use springlab::measure::tolerance::Metric;
use springlab::model::State;
use springlab::run::{run, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

struct MaxErr(f64, f64);
impl Observer for MaxErr {
    fn observe(&mut self, step: u64, s: &State, _e: &EnergyRecord) -> springlab::Result<()> {
        let t = step as f64 * self.1;
        let exact = 1.0 + 0.5 * (2.0 * t).cos();
        let err = ((s.x[1].x - exact).powi(2) + s.x[1].y.powi(2) + s.x[1].z.powi(2)).sqrt();
        self.0 = self.0.max(err);
        Ok(())
    }
}

#[test]
fn advised_step_meets_the_tolerance_when_rerun() {
    let scene = Scenario::from_file("scenarios/anchored_spring.toml").unwrap();
    let tol = 1e-4;
    let cfg = AdviseConfig {
        tolerance: Some(tol),
        metric: Some(Metric::Position),
        horizon: Some(5.0),
        points: 8,
        ..Default::default()
    };
    let adv = advise(&scene, &cfg).unwrap();
    let name = adv.method.clone().expect("something meets 1e-4 m");
    assert!(adv.verified_error.unwrap() <= tol);
    assert!(!adv.alternatives.is_empty());
    // Ranked by modelled seconds per simulated second: none comes before one cheaper by more
    // than the tie band.
    let band = springlab::measure::advise::TIE_BAND;
    for w in adv.alternatives.windows(2) {
        assert!(w[0].modelled_per_second <= (1.0 + band) * w[1].modelled_per_second);
    }
    for choice in &adv.alternatives {
        let mut stepper = springlab::method::create(&choice.method, &Default::default()).unwrap();
        let steps = (5.0 / choice.dt).round() as u64;
        let mut obs = MaxErr(0.0, choice.dt);
        let plan = RunPlan::new(choice.dt, steps);
        let out = run(
            &scene.build(),
            &mut stepper,
            scene.initial_state(),
            &plan,
            &mut obs,
        )
        .unwrap();
        assert!(out.status.is_ok());
        assert!(
            obs.0 <= tol,
            "{}: re-run error {:e} > {tol:e} at dt {}",
            choice.method,
            obs.0,
            choice.dt
        );
        // The advisor's own verification agrees with the independent one.
        assert!(
            (obs.0 - choice.verified_error).abs() <= 1e-9 + 1e-6 * obs.0,
            "{}",
            choice.method
        );
    }
    assert_eq!(adv.frame_rates.len(), 4);
    eprintln!("pick {name} dt {:?}", adv.dt);
}
