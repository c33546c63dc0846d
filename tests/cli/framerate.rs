//! `springlab framerate`.
//!
//! Oracle for the substep search: a chain of N = 8 free beads (m = 0.01 kg, k = 1000 N/m)
//! between two fixed ends, moving along its axis, is the textbook fixed–fixed chain whose
//! modes are ω_j = 2√(k/m)·sin(jπ / (2(N+1))); symplectic Euler at step h is stable exactly
//! when h·ω_max < 2. With a tolerance no stable run can miss (1 km), the fewest substeps per
//! frame of step H is the smallest n with (H/n)·ω_max < 2: ⌈H·ω_max/2⌉ (H·ω_max/2 is not an
//! integer at these rates).
//!
//! Margin of the blow-up criterion: the verdict calls a run unstable once its energy balance
//! rises by more than the blow-up factor × the scene's energy scale (here the kick's energy).
//! A *stable* symplectic Euler run at θ = hω overshoots the true energy of a mode by up to a
//! factor 1/(1 − θ²/4), so at the default factor (1) steps with θ > √2 that excite the top
//! mode are already called unstable (measured: 30 Hz needs 15 substeps instead of 11). With a
//! factor of 100 the verdict only disagrees with the stability limit for θ in (1.990, 2); the
//! stable counts here have θ ≤ 1.89, and the unstable ones (θ ≥ 2.08) grow by ≥ 1.7× per step,
//! past 100× within the 0.5 s run, so the count must match the formula exactly.

use springlab::measure::framerate::{framerate, write_framerate, FramerateConfig};
use springlab::scenario::Scenario;

const CHAIN: &str = r#"
[[chain]]
start = [0.0, 0.0, 0.0]
end = [0.9, 0.0, 0.0]
count = 10
mass = 0.01
stiffness = 1000.0
fix = ["first", "last"]
[[impulse]]
time = 0.0
particle = 3
delta_v = [0.05, 0.0, 0.0]
[run]
dt = 0.001
duration = 0.5
"#;

#[test]
fn symplectic_euler_needs_ceil_h_omega_max_over_two() {
    let scene = Scenario::from_toml_str(CHAIN, "chain.toml").unwrap();
    let n = 8.0;
    let omega_max =
        2.0 * (1000.0f64 / 0.01).sqrt() * (n * std::f64::consts::PI / (2.0 * (n + 1.0))).sin();
    let rates = vec![30.0, 60.0, 144.0, 240.0];
    let fr = framerate(
        &scene,
        &FramerateConfig {
            rates: rates.clone(),
            tolerance: Some(1e3),
            common: springlab::measure::Common {
                blowup_factor: 100.0,
                methods: vec!["symplectic_euler".into()],
                ..Default::default()
            },
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(fr.entries.len(), rates.len());
    for e in &fr.entries {
        let x = omega_max / e.hz / 2.0;
        let frac = x - x.floor();
        assert!(
            (0.15..0.85).contains(&frac),
            "{x}: too near an integer for this oracle"
        );
        let expect = x.ceil() as u64;
        let got = e.fewest.as_ref().map(|f| f.substeps);
        assert_eq!(
            got,
            Some(expect),
            "{} Hz: H·ω_max/2 = {x}; tried {:?}",
            e.hz,
            e.tried
        );
        assert_eq!(e.one_substep.substeps, 1);
        // One step more would be unstable: the count below the answer was tried and failed.
        assert!(e.tried.contains(&(expect - 1, false)) || expect == 1);
        let f = e.fewest.as_ref().unwrap();
        assert_eq!(
            f.force_evals_per_frame,
            Some(expect as f64),
            "one force evaluation per substep"
        );
        assert!(f.wall_seconds_per_frame.is_some_and(|w| w > 0.0));
        assert!(f.modelled_seconds_per_frame.is_some_and(|w| w > 0.0));
    }
}

/// Oracle: the same textbook limit (module docs). The search that starts from the substeps the
/// linear stability theory gives (hω_max < 2 for symplectic Euler, found by the theory from the
/// method itself) finds what the plain search doubling from one substep finds, ⌈H·ω_max/2⌉; and
/// of the counts between one and that answer it runs only the one just below it.
#[test]
fn the_search_from_the_stability_theory_finds_what_doubling_finds() {
    let scene = Scenario::from_toml_str(CHAIN, "chain.toml").unwrap();
    let n = 8.0;
    let omega_max =
        2.0 * (1000.0f64 / 0.01).sqrt() * (n * std::f64::consts::PI / (2.0 * (n + 1.0))).sin();
    let search = |theory_start: bool| {
        framerate(
            &scene,
            &FramerateConfig {
                rates: vec![30.0, 60.0, 144.0],
                tolerance: Some(1e3),
                theory_start,
                common: springlab::measure::Common {
                    blowup_factor: 100.0,
                    methods: vec!["symplectic_euler".into()],
                    ..Default::default()
                },
                ..Default::default()
            },
        )
        .unwrap()
    };
    let (from_theory, doubling) = (search(true), search(false));
    for (t, d) in from_theory.entries.iter().zip(&doubling.entries) {
        let expect = (omega_max / t.hz / 2.0).ceil() as u64;
        let fewest =
            |e: &springlab::measure::framerate::RateEntry| e.fewest.as_ref().map(|f| f.substeps);
        assert_eq!(fewest(t), Some(expect), "{} Hz: tried {:?}", t.hz, t.tried);
        assert_eq!(
            fewest(t),
            fewest(d),
            "{} Hz: {:?} vs {:?}",
            t.hz,
            t.tried,
            d.tried
        );
        let below: Vec<u64> = t
            .tried
            .iter()
            .map(|c| c.0)
            .filter(|&c| c < expect)
            .collect();
        assert_eq!(below, [1, expect - 1], "{} Hz: tried {:?}", t.hz, t.tried);
        assert!(
            t.tried.len() < d.tried.len(),
            "{:?} vs {:?}",
            t.tried,
            d.tried
        );
    }
}

#[test]
fn writes_csv_and_json_with_a_command_that_recreates_them() {
    let scene = Scenario::from_file("scenarios/damped_spring.toml").unwrap();
    // xpbd with its own substeps: the recorded command must carry the method's options, or
    // the re-run below measures another method.
    let cfg = FramerateConfig {
        rates: vec![30.0, 60.0],
        common: springlab::measure::Common {
            methods: vec![
                "symplectic_euler".into(),
                "rapier_impulse".into(),
                "xpbd".into(),
            ],
            options: springlab::method::MethodOptions::default().with(
                &springlab::method::options::XPBD_SUBSTEPS,
                springlab::method::options::OptionValue::Count(3),
            ),
            ..Default::default()
        },
        ..Default::default()
    };
    let fr = framerate(&scene, &cfg).unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_framerate(dir.path(), &fr).unwrap();
    let csv = std::fs::read_to_string(dir.path().join("framerate.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for col in [
        "method",
        "hz",
        "substeps",
        "status",
        "max_position_error",
        "energy_drift",
        "modelled_seconds_per_frame",
        "force_evals_per_frame",
    ] {
        assert!(header.contains(&col), "{col}");
    }
    // The wall times are apart, in timing.json, and read back in place.
    assert!(!header.contains(&"wall_seconds_per_frame"));
    let back = springlab::output::read_document(dir.path().join("framerate.csv")).unwrap();
    assert!(back
        .lines()
        .next()
        .unwrap()
        .contains("modelled_seconds_per_frame,wall_seconds_per_frame"));
    assert_eq!(
        csv.lines().count(),
        1 + 2 * 2 * 3,
        "two rows per method and rate"
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("framerate.json")).unwrap()).unwrap();
    let cmd = json["command"].as_str().unwrap();
    assert!(cmd.starts_with("springlab framerate scenarios/damped_spring.toml --hz 30,60"));
    assert!(cmd.contains("--xpbd-substeps 3"), "{cmd}");
    // Re-running the command reproduces every measured number (timings aside).
    let words = springlab::measure::command::split_words(cmd);
    let out = tempfile::tempdir().unwrap();
    let mut args: Vec<String> = words[1..words.len() - 2].to_vec();
    args.extend(["--out".into(), out.path().display().to_string()]);
    let st = crate::support::bin().args(&args).output().unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let again: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("framerate.json")).unwrap()).unwrap();
    for (a, b) in json["entries"]
        .as_array()
        .unwrap()
        .iter()
        .zip(again["entries"].as_array().unwrap())
    {
        for k in ["method", "hz", "tried"] {
            assert_eq!(a[k], b[k]);
        }
        for r in ["one_substep", "fewest"] {
            for k in [
                "substeps",
                "status",
                "max_position_error",
                "energy_drift",
                "force_evals_per_frame",
            ] {
                assert_eq!(a[r][k], b[r][k], "{r}.{k}");
            }
        }
    }
}

fn springlab(args: &[&str]) -> (bool, String) {
    let out = crate::support::bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    (out.status.success(), err)
}

/// Bad input: a clear error naming what is wrong, a non-zero exit, no panic.
#[test]
fn bad_frame_input_is_refused_clearly() {
    let s = "scenarios/damped_spring.toml";
    for (args, says) in [
        (vec!["run", s, "-i", "rk4", "--hz", "0"], "--hz"),
        (vec!["run", s, "-i", "rk4", "--hz", "-60"], "--hz"),
        (vec!["run", s, "-i", "rk4", "--substeps", "0"], "--substeps"),
        (
            vec!["run", s, "-i", "rk4", "--dt", "1/0"],
            "divides by zero",
        ),
        (vec!["run", s, "-i", "rk4", "--dt", "1/sixty"], "--dt"),
        (
            vec!["run", s, "-i", "rk4", "--dt", "0.01", "--hz", "60"],
            "--hz",
        ),
        (vec!["framerate", s, "--hz", "0"], "--hz"),
        // A frame longer than the run, refused at once as `run` refuses it.
        (vec!["framerate", s, "--hz", "1e-300"], "--hz"),
        (vec!["framerate", s, "--duration", "1e-300"], "--duration"),
        (vec!["framerate", s, "--hz", "30,,60"], "--hz"),
        (vec!["framerate", s, "--hz", "30,sixty"], "--hz"),
        (vec!["framerate", s, "--hz", "30;60"], "--hz"),
        (vec!["framerate", s, "--tolerance", "0"], "--tolerance"),
        (
            vec!["framerate", s, "--max-substeps", "0"],
            "--max-substeps",
        ),
    ] {
        let (ok, err) = springlab(&args);
        assert!(!ok, "{args:?} succeeded");
        assert!(err.contains(says), "{args:?}: {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad_events.toml");
    std::fs::write(
        &bad,
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\n[run]\ndt = 0.01\nduration = 1.0\nevents = \"frames\"\n",
    )
    .unwrap();
    let (ok, err) = springlab(&["run", bad.to_str().unwrap(), "-i", "rk4"]);
    assert!(!ok);
    for part in [
        "bad_events.toml",
        "run.events",
        "\"exact\" or \"frame\"",
        "frames",
    ] {
        assert!(err.contains(part), "{err}");
    }
}

#[test]
fn dt_accepts_fractions_and_substeps_apply_to_native_methods() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).display().to_string();
    let s = "scenarios/hanging_chain.toml";
    let (ok, err) = springlab(&[
        "run",
        s,
        "-i",
        "symplectic_euler",
        "--dt",
        "1/60",
        "--substeps",
        "4",
        "--out",
        &out("a"),
    ]);
    assert!(ok, "{err}");
    let (ok, err) = springlab(&[
        "run",
        s,
        "-i",
        "symplectic_euler",
        "--dt",
        "1/240",
        "--out",
        &out("b"),
    ]);
    assert!(ok, "{err}");
    let last = |d: &str| {
        let t = std::fs::read_to_string(dir.path().join(d).join("trajectory.csv")).unwrap();
        let lines: Vec<&str> = t.lines().collect();
        lines[lines.len() - 20..]
            .iter()
            .map(|l| l.split(',').skip(2).collect::<Vec<_>>().join(","))
            .collect::<Vec<_>>()
    };
    // The same final state of all 20 beads (step and time columns aside: frame 120 is step 480).
    assert_eq!(last("a"), last("b"));
    let sum: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("a/summary.json")).unwrap())
            .unwrap();
    assert_eq!(sum["substeps"], 4);
    assert_eq!(sum["steps"], 120);
}
