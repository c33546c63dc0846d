//! The command line that re-creates a document: every JSON a measuring command writes carries
//! it in a top-level `"command"` field, built here from the resolved configuration (not from
//! the flags typed), so the report's documents and the commands' own agree word for word.
//!
//! Numbers are written in Rust's shortest round-trip form, so re-running the command parses
//! back the very same bits. Methods a library user registered are named like the built-ins;
//! re-running such a command needs the same registry (the library API), not the CLI.

use crate::method::{MethodOptions, Registry};
use std::fmt::Display;
use std::path::Path;

/// The head of a measuring document: the command that re-creates it, the scene and the
/// reference it was measured against, flattened into the document in this order.
#[derive(Debug, Clone, serde::Serialize)]
pub struct DocumentHead {
    /// The command that re-creates the document (`--out DIR` is added where it is written).
    pub command: String,
    /// Scenario name.
    pub scenario: String,
    /// Reference used.
    pub reference: crate::measure::reference::ReferenceInfo,
}

impl DocumentHead {
    /// The head of the document as written into `dir`: its command with `--out dir`.
    pub fn written_to(&self, dir: &Path) -> Self {
        DocumentHead {
            command: with_out(&self.command, dir),
            ..self.clone()
        }
    }
}

/// A `springlab` command line under construction.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CommandLine {
    words: Vec<String>,
}

/// One shell word: as is when it is plain, else single-quoted.
pub fn shell_word(s: &str) -> String {
    let plain = !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-_./,=+:@%".contains(&b));
    if plain {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

impl CommandLine {
    /// `springlab SUBCOMMAND SCENE`.
    pub fn new(subcommand: &str, scene: &Path) -> Self {
        CommandLine {
            words: vec![
                "springlab".into(),
                subcommand.into(),
                scene.display().to_string(),
            ],
        }
    }
    /// Adds `--name value`.
    pub fn flag(mut self, name: &str, value: impl Display) -> Self {
        self.words.push(format!("--{name}"));
        self.words.push(value.to_string());
        self
    }
    /// Adds `--name value` when there is a value.
    pub fn flag_opt<T: Display>(self, name: &str, value: Option<T>) -> Self {
        match value {
            Some(v) => self.flag(name, v),
            None => self,
        }
    }
    /// Adds `--name a,b,c` when the list is not empty.
    pub fn list<T: Display>(self, name: &str, values: &[T]) -> Self {
        if values.is_empty() {
            return self;
        }
        let joined: Vec<String> = values.iter().map(|v| v.to_string()).collect();
        self.flag(name, joined.join(","))
    }
    /// Adds `--flag value` for every option a method of `methods` reads (their declared
    /// schema, in registration order), at its value in `opts`; every option when `methods` is
    /// empty (all methods). An option no listed method reads is left out: the command line
    /// refuses it.
    pub fn method_options(
        self,
        registry: &Registry,
        methods: &[String],
        opts: &MethodOptions,
    ) -> Self {
        registry
            .option_schema()
            .into_iter()
            .filter(|(spec, _)| registry.reads_option(methods, spec.flag))
            .fold(self, |c, (spec, _)| c.flag(spec.flag, opts.value(&spec)))
    }
    /// Adds the shared settings' flags ([`crate::measure::common::Common::recorded`]) for
    /// `methods`.
    pub fn common(self, common: &crate::measure::common::Common, methods: &[String]) -> Self {
        common.recorded(self, methods)
    }
    /// Adds a bare `--name`.
    pub fn switch(mut self, name: &str, on: bool) -> Self {
        if on {
            self.words.push(format!("--{name}"));
        }
        self
    }
    /// The command as one shell line.
    pub fn render(&self) -> String {
        self.words
            .iter()
            .map(|w| shell_word(w))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// `command` with `--out DIR` appended: the line that re-creates the document written to `dir`
/// (named by the path it is published under when `dir` is being staged).
pub fn with_out(command: &str, dir: &Path) -> String {
    let dir = crate::output::published_path(dir);
    format!("{command} --out {}", shell_word(&dir.display().to_string()))
}

/// The words of a rendered command line (inverse of [`CommandLine::render`] for its own
/// output: plain words and single-quoted ones), for tests and scripts that re-run it.
pub fn split_words(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut chars = line.chars().peekable();
    let mut any = false;
    while let Some(c) = chars.next() {
        match c {
            ' ' => {
                if any {
                    out.push(std::mem::take(&mut cur));
                    any = false;
                }
            }
            '\'' => {
                any = true;
                for q in chars.by_ref() {
                    if q == '\'' {
                        break;
                    }
                    cur.push(q);
                }
            }
            '\\' => {
                any = true;
                if let Some(n) = chars.next() {
                    cur.push(n);
                }
            }
            _ => {
                any = true;
                cur.push(c);
            }
        }
    }
    if any {
        out.push(cur);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_words_and_numbers() {
        let c = CommandLine::new("compare", Path::new("my scenes/x.toml"))
            .flag("dt", 0.1 + 0.2)
            .list("methods", &["rk4", "velocity_verlet"])
            .switch("quick", true);
        let line = with_out(&c.render(), Path::new("/tmp/it's"));
        let w = split_words(&line);
        assert_eq!(w[2], "my scenes/x.toml");
        assert_eq!(w[4].parse::<f64>().unwrap(), 0.1 + 0.2);
        assert_eq!(w[6], "rk4,velocity_verlet");
        assert_eq!(w.last().unwrap(), "/tmp/it's");
    }
}
