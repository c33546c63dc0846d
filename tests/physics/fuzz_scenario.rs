//! Fuzzing the scenario parser and builder with proptest: shipped scenarios mutated (truncated,
//! values replaced by hostile ones, lines dropped or duplicated, garbage inserted) and scenes
//! generated from scratch. Oracle: the format's contract: no panic; an error names a field; an
//! accepted scene builds, and one force evaluation on it is finite or the scene has a
//! non-finite input nowhere (validation guarantees finite inputs).

use proptest::prelude::*;
use springlab::scenario::Scenario;
use springlab::Error;

const BASES: &[&str] = &[
    include_str!("../../scenarios/anchored_spring.toml"),
    include_str!("../../scenarios/damped_spring.toml"),
    include_str!("../../scenarios/two_body.toml"),
    include_str!("../../scenarios/recoil_spring.toml"),
    include_str!("../../scenarios/hanging_chain.toml"),
    include_str!("../../scenarios/pendulum_rod.toml"),
    include_str!("../../scenarios/stiff_spring.toml"),
    // The shipped cloth, shrunk so that every case stays fast.
    "[world]\ngravity = [0.0, -9.81, 0.0]\ndrag = 0.1\n[[cloth]]\norigin = [0.0, 0.0, 0.0]\n\
     size = [1.0, 1.0]\ncount = [4, 3]\nmass = 0.001\nstiffness = 200.0\ndamping = 0.002\n\
     bend_stiffness = 20.0\nplane = \"xz\"\nfix = [\"top_left\", \"top_right\"]\n\
     [[impulse]]\ntime = 0.5\nparticle = 3\ndelta_v = [0.0, 1.0, 0.0]\n[run]\ndt = 0.001\nduration = 1.0\n",
];

/// Values that break assumptions: signs, zeros, NaN/inf, huge and tiny magnitudes, wrong types.
const HOSTILE: &[&str] = &[
    "-1",
    "0",
    "1",
    "2",
    "-0.0",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "1e-320",
    "-1e308",
    "9223372036854775807",
    "-9223372036854775808",
    "10000001",
    "\"text\"",
    "true",
    "[]",
    "[1.0]",
    "[1.0, 2.0, 3.0, 4.0]",
    "{}",
    "[0, 0]",
    "[0, 99]",
    "[-1, 0]",
    "3.5",
    "\"\"",
    "[\"first\", \"nowhere\"]",
];

#[derive(Debug, Clone)]
enum Mutation {
    Truncate(usize),
    ReplaceValue(usize, usize),
    DropLine(usize),
    DuplicateLine(usize),
    Insert(usize, String),
    RenameKey(usize),
}

fn mutate(text: &str, muts: &[Mutation]) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for m in muts {
        if lines.is_empty() {
            break;
        }
        let n = lines.len();
        match m {
            Mutation::Truncate(k) => {
                let s = lines.join("\n");
                let mut cut = k % (s.len() + 1);
                while !s.is_char_boundary(cut) {
                    cut -= 1;
                }
                lines = s[..cut].lines().map(String::from).collect();
            }
            Mutation::ReplaceValue(l, v) => {
                let line = &mut lines[l % n];
                if let Some(eq) = line.find('=') {
                    *line = format!("{}= {}", &line[..eq], HOSTILE[v % HOSTILE.len()]);
                }
            }
            Mutation::DropLine(l) => {
                lines.remove(l % n);
            }
            Mutation::DuplicateLine(l) => {
                let dup = lines[l % n].clone();
                lines.insert(l % n, dup);
            }
            Mutation::Insert(l, g) => lines.insert(l % (n + 1), g.clone()),
            Mutation::RenameKey(l) => {
                let line = &mut lines[l % n];
                if let Some(eq) = line.find('=') {
                    *line = format!("{}x {}", line[..eq].trim_end(), &line[eq..]);
                }
            }
        }
    }
    lines.join("\n")
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), any::<usize>()).prop_map(|(l, v)| Mutation::ReplaceValue(l, v)),
        (any::<usize>(), any::<usize>()).prop_map(|(l, v)| Mutation::ReplaceValue(l, v)),
        any::<usize>().prop_map(Mutation::DropLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), "[ -~]{0,30}|\\PC{0,10}").prop_map(|(l, g)| Mutation::Insert(l, g)),
        any::<usize>().prop_map(Mutation::RenameKey),
    ]
}

/// True when some input magnitude exceeds 1e100 or a mass is below 1e-100 (so squares,
/// products or quotients of inputs can overflow f64).
fn has_huge_value(scene: &Scenario) -> bool {
    let big = |x: f64| x.abs() > 1e100;
    scene.particles.iter().any(|p| {
        p.position.iter().chain(p.velocity.iter()).any(|&c| big(c))
            || big(p.mass)
            || (!p.fixed && p.mass < 1e-100)
    }) || scene
        .springs
        .iter()
        .any(|s| big(s.stiffness) || big(s.damping) || s.rest_length.is_some_and(big))
        || scene.gravity.is_some_and(|g| g.iter().any(|&c| big(c)))
        || scene.drag.is_some_and(big)
        || scene
            .impulses
            .iter()
            .any(|i| i.delta_v.iter().any(|&c| big(c)))
}

/// The contract for any input text.
fn check(text: &str) -> Result<(), TestCaseError> {
    match Scenario::from_toml_str(text, "fuzz.toml") {
        Ok(scene) => {
            let sys = scene.build();
            let s = scene.initial_state();
            let mut a = vec![springlab::model::Vec3::zeros(); sys.len()];
            let p = sys.accelerations(&s.x, &s.v, &mut a);
            let e = sys.state_energy(&s);
            let finite = p.is_finite()
                && a.iter().all(|v| v.iter().all(|c| c.is_finite()))
                && e.kinetic.is_finite()
                && e.gravity.is_finite()
                && e.elastic.is_finite();
            // Validation admits any finite value; only products of huge inputs may overflow.
            prop_assert!(
                finite || has_huge_value(&scene),
                "non-finite forces or energy from moderate inputs"
            );
        }
        Err(Error::Parse { field, message, .. }) | Err(Error::Invalid { field, message, .. }) => {
            prop_assert!(!field.is_empty(), "error without a field: {message}");
            prop_assert!(!message.is_empty());
        }
        Err(other) => prop_assert!(false, "unexpected error kind: {other}"),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenarios_never_panic(base in 0..BASES.len(), muts in prop::collection::vec(mutation(), 1..4)) {
        check(&mutate(BASES[base], &muts))?;
    }

    #[test]
    fn generated_scenes_never_panic(
        particles in prop::collection::vec((any::<[i8; 3]>(), -2.0f64..5.0, any::<bool>()), 0..6),
        springs in prop::collection::vec((-1i64..7, -1i64..7, -1.0f64..1e4, prop::option::of(-1.0f64..3.0), -0.5f64..2.0, any::<bool>()), 0..8),
        gravity in prop::option::of(any::<[i8; 3]>()),
        dt in prop::option::of(-1.0f64..1.0),
    ) {
        let mut t = String::new();
        if let Some(g) = gravity {
            t += &format!("[world]\ngravity = [{:?}, {:?}, {:?}]\n", g[0] as f64, g[1] as f64, g[2] as f64);
        }
        for (p, m, fixed) in &particles {
            t += &format!("[[particle]]\nposition = [{:?}, {:?}, {:?}]\nmass = {m:?}\nfixed = {fixed}\n", p[0] as f64, p[1] as f64, p[2] as f64);
        }
        for (i, j, k, l0, c, strain) in &springs {
            t += &format!("[[spring]]\nbetween = [{i}, {j}]\nstiffness = {k:?}\ndamping = {c:?}\n");
            if let Some(l) = l0 { t += &format!("rest_length = {l:?}\n"); }
            if *strain { t += "law = \"strain\"\n"; }
        }
        if let Some(dt) = dt { t += &format!("[run]\ndt = {dt:?}\nsteps = 10\n"); }
        check(&t)?;
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        check(&String::from_utf8_lossy(&bytes))?;
    }
}
