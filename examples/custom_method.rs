//! Bring your own method: implement `Stepper` for the scheme in your game, register it
//! with its facts, and it runs through run, compare, sweep, stability, advise and the report
//! exactly like the built-in methods.
//!
//! Run with `cargo run --release --example custom_method` (writes under `out/custom/`).

use springlab::integrate::{StepStats, Stepper};
use springlab::measure::advise::{advise, AdviseConfig};
use springlab::measure::compare::{compare, CompareConfig};
use springlab::measure::stability::{analyse, StabilityConfig};
use springlab::measure::sweep::{run_sweep, SweepConfig};
use springlab::method::options::OptionValue;
use springlab::method::{Method, MethodInfo, MethodOptions, OptionSpec, Registry};
use springlab::model::{State, System, Vec3};
use springlab::run::{run, NoObserver, RunPlan};
use springlab::scenario::file::{ParticleSpec, RunSpec, ScenarioFile, SpringSpec};
use springlab::scenario::{Scenario, SpringLaw};

/// The "game loop" scheme many engines ship: symplectic Euler with a velocity damping factor
/// per frame (v *= 0.999 by default), which quietly removes energy.
struct GameEuler {
    a: Vec<Vec3>,
    /// The factor v is multiplied by each step.
    keep: f64,
}

/// The option game_euler reads, declared once: its flag, default, least value and help. The
/// registry lists it in the method's facts, and every recorded command carries its value.
const DAMPING: OptionSpec = OptionSpec::real(
    "game-damping",
    1e-3,
    (0.0, 1.0),
    "Fraction of the velocity game_euler removes per step",
);

impl Stepper for GameEuler {
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> springlab::Result<StepStats> {
        self.a.resize(s.len(), Vec3::zeros());
        sys.accelerations(&s.x, &s.v, &mut self.a);
        for p in 0..s.len() {
            if sys.free[p] {
                s.v[p] = (s.v[p] + self.a[p] * h) * self.keep;
                s.x[p] += s.v[p] * h;
            }
        }
        s.t += h;
        Ok(StepStats {
            force_evals: 1,
            dissipated: 0.0,
            ..StepStats::default()
        })
    }
}

fn main() -> springlab::Result<()> {
    // A mass on an anchored spring, built in code (the same scene as scenarios/anchored_spring).
    let particle = |x: f64, fixed: bool| ParticleSpec {
        position: [x, 0.0, 0.0],
        velocity: [0.0; 3],
        mass: 1.0,
        fixed,
        radius: 0.0,
    };
    let scene = Scenario::from_spec(ScenarioFile {
        name: Some("code_spring".into()),
        particle: vec![particle(0.0, true), particle(1.5, false)],
        spring: vec![SpringSpec {
            between: [0, 1],
            stiffness: 4.0,
            rest_length: Some(1.0),
            damping: 0.0,
            law: SpringLaw::Hooke,
        }],
        run: Some(RunSpec {
            dt: Some(1.0 / 60.0),
            duration: Some(10.0),
            ..Default::default()
        }),
        ..Default::default()
    })?;
    // Register the method once, with its facts.
    let registry = Registry::builtin().with(Method::new(
        MethodInfo {
            options: &[DAMPING],
            ..MethodInfo::native(
                "game_euler",
                1,
                "symplectic Euler with a velocity damping per step (--game-damping)",
            )
        },
        |o| {
            Box::new(GameEuler {
                a: Vec::new(),
                keep: 1.0 - o.real(&DAMPING),
            })
        },
    ))?;
    let sys = scene.build();
    let mine = ["game_euler", "symplectic_euler", "velocity_verlet", "rk4"].map(String::from);

    // run: one trajectory.
    let plan = RunPlan::for_duration(1.0 / 60.0, 10.0);
    for damping in [1e-3, 0.0] {
        let opts = MethodOptions::default().with(&DAMPING, OptionValue::Real(damping));
        let mut game = registry.create("game_euler", &opts)?;
        let out = run(
            &sys,
            &mut game,
            scene.initial_state(),
            &plan,
            &mut NoObserver,
        )?;
        println!(
            "run: game_euler at --game-damping {damping} keeps {:.1}% of its energy after 10 s",
            100.0 * out.final_energy.total / out.initial_energy.total
        );
    }

    // compare: side by side against the closed form.
    let cmp = compare(
        &scene,
        &CompareConfig {
            series_points: 0,
            common: springlab::measure::Common {
                registry: registry.clone(),
                methods: mine.to_vec(),
                ..Default::default()
            },
            ..Default::default()
        },
    )?;
    println!("compare against {} ({}):", cmp.reference.kind, cmp.command);
    for e in &cmp.entries {
        match e.result.as_ref().map(|r| (r, r.metrics.as_ref())) {
            Some((r, Some(m))) => println!(
                "  {:<18} max position error {:.3e} m, energy error {:+.3e}",
                r.method, m.error_max, m.energy_balance
            ),
            Some((r, None)) => println!(
                "  {:<18} {}: {}",
                r.method,
                r.status,
                r.unstable_reason.as_deref().unwrap_or("")
            ),
            None => {}
        }
    }

    // sweep: observed orders.
    let sw = run_sweep(
        &scene,
        &SweepConfig {
            common: springlab::measure::Common {
                registry: registry.clone(),
                methods: mine.to_vec(),
                ..Default::default()
            },
            ..Default::default()
        },
    )?;
    for i in &sw.summary.as_ref().expect("full sweep").methods {
        println!(
            "sweep: {:<18} observed order {}",
            i.method,
            i.observed_order.map_or_else(
                || format!("none ({})", i.fit.note.clone().unwrap_or_default()),
                |p| format!("{p:.3}")
            )
        );
    }

    // stability: the spectral radius of game_euler's own one-step map.
    let st = analyse(
        &scene,
        &StabilityConfig {
            common: springlab::measure::Common {
                registry: registry.clone(),
                methods: mine.to_vec(),
                ..Default::default()
            },
            ..Default::default()
        },
    )?;
    for i in &st.methods {
        println!(
            "stability: {:<18} {} {}",
            i.method,
            i.verdict.words(),
            i.max_stable_dt
                .map_or(String::new(), |d| format!("dt ≤ {d:.4} s"))
        );
    }

    // advise: the cheapest method and step for 1 mm.
    let adv = advise(
        &scene,
        &AdviseConfig {
            tolerance: Some(1e-3),
            common: springlab::measure::Common {
                registry: registry.clone(),
                methods: mine.to_vec(),
                ..Default::default()
            },
            ..Default::default()
        },
    )?;
    println!(
        "advise: {} at dt = {}",
        adv.method.as_deref().unwrap_or("nothing"),
        adv.dt.map_or("-".into(), |d| format!("{d:.4e} s"))
    );

    // report: the same pages as `springlab report`, with game_euler among the methods.
    let opts = springlab::report::ReportOptions {
        out: "out/custom".into(),
        quick: true,
        energy_terms: false,
        registry,
        blowup_factor: springlab::run::DEFAULT_BLOWUP_FACTOR,
        no_cache: false,
    };
    // The flag says whether an unchanged earlier page was kept rather than studied again.
    let (page, _kept) = springlab::pipeline::report_scene(&scene, &opts)?;
    println!("report: out/custom/{}", page.page);
    Ok(())
}
