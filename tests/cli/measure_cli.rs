//! The measuring subcommands end to end: file names, headers, skipped methods, shard + merge.
//! Oracles: the documented CSV headers and JSON fields; merge equality is exact.

use crate::support::ok as springlab;
use springlab::scenario::Scenario;
use std::path::Path;

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn compare_lists_skipped_methods_with_the_reason() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().to_str().unwrap();
    springlab(&[
        "compare",
        "scenarios/pendulum_rod.toml",
        "--methods",
        "verlet_constraints,rk4",
        "--duration",
        "0.5",
        "--out",
        out,
    ]);
    let csv = read(&d.path().join("compare.csv"));
    let mut lines = csv.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("method,status,skip_reason,"));
    let rows: Vec<&str> = lines.collect();
    assert!(rows.iter().any(|r| r.starts_with("verlet_constraints,ok,")));
    assert!(rows
        .iter()
        .any(|r| r.starts_with("rk4,skipped,") && r.contains("constraint")));
    assert!(rows.iter().all(|r| r.ends_with("dop853_constrained")));
    let json: serde_json::Value =
        serde_json::from_str(&read(&d.path().join("summary.json"))).unwrap();
    assert_eq!(json["reference"]["kind"], "dop853_constrained");
}

#[test]
fn sweep_shards_merge_and_stability_advise_files() {
    let d = tempfile::tempdir().unwrap();
    let p = |s: &str| d.path().join(s).to_str().unwrap().to_string();
    let common = [
        "sweep",
        "scenarios/anchored_spring.toml",
        "--methods",
        "rk4,symplectic_euler",
        "--dt-min",
        "1e-3",
        "--dt-max",
        "1e-1",
        "--points",
        "4",
        "--duration",
        "2",
    ];
    let mut full = common.to_vec();
    let fo = p("full");
    full.extend(["--out", &fo]);
    springlab(&full);
    let (s0, s1) = (p("s0"), p("s1"));
    for (i, o) in [("0/2", &s0), ("1/2", &s1)] {
        let mut a = common.to_vec();
        a.extend(["--shard", i, "--out", o]);
        springlab(&a);
    }
    let mo = p("merged");
    springlab(&["merge", &s1, &s0, "--out", &mo]);
    let strip = |s: String| {
        s.lines()
            .map(|l| {
                l.split(',')
                    .enumerate()
                    .filter(|(i, _)| *i != 5)
                    .map(|(_, f)| f)
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect::<Vec<_>>()
    };
    let full_csv = read(&Path::new(&fo).join("sweep.csv"));
    // The wall times are in timing.json; the merged document is the unsharded one, byte for
    // byte, and reads back with its wall times.
    assert!(full_csv.starts_with("method,dt,steps,force_evals,modelled_seconds,error_final,error_max,error_rms,energy_drift,status\n"));
    assert_eq!(full_csv, read(&Path::new(&mo).join("sweep.csv")));
    let back = springlab::output::read_document(Path::new(&mo).join("sweep.csv")).unwrap();
    assert!(back.starts_with("method,dt,steps,force_evals,modelled_seconds,wall_seconds,"));
    assert_eq!(
        strip(back),
        strip(springlab::output::read_document(Path::new(&fo).join("sweep.csv")).unwrap())
    );
    // The merged summary equals the unsharded one; only the command's --out differs.
    let without_command = |dir: &str| {
        let mut v: serde_json::Value =
            serde_json::from_str(&read(&Path::new(dir).join("summary.json"))).unwrap();
        let c = v["command"].as_str().unwrap().to_string();
        v.as_object_mut().unwrap().remove("command");
        (v, c)
    };
    let (full, fc) = without_command(&fo);
    let (merged, mc) = without_command(&mo);
    assert_eq!(full, merged);
    assert_eq!(fc.replace(&fo, "DIR"), mc.replace(&mo, "DIR"));
    let sum: serde_json::Value =
        serde_json::from_str(&read(&Path::new(&fo).join("summary.json"))).unwrap();
    assert!(sum["methods"][0]["observed_order"].is_number());

    let so = p("stab");
    springlab(&[
        "stability",
        "scenarios/anchored_spring.toml",
        "--methods",
        "rk4",
        "--map",
        "--stiffness-scales",
        "1,4",
        "--out",
        &so,
    ]);
    let st: serde_json::Value =
        serde_json::from_str(&read(&Path::new(&so).join("stability.json"))).unwrap();
    assert_eq!(st["methods"][0]["verdict"], "stable_below");
    assert!(st["omega_max"].is_number() && st["methods"][0]["max_stable_dt"].is_number());
    let map = read(&Path::new(&so).join("stability_map.csv"));
    assert_eq!(map.lines().count(), 1 + 2 * 16);

    let ao = p("adv");
    springlab(&[
        "advise",
        "scenarios/anchored_spring.toml",
        "--tolerance",
        "1e-3",
        "--points",
        "4",
        "--methods",
        "rk4,velocity_verlet",
        "--out",
        &ao,
    ]);
    let adv: serde_json::Value =
        serde_json::from_str(&read(&Path::new(&ao).join("advice.json"))).unwrap();
    for k in [
        "method",
        "dt",
        "predicted_error",
        "verified_error",
        "cost_per_second",
        "alternatives",
    ] {
        assert!(!adv[k].is_null(), "advice.json lacks {k}");
    }
}

/// The steps `springlab ARGS --out DIR` ran, from its `summary.json` (`run` and `compare`
/// both write one).
fn steps_ran(args: &[&str], dir: &Path) -> serde_json::Value {
    let mut all = args.to_vec();
    all.extend(["--out", dir.to_str().unwrap()]);
    springlab(&all);
    let json: serde_json::Value = serde_json::from_str(&read(&dir.join("summary.json"))).unwrap();
    json["steps"].clone()
}

/// One rule for the run's length, in every command: a scene of `steps` × `dt` lasts that many
/// seconds, and a `--dt` override keeps the seconds (run and compare agree); `--steps` asks
/// for a number of steps instead. Oracle: 10 steps of 0.01 s are 0.1 s, 20 steps of 0.005 s.
#[test]
fn a_step_override_keeps_the_scenes_length_in_seconds() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("spring.toml");
    std::fs::write(
        &scene,
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
         [[particle]]\nposition = [1.5, 0.0, 0.0]\nmass = 1.0\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = 4.0\nrest_length = 1.0\n\
         [run]\ndt = 0.01\nsteps = 10\n",
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let (run, cmp) = (d.path().join("run"), d.path().join("compare"));
    let run_args = ["run", scene, "-i", "rk4", "--dt", "0.005"];
    assert_eq!(steps_ran(&run_args, &run), 20);
    let cmp_args = ["compare", scene, "--methods", "rk4", "--dt", "0.005"];
    assert_eq!(steps_ran(&cmp_args, &cmp), 20);
    // The twin: an explicit step count is kept as asked.
    let counted = ["run", scene, "-i", "rk4", "--dt", "0.005", "--steps", "7"];
    assert_eq!(steps_ran(&counted, &run), 7);
}

/// A scene that gives `[run] steps` without a step runs that many steps of the step it is
/// given; the twin without a step anywhere is refused, naming the flag to add.
#[test]
fn steps_without_a_scene_step_count_in_the_given_step() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("no_dt.toml");
    std::fs::write(
        &scene,
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nvelocity = [1.0, 0.0, 0.0]\nmass = 1.0\n\
         [run]\nsteps = 10\n",
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let given = ["run", scene, "-i", "rk4", "--dt", "0.01"];
    assert_eq!(steps_ran(&given, &d.path().join("run")), 10);
    let refused = crate::support::bin()
        .args(["run", scene, "-i", "rk4"])
        .output()
        .unwrap();
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("--dt") && err.contains("no_dt.toml"), "{err}");
}

/// Scenes and scripts written with the older words still run: `integrators`/`integrator`
/// scene keys and the `--integrators`, `--integrator` and `-i` flags read as `methods`/`method`.
/// Oracle: the same run asked both ways writes the same document, byte for byte.
#[test]
fn older_method_words_are_read_as_method() {
    let old = Scenario::from_toml_str(
        "[[particle]]\nposition=[0.0,0.0,0.0]\nvelocity=[1.0,0.0,0.0]\nmass=1.0\n[run]\ndt=0.01\nsteps=5\nintegrators=[\"rk4\"]\n[expect]\nintegrator=\"rk4\"\nhz=60\n",
        "old.toml",
    )
    .unwrap();
    assert_eq!(old.run.methods, vec!["rk4".to_string()]);
    assert_eq!(old.expect.as_ref().unwrap().method, "rk4");
    let d = tempfile::tempdir().unwrap();
    let summary = |flag: &str, dir: &str| {
        let out = d.path().join(dir);
        springlab(&[
            "run",
            "scenarios/anchored_spring.toml",
            flag,
            "rk4",
            "--steps",
            "20",
            "--out",
            out.to_str().unwrap(),
        ]);
        read(&out.join("summary.json"))
    };
    let new = summary("--method", "new");
    assert!(new.contains("\"method\": \"rk4\""), "{new}");
    assert_eq!(summary("--integrator", "old"), new);
    assert_eq!(summary("-i", "short"), new);
    let compare = |flag: &str, dir: &str| {
        let out = d.path().join(dir);
        springlab(&[
            "compare",
            "scenarios/anchored_spring.toml",
            flag,
            "rk4",
            "--duration",
            "0.2",
            "--series-points",
            "0",
            "--out",
            out.to_str().unwrap(),
        ]);
        read(&out.join("compare.csv"))
    };
    assert_eq!(
        compare("--integrators", "c_old"),
        compare("--methods", "c_new")
    );
}

/// The twin: a word that was never a name for a method is refused with a clear error.
#[test]
fn an_unknown_method_flag_is_refused() {
    let out = crate::support::bin()
        .args([
            "compare",
            "scenarios/anchored_spring.toml",
            "--backends",
            "rk4",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--backends"));
}
