//! The documentation (README.md and every page under docs/) and `--help` agree. Oracle: the
//! binary's own `--help` output (clap renders each flag's `[default: …]` from the value the
//! code uses) against every default the documentation states for a flag.

use std::collections::BTreeMap;

const COMMANDS: [&str; 14] = [
    "run",
    "check",
    "list",
    "bench-scaling",
    "bench-ratios",
    "report",
    "sweep",
    "stability",
    "advise",
    "compare",
    "framerate",
    "merge",
    "small-steps",
    "expect",
];

fn help(cmd: &str) -> String {
    let out = crate::support::bin()
        .args([cmd, "--help"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{cmd} --help failed");
    String::from_utf8(out.stdout).unwrap()
}

/// `--flag` → its help text (until the next flag), from one command's `--help`.
fn flags(help: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for line in help.lines() {
        let t = line.trim_start();
        match t.find("--").filter(|_| t.starts_with('-')) {
            Some(k) => {
                let rest = &t[k + 2..];
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || *c == '-' || c.is_ascii_digit())
                    .collect();
                out.push((name.clone(), rest[name.len()..].to_string()));
            }
            None => {
                if let Some(last) = out.last_mut() {
                    last.1.push(' ');
                    last.1.push_str(t);
                }
            }
        }
    }
    out
}

fn default_of(text: &str) -> Option<String> {
    let k = text.find("[default: ")?;
    let rest = &text[k + 10..];
    Some(rest[..rest.find(']')?].to_string())
}

/// Every flag's `[default: …]` across all commands; a flag shared by several commands must
/// have the same default in each.
fn help_defaults() -> BTreeMap<String, String> {
    let mut all: BTreeMap<String, (String, String)> = BTreeMap::new();
    for cmd in COMMANDS {
        for (flag, text) in flags(&help(cmd)) {
            // Paths (`--out`) differ by command on purpose; numbers must agree everywhere.
            if let Some(d) = default_of(&text).filter(|d| d.parse::<f64>().is_ok()) {
                if let Some((c0, d0)) = all.get(&flag) {
                    assert_eq!(d0, &d, "--{flag}: {c0} says {d0}, {cmd} says {d}");
                } else {
                    all.insert(flag, (cmd.to_string(), d));
                }
            }
        }
    }
    all.into_iter().map(|(f, (_, d))| (f, d)).collect()
}

/// README.md and every `docs/*.md` page (in name order), each ending in a blank line so no
/// passage runs from one file into the next.
fn documentation() -> String {
    let mut pages: Vec<std::path::PathBuf> = std::fs::read_dir("docs")
        .expect("docs/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    pages.sort();
    assert!(!pages.is_empty(), "docs/ has no pages");
    let mut all = String::new();
    for p in std::iter::once(std::path::PathBuf::from("README.md")).chain(pages) {
        let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        all.push_str(&text);
        all.push_str("\n\n");
    }
    all
}

/// (flag, number) for every documentation passage "`--flag …` … default [`NAME` =] NUMBER" up
/// to the next flag or blank line.
fn documented_defaults(doc: &str) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    let mut rest = doc;
    while let Some(k) = rest.find("`--") {
        rest = &rest[k + 3..];
        let name: String = rest
            .chars()
            .take_while(|c| c.is_ascii_lowercase() || *c == '-' || c.is_ascii_digit())
            .collect();
        let Some(close) = rest.find('`') else { break };
        let after = &rest[close + 1..];
        let end = [after.find("`--"), after.find("\n\n")]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(after.len());
        let seg = &after[..end];
        if let Some(d) = seg.find("default") {
            let mut v = seg[d + 7..].trim_start();
            if v.starts_with('`') {
                // "default `NAME` = VALUE"
                if let Some(eq) = v.find("= ") {
                    v = &v[eq + 2..];
                }
            }
            let num: String = v
                .chars()
                .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | '-' | '+'))
                .collect();
            if let Ok(x) = num.trim_end_matches('.').parse::<f64>() {
                out.push((name, x));
            }
        }
    }
    out
}

#[test]
fn every_default_the_documentation_states_is_the_one_help_shows() {
    let doc = documentation();
    let help = help_defaults();
    let stated = documented_defaults(&doc);
    assert!(
        stated.iter().any(|(f, _)| f == "blowup-factor"),
        "the documentation states the blow-up factor's default"
    );
    let mut checked = 0;
    for (flag, value) in &stated {
        if let Some(h) = help.get(flag) {
            let h: f64 = h
                .parse()
                .unwrap_or_else(|_| panic!("--{flag}: the docs say {value}, --help says {h}"));
            assert_eq!(*value, h, "--{flag}: the docs say {value}, --help says {h}");
            checked += 1;
        }
    }
    assert!(checked >= 4, "only {checked} defaults compared: {stated:?}");
}

#[test]
fn the_blowup_threshold_reads_the_same_in_the_documentation_and_every_help() {
    let doc = documentation();
    let text = springlab::run::verdict::BLOWUP_FACTOR_HELP;
    assert!(doc.contains(text), "README.md and docs/ lack: {text}");
    for cmd in ["run", "compare", "stability", "sweep", "advise", "report"] {
        let h = help(cmd).split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(h.contains(text), "{cmd} --help lacks: {text}");
        let def = flags(&help(cmd))
            .into_iter()
            .find(|(f, _)| f == "blowup-factor")
            .and_then(|(_, t)| default_of(&t));
        assert_eq!(
            def.as_deref().map(|d| d.parse::<f64>().unwrap()),
            Some(springlab::run::DEFAULT_BLOWUP_FACTOR),
            "{cmd}"
        );
    }
}
