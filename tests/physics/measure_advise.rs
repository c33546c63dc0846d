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
    // The game view is the frame-rate table of the verified candidates (one answer to the
    // frame-rate question): the same methods, judged as the advice was, at the table's rates,
    // and at each rate the best the game-rate answer reads from that table.
    let table = adv.frame_rates.as_ref().expect("the view is on by default");
    assert_eq!(table.rates, springlab::measure::framerate::DEFAULT_RATES);
    assert_eq!(table.judged.tolerance, adv.judged.tolerance);
    let mut asked: Vec<&str> = adv.alternatives.iter().map(|c| c.method.as_str()).collect();
    let mut listed: Vec<&str> = table.entries.iter().map(|e| e.method.as_str()).collect();
    asked.sort_unstable();
    listed.sort_unstable();
    listed.dedup();
    assert_eq!(asked, listed);
    assert_eq!(adv.best_at_rates.len(), table.rates.len());
    for b in &adv.best_at_rates {
        let g = springlab::measure::answer::game_rate(table, b.hz, &scene.name, &[]).unwrap();
        assert_eq!(g.meets, b.method.is_some(), "{} Hz", b.hz);
        if g.meets {
            assert_eq!(
                (&g.method, g.substeps),
                (&b.method, b.substeps),
                "{} Hz",
                b.hz
            );
        }
    }
    eprintln!("pick {name} dt {:?}", adv.dt);
}
