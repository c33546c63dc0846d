//! The method options' flags (`--iterations`, `--xpbd-substeps`, ...), generated from the
//! option schema the registry's methods declare: one declaration per option gives its flag,
//! default, bounds and help in every command that builds methods.

use clap::{Arg, ArgMatches, Command, FromArgMatches};
use springlab::method::options::at_least;
use springlab::method::options::{OptionKind, OptionValue};
use springlab::method::{MethodOptions, OptionSpec, Registry};

/// The method options as given on the command line (each at its default when not given).
#[derive(Debug, Clone, Default)]
pub struct MethodArgs {
    options: MethodOptions,
    /// The option flags the user wrote (not their defaults), checked against the methods run.
    given: Vec<&'static str>,
}

impl MethodArgs {
    /// The options, every value already checked against its bounds by the parser; a frame's
    /// `--substeps`, when given, is also an engine's solver substeps.
    pub fn options(&self, substeps: Option<usize>) -> MethodOptions {
        match substeps {
            Some(n) => self.options.clone().with_substeps(n),
            None => self.options.clone(),
        }
    }

    /// Refuses an option flag the user gave that none of `methods` reads (it would change
    /// nothing): the error names the flag, the methods asked and the ones that read it.
    /// Names the registry does not know are left to the command's own check; an empty list
    /// (every method that applies) reads every option.
    pub fn check_read_by(&self, methods: &[String]) -> anyhow::Result<()> {
        let registry = Registry::builtin();
        let Some(infos) = methods
            .iter()
            .map(|n| registry.find(n).map(|m| &m.info))
            .collect::<Option<Vec<_>>>()
        else {
            return Ok(());
        };
        for (spec, by) in schema() {
            if self.given.contains(&spec.flag) && !registry.reads_option(methods, spec.flag) {
                let asked: Vec<&str> = infos.iter().map(|i| i.name).collect();
                anyhow::bail!(
                    "--{}: read only by {}; {} {} not read it, so it would change nothing (drop the flag or run a method that reads it)",
                    spec.flag,
                    by.join(", "),
                    asked.join(", "),
                    if asked.len() == 1 { "does" } else { "do" }
                );
            }
        }
        Ok(())
    }
}

fn schema() -> Vec<(OptionSpec, Vec<&'static str>)> {
    Registry::builtin().option_schema()
}

/// A whole number no less than `min`, for clap: the error says what is wrong; clap adds the
/// flag.
fn whole_at_least(min: usize) -> impl Fn(&str) -> Result<usize, String> + Clone + Send + Sync {
    move |s: &str| {
        let v: usize = s
            .trim()
            .parse()
            .map_err(|_| format!("expected a whole number ≥ {min}"))?;
        at_least(min, v)?;
        Ok(v)
    }
}

/// The placeholder a kind of option shows in help: N, X or NAME.
pub fn value_name(kind: &OptionKind) -> &'static str {
    match kind {
        OptionKind::Count { .. } => "N",
        OptionKind::Real { .. } => "X",
        OptionKind::Choice { .. } => "NAME",
    }
}

/// Frame substeps (`--substeps`): a whole number ≥ 1, checked like the method options.
pub fn substeps(s: &str) -> Result<usize, String> {
    whole_at_least(1)(s)
}

impl clap::Args for MethodArgs {
    fn augment_args(cmd: Command) -> Command {
        schema().into_iter().fold(cmd, |cmd, (spec, by)| {
            cmd.arg(
                Arg::new(spec.flag)
                    .long(spec.flag)
                    .value_name(value_name(&spec.kind))
                    .allow_negative_numbers(true)
                    .value_parser(clap::builder::ValueParser::new(move |s: &str| {
                        spec.parse(s)
                    }))
                    .default_value(spec.default_value().to_string())
                    .help(format!(
                        "{}: {} (read by {})",
                        spec.help,
                        spec.kind.what(),
                        by.join(", ")
                    )),
            )
        })
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl FromArgMatches for MethodArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut options = MethodOptions::default();
        let mut given = Vec::new();
        for (spec, _) in schema() {
            if let Some(v) = m.get_one::<OptionValue>(spec.flag) {
                options.set(&spec, v.clone());
            }
            if m.value_source(spec.flag) == Some(clap::parser::ValueSource::CommandLine) {
                given.push(spec.flag);
            }
        }
        Ok(MethodArgs { options, given })
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}
