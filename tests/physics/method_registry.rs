//! The method registry: facts registered once, refused when inconsistent, and a user's own
//! method run by the measuring commands exactly like a built-in.

use springlab::integrate::{StepStats, Stepper};
use springlab::measure::compare::{compare, CompareConfig};
use springlab::method::{CostUnit, Method, MethodInfo, Order, Registry, StabilityTheory};
use springlab::model::{State, System};
use springlab::scenario::Scenario;

/// Symplectic Euler written by a user (the scheme most game loops ship).
struct UserEuler {
    a: Vec<springlab::model::Vec3>,
}

impl Stepper for UserEuler {
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> springlab::Result<StepStats> {
        self.a.resize(s.len(), Default::default());
        sys.accelerations(&s.x, &s.v, &mut self.a);
        for p in 0..s.len() {
            if sys.free[p] {
                s.v[p] += self.a[p] * h;
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

fn info(name: &'static str, order: Order) -> MethodInfo {
    MethodInfo {
        order,
        ..MethodInfo::native(name, 1, "a user's symplectic Euler")
    }
}

fn user() -> Method {
    Method::new(info("user_euler", Order::Finite(1)), |_| {
        Box::new(UserEuler { a: Vec::new() })
    })
}

#[test]
fn builtin_facts_are_the_textbook_ones() {
    // Orders: Hairer, Nørsett & Wanner, Solving ODEs I (Euler 1, midpoint 2, classic RK 4),
    // Störmer–Verlet 2; the closed form is exact; Rapier's substepped symplectic Euler 1.
    let r = Registry::builtin();
    let order = |n: &str| r.info(n).unwrap().order;
    for (n, p) in [
        ("explicit_euler", 1),
        ("symplectic_euler", 1),
        ("implicit_euler", 1),
        ("rk2", 2),
        ("rk4", 4),
        ("velocity_verlet", 2),
        ("position_verlet", 2),
        // Linearly implicit Euler 1 (a W-method, Solving ODEs II §IV.7); implicit midpoint,
        // BDF2 (§III.1) and RATTLE (GNI §VII.1) 2.
        ("linear_implicit_euler", 1),
        ("implicit_midpoint", 2),
        ("bdf2", 2),
        ("rattle", 2),
        // XPBD: backward Euler on each constraint per substep (Macklin et al. 2016).
        ("xpbd", 1),
    ] {
        assert_eq!(order(n), Order::Finite(p), "{n}");
    }
    // Linear one-step theory judges every native method but the closed form and xpbd (a
    // constraint projection, not a linear one-step map: empirical search only).
    for n in r.native_names() {
        let want = match n {
            "analytic" => StabilityTheory::Unconditional,
            "xpbd" => StabilityTheory::Empirical,
            _ => StabilityTheory::SpectralRadius,
        };
        assert_eq!(r.info(n).unwrap().stability, want, "{n}");
    }
    assert_eq!(order("analytic"), Order::Exact);
    // xpbd never evaluates the spring force model (springs become constraints).
    assert_eq!(r.info("xpbd").unwrap().cost, CostUnit::ModelledOnly);
    assert_eq!(serde_json::to_string(&Order::Exact).unwrap(), "\"exact\"");
    assert_eq!(serde_json::to_string(&Order::Finite(4)).unwrap(), "4");
    assert_eq!(r.canonical("semi_implicit_euler"), Some("symplectic_euler"));
    for n in r.engine_names() {
        let i = r.info(n).unwrap();
        assert_eq!(
            i.cost,
            CostUnit::ModelledOnly,
            "{n} never evaluates our forces"
        );
        assert_eq!(i.stability, StabilityTheory::Empirical);
    }
    // Every instance carries its registered facts.
    for m in r.iter() {
        assert_eq!(m.create(&Default::default()).info, m.info);
    }
}

#[test]
fn inconsistent_facts_are_refused_at_registration() {
    let r = Registry::builtin();
    let zero = Method::new(info("user_euler", Order::Finite(0)), |_| {
        Box::new(UserEuler { a: Vec::new() })
    });
    let e = r.clone().with(zero).unwrap_err().to_string();
    assert!(e.contains("user_euler") && e.contains("order 0"), "{e}");
    let dup = Method::new(info("rk4", Order::Finite(4)), |_| {
        Box::new(UserEuler { a: Vec::new() })
    });
    let e = r.clone().with(dup).unwrap_err().to_string();
    assert!(e.contains("already taken"), "{e}");
    let alias = Method::new(
        MethodInfo {
            aliases: &["semi_implicit_euler"],
            ..info("user_euler", Order::Finite(1))
        },
        |_| Box::new(UserEuler { a: Vec::new() }),
    );
    let e = r.clone().with(alias).unwrap_err().to_string();
    assert!(
        e.contains("semi_implicit_euler") && e.contains("symplectic_euler"),
        "{e}"
    );
    let bad = Method::new(info("User Euler", Order::Finite(1)), |_| {
        Box::new(UserEuler { a: Vec::new() })
    });
    assert!(r.clone().with(bad).is_err());
    // Unknown names list every known one, the user's included.
    let mine = r.with(user()).unwrap();
    let e = mine
        .create("nope", &Default::default())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("rk4") && e.contains("user_euler"), "{e}");
}

/// Options are declared once: a method may share a built-in's option only with the very same
/// declaration. Each refusal has a twin that differs only in the inconsistency and is accepted.
#[test]
fn options_are_checked_at_registration() {
    use springlab::method::options::ITERATIONS;
    use springlab::method::options::{OptionKind, OptionValue};
    use springlab::method::{MethodOptions, OptionSpec};
    let r = Registry::builtin();
    let make = |_: &MethodOptions| -> Box<dyn Stepper> { Box::new(UserEuler { a: Vec::new() }) };
    let with_options = |options: &'static [OptionSpec]| {
        Method::new(
            MethodInfo {
                options,
                ..info("user_euler", Order::Finite(1))
            },
            make,
        )
    };
    // Shares --iterations exactly: accepted, and the schema names both readers once.
    const SAME: [OptionSpec; 1] = [ITERATIONS];
    let shared = r.clone().with(with_options(&SAME)).unwrap();
    let schema = shared.option_schema();
    let (spec, by) = schema.iter().find(|(o, _)| o.flag == "iterations").unwrap();
    assert_eq!(spec.default_value(), ITERATIONS.default_value());
    assert_eq!(by, &["verlet_constraints", "user_euler"]);
    assert_eq!(
        schema
            .iter()
            .filter(|(o, _)| o.flag == "iterations")
            .count(),
        1
    );
    // The same flag with another default: refused, naming the flag and the other reader.
    const OTHER_DEFAULT: [OptionSpec; 1] = [OptionSpec {
        kind: OptionKind::Count { default: 5, min: 1 },
        ..ITERATIONS
    }];
    let e = r
        .clone()
        .with(with_options(&OTHER_DEFAULT))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--iterations") && e.contains("verlet_constraints"),
        "{e}"
    );
    // A default below its own least value, and a flag that is not kebab-case: refused.
    const BELOW: [OptionSpec; 1] = [OptionSpec::count("passes", 0, 1, "passes")];
    assert!(r.clone().with(with_options(&BELOW)).is_err());
    const BAD_FLAG: [OptionSpec; 1] = [OptionSpec::count("Passes", 1, 1, "passes")];
    assert!(r.clone().with(with_options(&BAD_FLAG)).is_err());
    const OWN: [OptionSpec; 1] = [OptionSpec::count("passes", 1, 1, "passes")];
    assert!(r.clone().with(with_options(&OWN)).is_ok());
    // A real option whose default lies outside its range, and a choice with no names:
    // refused; their twins inside are accepted.
    const REAL_OUT: [OptionSpec; 1] = [OptionSpec::real("gain", 2.0, (0.0, 1.0), "gain")];
    assert!(r.clone().with(with_options(&REAL_OUT)).is_err());
    const REAL_IN: [OptionSpec; 1] = [OptionSpec::real("gain", 0.5, (0.0, 1.0), "gain")];
    assert!(r.clone().with(with_options(&REAL_IN)).is_ok());
    const NO_NAMES: [OptionSpec; 1] = [OptionSpec::choice("mode", &[], "mode")];
    assert!(r.clone().with(with_options(&NO_NAMES)).is_err());
    const NAMES: [OptionSpec; 1] = [OptionSpec::choice("mode", &["fast", "exact"], "mode")];
    assert!(r.clone().with(with_options(&NAMES)).is_ok());
    // One method listing one option twice: refused.
    const TWICE: [OptionSpec; 2] = [ITERATIONS, ITERATIONS];
    let e = r
        .clone()
        .with(with_options(&TWICE))
        .unwrap_err()
        .to_string();
    assert!(e.contains("listed twice"), "{e}");
    // A value below an option's least is refused when the method is made, naming the flag;
    // its twin at the least value is made.
    use springlab::method::options::XPBD_SUBSTEPS;
    let e = r
        .create(
            "xpbd",
            &MethodOptions::default().with(&XPBD_SUBSTEPS, OptionValue::Count(0)),
        )
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("--xpbd-substeps"), "{e}");
    assert!(r
        .create(
            "xpbd",
            &MethodOptions::default().with(&XPBD_SUBSTEPS, OptionValue::Count(1))
        )
        .is_ok());
    // The engines are the ones that resolve contacts and split frames.
    for m in r.iter() {
        assert_eq!(m.info.contacts, m.info.engine, "{}", m.info.name);
        assert_eq!(m.info.splits_frames, m.info.engine, "{}", m.info.name);
    }
    assert_eq!(r.info("bdf2").unwrap().recurrence_steps, 2);
}

/// The runner reads how a method meets it from the method's registered facts alone. Oracle:
/// the definition of frame splitting: with 3 substeps per frame over 6 frames, a method whose
/// facts say it splits frames itself is handed 6 whole frames, its twin with the very same
/// stepper 18 substeps; and a method that resolves contacts itself gets no contact stage
/// (no contact passes are counted) where its twin with the same stepper does.
#[test]
fn the_runner_reads_the_registered_facts() {
    use springlab::method::MethodOptions;
    use springlab::run::{run, NoObserver, RunPlan};
    let r = Registry::builtin();
    let make = |_: &MethodOptions| -> Box<dyn Stepper> { Box::new(UserEuler { a: Vec::new() }) };
    let ball = Scenario::from_file("scenarios/bounce.toml").unwrap();
    let sys = ball.build();
    let plan = RunPlan::new(1e-3, 6).with_substeps(3);
    let steps_and_passes = |facts: MethodInfo| {
        let mine = r.clone().with(Method::new(facts, make)).unwrap();
        let mut m = mine
            .create("user_euler", &MethodOptions::default())
            .unwrap();
        let out = run(&sys, &mut m, ball.initial_state(), &plan, &mut NoObserver).unwrap();
        (out.work.steps, out.work.contact_passes)
    };
    let own = info("user_euler", Order::Finite(1));
    let (steps, passes) = steps_and_passes(own.clone());
    assert_eq!(steps, 18);
    assert!(passes > 0, "the contact stage ran {passes} passes");
    let (steps, _) = steps_and_passes(MethodInfo {
        splits_frames: true,
        ..own.clone()
    });
    assert_eq!(steps, 6);
    let (_, passes) = steps_and_passes(MethodInfo {
        contacts: true,
        ..own
    });
    assert_eq!(passes, 0);
}

#[test]
fn a_registered_method_runs_through_compare_like_a_builtin() {
    // Oracle: the user's scheme is symplectic Euler step for step, so compare must report
    // bit-identical errors for both.
    let scene = Scenario::from_toml_str(
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
         [[particle]]\nposition = [1.5, 0.0, 0.0]\nmass = 1.0\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = 4.0\nrest_length = 1.0\n\
         [run]\ndt = 0.05\nduration = 2.0\n",
        "osc.toml",
    )
    .unwrap();
    let cfg = CompareConfig {
        series_points: 0,
        common: springlab::measure::Common {
            registry: Registry::builtin().with(user()).unwrap(),
            methods: vec!["user_euler".into(), "symplectic_euler".into()],
            ..Default::default()
        },
        ..Default::default()
    };
    let res = compare(&scene, &cfg).unwrap();
    let err = |n: &str| {
        let e = res.entries.iter().find(|e| e.method == n).unwrap();
        e.result
            .as_ref()
            .unwrap()
            .metrics
            .as_ref()
            .unwrap()
            .error_max
    };
    assert!(err("user_euler") > 0.0);
    assert_eq!(
        err("user_euler").to_bits(),
        err("symplectic_euler").to_bits()
    );
}

/// A choice option reaches the method it is read by. Oracle: the solvers' definitions: the
/// block IC(0) solver factors the Newton matrix at every Newton iteration and applies its
/// factor once per CG solve and at most once per CG iteration, block-Jacobi CG never does
/// either; both solve the same backward-Euler stage to its root, so a cloth's steps agree to
/// the Newton tolerance.
#[test]
fn the_linear_solver_is_an_option_of_the_implicit_methods() {
    use springlab::method::options::{OptionValue, LINEAR_SOLVER};
    use springlab::method::MethodOptions;
    let scene = springlab::perf::cloth(6);
    let sys = scene.build();
    let step = |solver: &str| {
        let opts =
            MethodOptions::default().with(&LINEAR_SOLVER, OptionValue::Choice(solver.into()));
        let mut m = Registry::builtin().create("implicit_euler", &opts).unwrap();
        let mut s = scene.initial_state();
        for _ in 0..5 {
            m.step(&sys, &mut s, 1.0 / 60.0).unwrap();
        }
        (m.solver_work(), s)
    };
    let (jacobi, a) = step("block_jacobi_cg");
    let (ic0, b) = step("block_ic0_cg");
    assert_eq!((jacobi.factorizations, jacobi.factor_solves), (0, 0));
    assert!(
        ic0.factorizations >= ic0.newton_iterations && ic0.newton_iterations > 0,
        "{ic0:?}"
    );
    // Each Newton iteration is one CG solve here (no shift was needed on this cloth).
    assert_eq!(ic0.modified_iterations, 0, "{ic0:?}");
    assert!(
        ic0.factor_solves >= ic0.newton_iterations
            && ic0.factor_solves <= ic0.linear_iterations + ic0.newton_iterations,
        "{ic0:?}"
    );
    let scale = a.v.iter().map(|v| v.amax()).fold(0.0, f64::max);
    for (va, vb) in a.v.iter().zip(&b.v) {
        assert!((va - vb).amax() <= 1e-4 * scale, "{va} vs {vb}");
    }
    // A name the option does not take is refused when the method is made, naming the flag.
    let bad = MethodOptions::default().with(&LINEAR_SOLVER, OptionValue::Choice("lu".into()));
    let e = Registry::builtin()
        .create("implicit_euler", &bad)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("--linear-solver"), "{e}");
}
